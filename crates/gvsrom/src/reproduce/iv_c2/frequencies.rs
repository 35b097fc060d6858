//! Beyond the paper: how well IV-C2's reduced models keep the arm's lowest natural frequencies
//! (`gvsrom modes six-tendon --tension=U,U,U,U,U,U [--model M]`: the undamped linearized
//! eigenproblem about the equilibrium under gravity with every tendon at `U`). A model that cannot
//! answer there (the tensions outside its training inputs, or its equilibrium off its manifold, as
//! for a dynamic autoencoder at some holds) gets a row without numbers and its reason. A reduced
//! model that moves the frequencies of the modes a step excites drifts out of phase with the HOM
//! within the test's seconds; POD's frequencies are Rayleigh–Ritz upper bounds, an autoencoder's
//! need not be.

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
    /// Why a reduced model has no frequencies here (its refusal, one line).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) failure: Option<String>,
}

/// The HOM's and each of `models`' (label, model) lowest [`MODES`] frequencies about the
/// equilibrium with every tendon at `tension` [N].
pub(super) fn natural_frequencies(
    run: &Run,
    scenario: &ScenarioSpec,
    tension: f64,
    models: &[(String, &Step<ModelInfo>)],
) -> anyhow::Result<Step<Vec<Frequencies>>> {
    let tendons = scenario.build()?.0.u.len();
    let pulled: Vec<String> = (0..tendons)
        .map(|k| format!("tendons.{k}.tension={tension}"))
        .collect();
    let spec = scenario.with(&pulled);
    let keys: Vec<(&str, &str)> = models.iter().map(|(l, m)| (l.as_str(), m.key())).collect();
    let config = serde_json::json!({ "scenario": spec, "models": keys, "modes": MODES });
    run.step(
        "iv-c2/frequencies",
        &config,
        |_| true,
        |_| {
            let mut out = vec![of(&spec, "HOM", None)?];
            for (label, model) in models {
                out.push(
                    of(&spec, label, Some(model)).unwrap_or_else(|e| Frequencies {
                        label: label.clone(),
                        dof: model.value.latent,
                        hz: vec![],
                        failure: Some(format!("{e:#}")),
                    }),
                );
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
        reduce::attach(&mut built, &table, &m.path, Default::default())?;
    }
    let (_, report) = crate::modes::compute(&built, MODES)?;
    Ok(Frequencies {
        label: label.into(),
        dof: report.n_dof,
        hz: report.modes.iter().map(|m| m.frequency_hz).collect(),
        failure: None,
    })
}

/// Per model, its frequencies and their deviation from the HOM's, mode by mode, about the
/// equilibrium with every tendon at `tension` [N].
pub(super) fn frequencies_table(f: &[Frequencies], tension: f64) -> Table {
    let hom = f.first().map(|h| h.hz.clone()).unwrap_or_default();
    let rows = f
        .iter()
        .map(|m| {
            let mut row = vec![Cell::text(&m.label), Cell::int(m.dof)];
            for k in 0..MODES {
                match (m.hz.get(k), hom.get(k)) {
                    (Some(hz), Some(h)) => {
                        row.push(Cell::sig(*hz, 4));
                        row.push(Cell::sig(100.0 * (hz / h - 1.0), 2));
                    }
                    _ => row.extend([Cell::text("–"), Cell::text("–")]),
                }
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
        title: format!("Lowest natural frequencies about the equilibrium with every tendon at {tension} N (not in the paper)"),
        columns,
        rows,
        note: format!("Undamped, linearized about the equilibrium under gravity with every tendon at {tension} N, each model about its own equilibrium (`gvsrom modes six-tendon --tension={tension},… [--model M] --count 4`); modes in ascending frequency, the k-th against the HOM's k-th: for the HOM the first bending pair, then the second. About the same equilibrium a Galerkin projection on a fixed basis cannot lower the k-th frequency (Rayleigh–Ritz, Poincaré separation), so a linear basis's frequencies lie at or above the HOM's up to the small shift of its equilibrium; an autoencoder's tangent stiffness also holds the decoder's curvature times the residual force, so its frequencies may lie below. –: the model gave no frequencies there (reason in the notes and results.json)."),
    }
}

/// One note per model without frequencies: its reason.
pub(super) fn frequencies_notes(f: &[Frequencies], tension: f64) -> Vec<String> {
    f.iter()
        .filter_map(|m| {
            let why = m.failure.as_ref()?;
            Some(format!(
                "{} has no natural frequencies about the equilibrium with every tendon at {tension} N: {why}",
                m.label
            ))
        })
        .collect()
}
