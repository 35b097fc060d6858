//! Beyond the paper: how well IV-C2's reduced models keep the arm's lowest natural frequencies
//! (`gvsrom modes six-tendon --tension=0,0,0,0,0,0 [--model M]`: the undamped linearized
//! eigenproblem about the unloaded equilibrium under gravity). A reduced model that moves the
//! frequencies of the modes a step excites drifts out of phase with the HOM within the test's
//! seconds; POD's frequencies are Rayleigh–Ritz upper bounds, an autoencoder's need not be.

use super::super::report::{Cell, Table};
use super::super::step::Step;
use super::super::tasks::{ModelInfo, ScenarioSpec};
use super::super::Run;
use crate::reduce;
use serde::{Deserialize, Serialize};

/// Modes compared (the two lowest bending pairs of the arm).
pub(super) const MODES: usize = 4;

/// One model's lowest natural frequencies [Hz], ascending.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct Frequencies {
    pub(super) label: String,
    pub(super) dof: usize,
    pub(super) hz: Vec<f64>,
}

/// The HOM's and each of `models`' (label, model) lowest [`MODES`] frequencies about the
/// equilibrium with every tendon slack.
pub(super) fn natural_frequencies(
    run: &Run,
    scenario: &ScenarioSpec,
    models: &[(String, &Step<ModelInfo>)],
) -> anyhow::Result<Step<Vec<Frequencies>>> {
    let tendons = scenario.build()?.0.u.len();
    let slack: Vec<String> = (0..tendons)
        .map(|k| format!("tendons.{k}.tension=0"))
        .collect();
    let spec = scenario.with(&slack);
    let keys: Vec<(&str, &str)> = models.iter().map(|(l, m)| (l.as_str(), m.key())).collect();
    let config = serde_json::json!({ "scenario": spec, "models": keys, "modes": MODES });
    run.step(
        "iv-c2/frequencies",
        &config,
        |_| true,
        |_| {
            let mut out = vec![of(&spec, "HOM", None)?];
            for (label, model) in models {
                out.push(of(&spec, label, Some(model))?);
            }
            Ok(out)
        },
    )
}

fn of(
    spec: &ScenarioSpec,
    label: &str,
    model: Option<&Step<ModelInfo>>,
) -> anyhow::Result<Frequencies> {
    let (mut built, table) = spec.build()?;
    if let Some(m) = model {
        let options = reduce::AttachOptions {
            extrapolate: false,
            tensions_from_signal: false,
        };
        reduce::attach(&mut built, &table, &m.path, options)?;
    }
    let (_, report) = crate::modes::compute(&built, MODES)?;
    Ok(Frequencies {
        label: label.into(),
        dof: report.n_dof,
        hz: report.modes.iter().map(|m| m.frequency_hz).collect(),
    })
}

/// Per model, its frequencies and their deviation from the HOM's, mode by mode.
pub(super) fn frequencies_table(f: &[Frequencies]) -> Table {
    let hom = f.first().map(|h| h.hz.clone()).unwrap_or_default();
    let rows = f
        .iter()
        .map(|m| {
            let mut row = vec![Cell::text(&m.label), Cell::int(m.dof)];
            for (k, hz) in m.hz.iter().enumerate() {
                let off = hom.get(k).map_or(f64::NAN, |h| 100.0 * (hz / h - 1.0));
                row.push(Cell::sig(*hz, 4));
                row.push(Cell::sig(off, 2));
            }
            row
        })
        .collect();
    let mut columns = vec!["model".to_string(), "DOF".to_string()];
    for k in 1..=MODES {
        columns.push(format!("f{k} [Hz]"));
        columns.push(format!("f{k} off the HOM's [%]"));
    }
    Table {
        id: "frequencies".into(),
        title: "Lowest natural frequencies about the unloaded equilibrium (not in the paper)".into(),
        columns,
        rows,
        note: "Undamped, linearized about the equilibrium under gravity with every tendon slack, each model about its own equilibrium (`gvsrom modes six-tendon --tension=0,0,0,0,0,0 [--model M] --count 4`); modes in ascending frequency, the k-th against the HOM's k-th: for the HOM the first bending pair (about z, then y: the sag splits it), then the second. About the same equilibrium a Galerkin projection on a fixed basis cannot lower the k-th frequency (Rayleigh–Ritz, Poincaré separation), so a linear basis's frequencies lie at or above the HOM's up to the small shift of its equilibrium; an autoencoder's tangent stiffness also holds the decoder's curvature times the residual force, so its frequencies may lie below.".into(),
    }
}
