//! The statics evaluations of the cases: every model (the HOM and reduced models) at every test
//! input, each one call of `gvsrom statics [--model]`, with the errors against the HOM and the
//! mean solve time that the accuracy and speed tables report.

use super::step::{Run, Step};
use super::tasks::{nan_as_null, ModelInfo, ScenarioSpec};
use crate::dataset::Layout;
use crate::{reduce, statics};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// One model of an evaluation: a label, and a reduced model's directory (None: the HOM).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EvalModel {
    pub label: String,
    pub path: Option<PathBuf>,
    /// The key of the step that made it (so the evaluation is redone when the model changes).
    pub key: String,
}

impl EvalModel {
    pub fn hom() -> EvalModel {
        EvalModel {
            label: "HOM".into(),
            path: None,
            key: String::new(),
        }
    }
    pub fn of(label: &str, step: &Step<ModelInfo>) -> EvalModel {
        EvalModel {
            label: label.into(),
            path: Some(step.path.clone()),
            key: step.key().to_string(),
        }
    }
}

/// One model's equilibrium at one test input.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Solved {
    pub label: String,
    pub dof: usize,
    /// `None` when the solve failed (then `error` says why).
    pub error: Option<String>,
    pub q: Vec<f64>,
    #[serde(with = "nan_as_null::array3")]
    pub tip: [f64; 3],
    /// ξ − ξ* at the points, active components, point-major.
    pub strain: Vec<f64>,
    pub centerline: Vec<[f64; 3]>,
    /// Mean solve time over the repetitions \[s\].
    #[serde(with = "nan_as_null")]
    pub time_s: f64,
    pub iterations: usize,
    /// Against the HOM at the same input (0 for the HOM itself).
    #[serde(with = "nan_as_null")]
    pub strain_error_percent: f64,
    #[serde(with = "nan_as_null")]
    pub tip_error_percent: f64,
}

/// All models at one test input.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EvalPoint {
    /// The overrides that make the input (e.g. `tendons.0.tension=-2.7`).
    pub set: Vec<String>,
    pub models: Vec<Solved>,
}

/// An evaluation: the points' abscissae and components, and every model at every input.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Evaluation {
    pub strain_x: Vec<f64>,
    pub components: Vec<String>,
    pub length: f64,
    pub points: Vec<EvalPoint>,
}

impl Evaluation {
    /// The solutions of model `label` over the inputs.
    pub fn of<'a>(&'a self, label: &'a str) -> impl Iterator<Item = &'a Solved> + 'a {
        self.points
            .iter()
            .filter_map(move |p| p.models.iter().find(|m| m.label == label))
    }
    /// Mean and max of `f` over the inputs for model `label` (NaN if it failed anywhere).
    pub fn stats(&self, label: &str, f: impl Fn(&Solved) -> f64) -> (f64, f64) {
        let v: Vec<f64> = self
            .of(label)
            .map(|s| if s.error.is_some() { f64::NAN } else { f(s) })
            .collect();
        if v.is_empty() || v.iter().any(|x| !x.is_finite()) {
            return (f64::NAN, f64::NAN);
        }
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        (mean, v.iter().copied().fold(f64::MIN, f64::max))
    }
}

/// `gvsrom statics [--model M]` of every model at every input (each input: `scenario` with the
/// overrides `inputs[i]`), sequentially on one thread so that the times compare. Each solve is
/// repeated `repeat` times and its mean time kept (`statics --repeat`).
pub fn statics_eval(
    run: &Run,
    name: &str,
    scenario: &ScenarioSpec,
    inputs: &[Vec<String>],
    models: &[EvalModel],
    repeat: u32,
) -> anyhow::Result<Step<Evaluation>> {
    let config = serde_json::json!({
        "scenario": scenario, "inputs": inputs, "models": models, "repeat": repeat,
    });
    run.step(
        name,
        &config,
        |_| true,
        |_| {
            let mut points = vec![];
            let (base, _) = scenario.build()?;
            let layout = Layout::of(&base);
            for set in inputs {
                run.check_interrupt()?;
                let spec = scenario.with(set);
                let mut solved = vec![];
                let mut hom_report = None;
                for m in models {
                    let (mut built, table) = spec.build()?;
                    if let Some(dir) = &m.path {
                        reduce::attach(&mut built, &table, dir, Default::default())?;
                    }
                    let result = statics::solve_repeated(&built, repeat)
                        .map_err(anyhow::Error::from)
                        .and_then(|r| {
                            statics::check_reduced(&built, &r)
                                .map(|_| r)
                                .map_err(Into::into)
                        });
                    solved.push(match result {
                        Ok(r) => {
                            let (se, te) = match &hom_report {
                                Some(h) => {
                                    let c = statics::compare(&built, h, &r);
                                    (c.strain_error_percent, c.tip_error_percent)
                                }
                                None => (0.0, 0.0),
                            };
                            let s = Solved {
                                label: m.label.clone(),
                                dof: r.n_dof,
                                error: None,
                                q: r.q.clone(),
                                tip: r.tip_position,
                                strain: statics::active_deviations(&built, &r),
                                centerline: r.centerline.clone(),
                                time_s: r.solve_time_s,
                                iterations: r.iterations,
                                strain_error_percent: se,
                                tip_error_percent: te,
                            };
                            if m.path.is_none() {
                                hom_report = Some(r);
                            }
                            s
                        }
                        Err(e) => {
                            anyhow::ensure!(
                                m.path.is_some(),
                                "the full model's statics failed at {}: {e:#}",
                                set.join(" ")
                            );
                            Solved {
                                label: m.label.clone(),
                                dof: built.n_dof(),
                                error: Some(format!("{e:#}")),
                                q: vec![],
                                tip: [f64::NAN; 3],
                                strain: vec![],
                                centerline: vec![],
                                time_s: f64::NAN,
                                iterations: 0,
                                strain_error_percent: f64::NAN,
                                tip_error_percent: f64::NAN,
                            }
                        }
                    });
                }
                points.push(EvalPoint {
                    set: set.clone(),
                    models: solved,
                });
            }
            Ok(Evaluation {
                strain_x: layout.strain_x.clone(),
                components: layout.component_names(),
                length: base.model.disc.length(),
                points,
            })
        },
    )
}
