//! Built-in scenarios for the paper's robots (Section IV, gvs-spec §3.4, §10.4). Each is the TOML of
//! `examples/<name>.toml`, embedded so that `gvsrom statics single-tendon` works from any directory.
//! The first three are the paper's setups; `soft-beam-peak` (the pulse read as a peak line density)
//! and `six-tendon-no-gravity` are milder variants, kept for the gvs-spec §10.4 anchors;
//! `six-tendon-hanging` is the IV-C arm in the other orientation the paper leaves open.

use crate::error::ScenarioError;
use crate::provenance::{sha256_hex, Provenance, ScenarioOrigin};
use crate::scenario::Scenario;
use std::path::Path;

/// A built-in scenario.
#[derive(Debug, Clone, Copy)]
pub struct Preset {
    pub name: &'static str,
    pub summary: &'static str,
    /// The scenario file's text.
    pub toml: &'static str,
}

pub const PRESETS: &[Preset] = &[
    Preset {
        name: "single-tendon",
        summary:
            "IV-A: tapered single-tendon arm under gravity, friction 0.88, 33-DOF Legendre basis",
        toml: include_str!("../../../examples/single-tendon.toml"),
    },
    Preset {
        name: "soft-beam",
        summary: "IV-B: beam under a triangular-pulse moment of 4 N·m total, 50-DOF linear FEM-like basis",
        toml: include_str!("../../../examples/soft-beam.toml"),
    },
    Preset {
        name: "six-tendon",
        summary: "IV-C: two-division arm under gravity, three full- and three half-length tendons, 28 DOF",
        toml: include_str!("../../../examples/six-tendon.toml"),
    },
    Preset {
        name: "soft-beam-peak",
        summary: "IV-B, milder peak-density reading: 4 N·m/m peak (0.16 N·m total), 50 DOF",
        toml: include_str!("../../../examples/soft-beam-peak.toml"),
    },
    Preset {
        name: "six-tendon-no-gravity",
        summary: "IV-C without gravity: actuation only, strain nearly affine in the tensions, 28 DOF",
        toml: include_str!("../../../examples/six-tendon-no-gravity.toml"),
    },
    Preset {
        name: "six-tendon-hanging",
        summary: "IV-C hanging: the arm along −z, the direction of gravity (the other reading), 28 DOF",
        toml: include_str!("../../../examples/six-tendon-hanging.toml"),
    },
];

/// The preset called `name`.
pub fn find(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name == name)
}

/// Comma-separated preset names (for messages).
pub fn names() -> String {
    PRESETS
        .iter()
        .map(|p| p.name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// [`Source::origin`] of a scenario given as text, not read from a file (Python's
/// `Scenario.from_toml(text)`): provenance records it as `"text"` (the resolved TOML holds it).
pub const TEXT_ORIGIN: &str = "<string>";

/// Where a scenario's text came from.
#[derive(Debug, Clone)]
pub struct Source {
    /// The preset name or the file path, for messages.
    pub origin: String,
    /// Name used when the scenario sets none: the preset name or the file stem.
    pub default_name: String,
    pub text: String,
    /// A built-in preset (else a file).
    pub preset: bool,
}

impl Source {
    /// Where the text came from, as provenance records it (with its SHA-256).
    pub fn origin_record(&self) -> ScenarioOrigin {
        let text = !self.preset && self.origin == TEXT_ORIGIN;
        ScenarioOrigin {
            source: match (self.preset, text) {
                (true, _) => "preset",
                (false, true) => "text",
                (false, false) => "file",
            }
            .into(),
            name: self.preset.then(|| self.default_name.clone()),
            path: (!self.preset && !text).then(|| self.origin.clone()),
            sha256: sha256_hex(self.text.as_bytes()),
        }
    }

    /// The provenance of a run of this scenario with the `--set` `overrides`, run as
    /// `scenario_toml` (the resolved TOML), started now.
    pub fn provenance(&self, overrides: &[String], scenario_toml: String) -> Provenance {
        Provenance::of_scenario(self.origin_record(), overrides, scenario_toml)
    }
}

/// Resolves `arg` as a preset name first, then as a file path. A name that is both a preset and a
/// regular file here is refused as ambiguous (`./NAME` names the file): the preset would
/// silently win over the file the user may have meant.
pub fn source(arg: &str) -> Result<Source, ScenarioError> {
    if let Some(p) = find(arg) {
        if Path::new(arg).is_file() {
            return Err(ScenarioError::invalid(
                "SCENARIO",
                format!(
                    "`{arg}` names both the preset `{}` and a file in this directory: write `./{arg}` for the file; the preset is taken only where no such file exists",
                    p.name
                ),
            ));
        }
        return Ok(Source {
            origin: format!("preset `{}`", p.name),
            default_name: p.name.to_string(),
            text: p.toml.to_string(),
            preset: true,
        });
    }
    let path = Path::new(arg);
    if !path.exists() {
        if arg.ends_with(".toml") || arg.contains(std::path::MAIN_SEPARATOR) || arg.contains('/') {
            return Err(ScenarioError::NotFound {
                path: arg.to_string(),
                available: names(),
            });
        }
        return Err(ScenarioError::UnknownPreset {
            name: arg.to_string(),
            available: names(),
        });
    }
    let text = crate::output::read_regular_to_string(path).map_err(|e| {
        crate::scenario::read_error("SCENARIO", path, e, |error| ScenarioError::Io {
            path: arg.to_string(),
            error,
        })
    })?;
    Ok(Source {
        origin: arg.to_string(),
        default_name: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scenario".into()),
        text,
        preset: false,
    })
}

/// Loads a preset or a file and applies `--set` overrides; the scenario's name defaults to the
/// preset name or file stem.
pub fn load(arg: &str, overrides: &[String]) -> Result<Scenario, ScenarioError> {
    load_from(&source(arg)?, overrides)
}

/// [`load`] of a scenario text already read.
pub fn load_from(src: &Source, overrides: &[String]) -> Result<Scenario, ScenarioError> {
    let mut s = Scenario::from_toml(&src.origin, &src.text, overrides)?;
    if s.name.is_none() {
        s.name = Some(src.default_name.clone());
    }
    Ok(s)
}
