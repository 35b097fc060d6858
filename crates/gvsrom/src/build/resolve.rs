//! A scenario as a run asks for it — a preset name or a file, its `--set` overrides, then the
//! tensions, displacements and centreline points of `--tension`, `--displacement` and
//! `--centerline-points` — read, built and
//! given the provenance of a run of it. Every front-end resolves scenarios this way.

use super::{build, Built};
use crate::presets::{self, Source};
use crate::provenance::Provenance;
use crate::scenario::Scenario;
use anyhow::Context;

/// What a run asks for: the scenario's source and what changes it.
#[derive(Debug, Clone, Copy, Default)]
pub struct Request<'a> {
    /// A preset name or the path of a scenario TOML file ([`presets::source`]).
    pub source: &'a str,
    /// `--set PATH=VALUE` overrides, in order.
    pub overrides: &'a [String],
    /// Tendon tensions in place of the scenario's (one for every tendon or one per tendon),
    /// applied after the overrides.
    pub tensions: Option<&'a [f64]>,
    /// Tendon displacements \[m\] driving the tendons in place of their tensions (one for every
    /// tendon or one per tendon), applied after the overrides.
    pub displacements: Option<&'a [f64]>,
    /// Centreline samples in place of `output.centerline_points`.
    pub centerline_points: Option<usize>,
}

/// A resolved scenario: where it came from, the scenario as run, its engine model, and the
/// provenance of a run of it (started now; the run adds its own options).
pub struct Resolved {
    pub source: Source,
    /// The `--set` overrides applied to the source's text.
    pub overrides: Vec<String>,
    pub scenario: Scenario,
    pub built: Built,
    pub provenance: Provenance,
}

/// Reads, overrides and builds the scenario of `request`. Errors name the option or TOML field.
pub fn resolve(request: &Request) -> anyhow::Result<Resolved> {
    let source = presets::source(request.source)?;
    let mut scenario = presets::load_from(&source, request.overrides)?;
    if let Some(u) = request.tensions {
        scenario.set_tensions(u).context("--tension")?;
    }
    if let Some(d) = request.displacements {
        scenario.set_displacements(d).context("--displacement")?;
    }
    if let Some(n) = request.centerline_points {
        scenario.output.centerline_points = n;
    }
    let built = build(&scenario)?;
    let provenance = source.provenance(request.overrides, scenario.to_toml()?);
    Ok(Resolved {
        source,
        overrides: request.overrides.to_vec(),
        scenario,
        built,
        provenance,
    })
}
