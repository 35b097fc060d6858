//! How an output was made: the `"provenance"` object of `statics --json`, of a trajectory's, a
//! dataset's and a model's `meta.json` — enough to run it again.
//!
//! | key | content |
//! |---|---|
//! | `gvsrom_version` | the crate version that wrote it |
//! | `command` | the command line (argv, lossily UTF-8) |
//! | `cwd` | the working directory it ran in, against which the relative paths of `command` and of the input directories below resolve |
//! | `started` | wall-clock start, UTC, RFC 3339 (`2025-06-01T12:34:56Z`) |
//! | `scenario` | where the scenario came from: `{"source": "preset", "name": …}`, `{"source": "file", "path": …}` or `{"source": "text"}` (Python's `Scenario.from_toml(text)`), with the SHA-256 of its text (`sha256`) |
//! | `overrides` | every `--set PATH=VALUE`, in order |
//! | `scenario_toml` | the scenario as run (after `--set`, `--tension`, `--centerline-points`): `gvsrom statics FILE` on this text alone solves the same problem |
//! | `seeds` | every seed, by what it seeds (`{"input": 1}`, `{"plan": 0}`, `{"training": 0}`) |
//! | `input` | a run's actuation (`simulate::input_record`) |
//! | `sampling` | a dynamics run's `duration` \[s\] and `sample_rate` \[Hz\] |
//! | `integrator` | a dynamics run's method and tolerances (`simulate::integrator_record`) |
//! | `solver` | a statics run's solver options (the scenario's `[solver]`) |
//! | `model`, `dataset`, `reference`, `run` | an input directory (`compare`'s trajectories for the last two): its path and the hashes its manifest records (`meta_sha256`, `sha256` per file) |
//! | `more_datasets` | a model made from several datasets: those after the first, in order, each as `dataset` |
//! | `plotted` | the output `plot` drew: a directory as `model`, a `statics --json` file by its path and the SHA-256 of its bytes as read (under its file name in `sha256`) |
//!
//! Keys that do not apply are left out. One struct, [`Provenance`], builds them all.

use crate::output::MANIFEST_KEY;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::{SystemTime, UNIX_EPOCH};

/// How an output was made (see the module documentation for each key).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    pub gvsrom_version: String,
    pub command: Vec<String>,
    /// The working directory of the run (absent in outputs written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cwd: Option<String>,
    pub started: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scenario: Option<ScenarioOrigin>,
    #[serde(default)]
    pub overrides: Vec<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scenario_toml: Option<String>,
    #[serde(default)]
    pub seeds: BTreeMap<String, u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub input: Option<Value>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampling: Option<Sampling>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub integrator: Option<Value>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solver: Option<Value>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<DirOrigin>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dataset: Option<DirOrigin>,
    /// A model made from several datasets: those after the first (`dataset`), in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub more_datasets: Vec<DirOrigin>,
    /// `compare`'s two trajectories.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<DirOrigin>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub run: Option<DirOrigin>,
    /// The output `plot` drew.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plotted: Option<DirOrigin>,
}

/// The time span and output rate of a dynamics run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sampling {
    /// Simulated time \[s\] (`--duration`).
    pub duration: f64,
    /// Output samples per second \[Hz\] (`--sample-rate`).
    pub sample_rate: f64,
}

/// Where a scenario's text came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScenarioOrigin {
    /// `"preset"`, `"file"`, or `"text"` (given as text in Python: `scenario_toml` holds it).
    pub source: String,
    /// The preset's name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The file's path, as given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<String>,
    /// SHA-256 of the text read (before `--set`).
    pub sha256: String,
}

/// An input directory written by gvsrom (a model, a dataset): its path and the hashes its manifest
/// records, which identify its content ([`crate::output::integrity`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DirOrigin {
    pub path: String,
    /// The manifest's `meta_sha256` (absent for an output written before hashes were recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub meta_sha256: Option<String>,
    /// The manifest's `sha256`: file name → SHA-256.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub sha256: BTreeMap<String, String>,
}

impl Provenance {
    /// A run of the scenario read from `origin` with the `--set` `overrides`, run as
    /// `scenario_toml`; started now, by this process's command line.
    pub fn of_scenario(
        origin: ScenarioOrigin,
        overrides: &[String],
        scenario_toml: String,
    ) -> Provenance {
        let mut p = Provenance::of_command();
        p.scenario = Some(origin);
        p.overrides = overrides.to_vec();
        p.scenario_toml = Some(scenario_toml);
        p
    }

    /// An output made without a scenario (a model from a dataset): the version, the command line
    /// and the start time.
    pub fn of_command() -> Provenance {
        Provenance {
            gvsrom_version: env!("CARGO_PKG_VERSION").into(),
            command: std::env::args_os()
                .map(|a| a.to_string_lossy().into_owned())
                .collect(),
            cwd: std::env::current_dir()
                .ok()
                .map(|d| d.to_string_lossy().into_owned()),
            started: rfc3339_utc(SystemTime::now()),
            scenario: None,
            overrides: vec![],
            scenario_toml: None,
            seeds: BTreeMap::new(),
            input: None,
            sampling: None,
            integrator: None,
            solver: None,
            model: None,
            dataset: None,
            more_datasets: vec![],
            reference: None,
            run: None,
            plotted: None,
        }
    }

    /// Records the seed of `what` (`"input"`, `"plan"`, `"training"`).
    pub fn seed(mut self, what: &str, seed: u64) -> Self {
        self.seeds.insert(what.into(), seed);
        self
    }

    pub fn input(mut self, input: Value) -> Self {
        self.input = Some(input);
        self
    }

    /// A dynamics run's `duration` \[s\] and `sample_rate` \[Hz\].
    pub fn sampling(mut self, duration: f64, sample_rate: f64) -> Self {
        self.sampling = Some(Sampling {
            duration,
            sample_rate,
        });
        self
    }

    pub fn integrator(mut self, integrator: Value) -> Self {
        self.integrator = Some(integrator);
        self
    }

    /// The statics solver's options.
    pub fn solver(mut self, options: &gvs::solve::statics::StaticsOptions) -> Self {
        self.solver = serde_json::to_value(options).ok();
        self
    }

    /// The reduced model a run used (`--model`), by its manifest's hashes as it was loaded.
    pub fn model(mut self, model: &DirOrigin) -> Self {
        self.model = Some(model.clone());
        self
    }

    /// The model a training started from (`train --init`), by its manifest's hashes as it was
    /// loaded.
    pub fn start_model(self, model: &DirOrigin) -> Self {
        self.model(model)
    }

    /// `compare`'s reference and run trajectories, by their manifests' hashes as they were read.
    pub fn compared(mut self, reference: &DirOrigin, run: &DirOrigin) -> Self {
        self.reference = Some(reference.clone());
        self.run = Some(run.clone());
        self
    }

    /// The output `plot` drew, as it was read.
    pub fn plotted(mut self, origin: DirOrigin) -> Self {
        self.plotted = Some(origin);
        self
    }

    /// The dataset a model was made from, by its manifest's hashes as it was read.
    pub fn dataset(mut self, dataset: &DirOrigin) -> Self {
        self.dataset = Some(dataset.clone());
        self
    }
}

impl DirOrigin {
    /// The directory `dir` with no hashes (an output whose manifest records none).
    pub fn unhashed(dir: &Path) -> DirOrigin {
        DirOrigin {
            path: dir.display().to_string(),
            meta_sha256: None,
            sha256: BTreeMap::new(),
        }
    }

    /// The single-file output `path` (a `statics --json` result) by the SHA-256 of `bytes`, its
    /// content as read.
    pub fn of_file(path: &Path, bytes: &[u8]) -> DirOrigin {
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into(),
        );
        DirOrigin {
            path: path.display().to_string(),
            meta_sha256: None,
            sha256: BTreeMap::from([(name, sha256_hex(bytes))]),
        }
    }

    /// The gvsrom output directory `dir` by the hashes of the manifest in `meta` — its meta.json
    /// as the loader checked and parsed it ([`crate::output::Verified::meta`]), so that what a
    /// provenance records is what was read, not the directory as it is later. An output written
    /// before hashes were recorded has none.
    pub fn of_manifest(dir: &Path, meta: &Value) -> DirOrigin {
        let manifest = &meta[MANIFEST_KEY];
        let sha256 = manifest["sha256"]
            .as_object()
            .map(|m| {
                m.iter()
                    .filter_map(|(k, v)| Some((k.clone(), v.as_str()?.to_string())))
                    .collect()
            })
            .unwrap_or_default();
        DirOrigin {
            path: dir.display().to_string(),
            meta_sha256: manifest["meta_sha256"].as_str().map(str::to_string),
            sha256,
        }
    }
}

/// The SHA-256 of `bytes` as 64 lowercase hex digits.
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::{Digest, Sha256};
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// `t` as an RFC 3339 UTC timestamp to the second, `YYYY-MM-DDThh:mm:ssZ` (a time before 1970
/// reads as the epoch).
pub fn rfc3339_utc(t: SystemTime) -> String {
    let secs = t.duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let (days, rem) = (secs / 86_400, secs % 86_400);
    let (y, m, d) = civil_from_days(days as i64);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

/// The proleptic Gregorian date `(year, month, day)` of `z` days after 1970-01-01 (H. Hinnant,
/// "chrono-Compatible Low-Level Date Algorithms", `civil_from_days`).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097); // [0, 146096]
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365; // [0, 399]
    let y = yoe + era * 400;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100); // [0, 365]
    let mp = (5 * doy + 2) / 153; // [0, 11], from March
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (if m <= 2 { y + 1 } else { y }, m, d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn timestamps_match_known_dates() {
        // `date -u -d @SECONDS +%Y-%m-%dT%H:%M:%SZ`
        let at = |s: u64| rfc3339_utc(UNIX_EPOCH + Duration::from_secs(s));
        assert_eq!(at(0), "1970-01-01T00:00:00Z");
        assert_eq!(at(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(at(1_709_251_199), "2024-02-29T23:59:59Z");
        assert_eq!(at(1_735_689_600), "2025-01-01T00:00:00Z");
        assert_eq!(at(4_102_444_800), "2100-01-01T00:00:00Z");
    }

    #[test]
    fn sha256_of_the_empty_string_is_the_standard_one() {
        assert_eq!(
            sha256_hex(b""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
    }
}
