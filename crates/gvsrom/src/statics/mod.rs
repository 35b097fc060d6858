//! A statics run of a built scenario and its report: the equilibrium `q`, the tip pose, the centreline
//! sampled at equally spaced abscissae, the strain at the computational points, and solver statistics.

use crate::build::Built;
use crate::error::{ScenarioError, StaticsFailure};
use crate::provenance::Provenance;
use gvs::model::Model;
use gvs::solve::statics::{
    ContinuationOutcome, StaticsError, StaticsOptions, StaticsSolver, MAX_RAMP_STEPS,
};
use gvs::strain::StrainParam;
use nalgebra::DVector;
use serde::Serialize;
use std::time::Instant;

mod batch;
mod drive;
mod report;
pub use batch::{along_chain, solve_batch, warm_or_ramp, WARM_MAX_ITERATIONS};
use drive::solve_driven_on;
pub use drive::DriveReport;
use report::report;
pub use report::BodyPosition;

/// The result of one statics solve (this is also the `--json` output).
#[derive(Debug, Clone, Serialize)]
pub struct StaticsReport {
    pub scenario: String,
    /// Tendon tensions u \[N\].
    pub u: Vec<f64>,
    pub n_dof: usize,
    pub n_points: usize,
    /// Generalized coordinates at equilibrium.
    pub q: Vec<f64>,
    /// Tip position in the world frame \[m\].
    pub tip_position: [f64; 3],
    /// Tip rotation matrix (rows), section frame → world.
    pub tip_rotation: [[f64; 3]; 3],
    /// Abscissae of the centreline samples \[m\].
    pub centerline_x: Vec<f64>,
    /// Centreline positions at `centerline_x` \[m\].
    pub centerline: Vec<[f64; 3]>,
    /// Abscissae of the computational points \[m\].
    pub strain_x: Vec<f64>,
    /// ξ at the computational points, `[torsion, bend-y, bend-z, elongation, shear-y, shear-z]`.
    pub strain: Vec<[f64; 6]>,
    /// The reference strain ξ* at the computational points (the unloaded rod's: `[0, 0, 0, 1, 0, 0]`
    /// for a straight one), what strain deviations and errors are measured from.
    pub strain_reference: Vec<[f64; 6]>,
    /// World positions \[m\] of each tendon's thread `r + R d(X)` from its start to its end, at
    /// its ends and at the `centerline_x` between them (cubic Hermite interpolation between its
    /// computational points, as the centreline); empty without tendons.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub tendon_paths: Vec<Vec<[f64; 3]>>,
    /// Each tendon's length \[m\] along its routed thread, `ℓ = ∫ ‖t_u‖ dX` over its span
    /// ([`Model::tendon_lengths`]): what an encoder on its actuator reads, up to a constant.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub tendon_lengths: Vec<f64>,
    /// Each tendon's length \[m\] at rest (the reference strain): `rest − length` is how far its
    /// actuator has pulled it in.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub tendon_rest_lengths: Vec<f64>,
    /// Per rigid body (`[[bodies]]`), the world positions of the section it is fixed to and of
    /// its centre of mass \[m\]; empty without bodies.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub bodies: Vec<BodyPosition>,
    /// Per tendon, how it was driven, when one was driven by its displacement (`u` then holds the
    /// tensions found); empty when every tendon is driven by its tension.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub drives: Vec<DriveReport>,
    /// Tension updates of a displacement-driven solve ([`gvs::solve::tendon_drive`]), `None`
    /// (not written) when every tendon is driven by its tension; each update solves the statics
    /// again (their iterations are in `iterations`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drive_iterations: Option<usize>,
    /// Dogleg iterations over all load stages (and, with displacement drives, all solves).
    pub iterations: usize,
    pub load_stages: usize,
    pub residual_evaluations: usize,
    pub jacobian_evaluations: usize,
    /// `‖R(q)‖∞` at the solution.
    pub residual_norm: f64,
    /// Wall-clock time of the solve alone \[s\].
    pub solve_time_s: f64,
    /// Set when the load ramp stalled, or its equilibrium diverged, and the equilibrium was reached
    /// by arc-length continuation from the straight rod.
    pub continuation: Option<ContinuationSummary>,
    /// `Some(ω²)` \[1/s²\] if the equilibrium is unstable: `M⁻¹ K_T` has the real eigenvalue
    /// `ω² < 0` ([`gvs::solve::stability`]); no stable one connected to the straight rod was found.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub divergence: Option<f64>,
    /// `Some(ω²)` \[1/s²\] if the equilibrium on the path from the straight rod diverged (a
    /// bifurcation: a column compressed past buckling) and this stable one was reached by
    /// releasing the rod displaced along its divergent mode (its overdamped motion).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub buckled: Option<f64>,
    /// Pseudo-time steps of the rod's overdamped motion from the diverging equilibrium to the
    /// stable one (with `buckled`; also counted when that descent found nothing stable).
    #[serde(skip_serializing_if = "is_zero")]
    pub descent_steps: usize,
    /// Whether the equilibrium's stability was judged (`solver.check_stability`, default true);
    /// without it, `divergence` is never set.
    pub stability_checked: bool,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// How the arc-length continuation reached the equilibrium ([`gvs::solve::continuation`]).
#[derive(Debug, Clone, Serialize)]
pub struct ContinuationSummary {
    /// Accepted and rejected arc-length steps.
    pub steps: usize,
    pub rejected_steps: usize,
    /// The load factor at each fold passed, in order.
    pub folds: Vec<f64>,
    /// The largest load factor on the path before it reached 1.
    pub lambda_max: f64,
    /// `Some(ω²)` \[1/s²\] if it ran because the step from the straight rod converged onto an
    /// unstable equilibrium (the real eigenvalue `ω² < 0` of `M⁻¹ K_T` there), not because the
    /// ramp stalled.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub after_unstable: Option<f64>,
}

impl StaticsReport {
    /// Tip rotation as a unit axis and an angle \[rad\] (axis `[1, 0, 0]` for the identity).
    pub fn tip_axis_angle(&self) -> ([f64; 3], f64) {
        let r = self.tip_rotation;
        let m = nalgebra::Matrix3::from_fn(|i, j| r[i][j]);
        let rot = nalgebra::Rotation3::from_matrix_unchecked(m);
        match rot.axis_angle() {
            Some((axis, angle)) => ([axis[0], axis[1], axis[2]], angle),
            None => ([1.0, 0.0, 0.0], 0.0),
        }
    }
}

/// Solves the statics of `built` from the straight reference and samples the solution. A
/// non-convergence names the scenario's largest load ([`crate::plausibility::largest_load`]) and
/// suggests more ramp steps.
///
/// With a tendon driven by its displacement ([`Built::drives`]) the tensions are found
/// ([`gvs::solve::tendon_drive`]): the report's `u` holds them and `drives` says which tendon is
/// slack.
pub fn solve(built: &Built) -> Result<StaticsReport, StaticsFailure> {
    if built.displacement_driven() {
        return match &built.reduced {
            Some(r) => solve_driven_on(built, &r.model),
            None => solve_driven_on(built, &built.model),
        };
    }
    solve_under(built, &built.u)
}

/// [`solve`] under the tensions `u` \[N\] in place of the scenario's, one per tendon: the same
/// equilibrium as a scenario built with these tensions (`--tension`), without building it again.
/// Check `u` first with [`Built::tensions`] (and, with a reduced model attached,
/// [`crate::build::Reduced::covers_tensions`]). A reduced model starts from its initial guess at
/// `u` ([`crate::build::Reduced::initial_at`]), as in a scenario built with these tensions.
pub fn solve_under(built: &Built, u: &[f64]) -> Result<StaticsReport, StaticsFailure> {
    match &built.reduced {
        Some(r) => solve_on(built, &r.model, u, r.initial_at(u).as_ref()),
        None => solve_on(built, &built.model, u, None),
    }
}

/// [`solve_under`] as a run answers it: for an attached reduced model, the solution must also lie
/// where the model was trained (`Reduced::check_range`), else the error names the likely cause.
pub fn solve_checked(built: &Built, u: &[f64]) -> anyhow::Result<StaticsReport> {
    let report = solve_under(built, u)?;
    check_reduced(built, &report)?;
    Ok(report)
}

/// [`solve`] as a run answers it ([`solve_checked`] with the tendons driven as the scenario says:
/// by displacement where it gives one).
pub fn solve_as_built(built: &Built) -> anyhow::Result<StaticsReport> {
    let report = solve(built)?;
    check_reduced(built, &report)?;
    Ok(report)
}

/// For an attached reduced model, whether its solution `report` is to be trusted: inside the
/// training encodings' range (`Reduced::check_range`) and not a spurious straight rod
/// (`check_not_spurious_rest`); else the error names the likely cause. Nothing to check for the
/// full model.
pub fn check_reduced(built: &Built, report: &StaticsReport) -> Result<(), ScenarioError> {
    if let Some(r) = &built.reduced {
        // tensions found for displacement drives: inside the training inputs, as given ones
        // must be (with --extrapolate, said when the model was attached)
        let outside = match built.displacement_driven() && !r.extrapolate {
            true => r.found_tensions_outside(&report.u, &built.drive_flags()),
            false => vec![],
        };
        if !outside.is_empty() {
            return Err(ScenarioError::invalid(
                "--model",
                format!(
                    "`{}` was not trained for the tensions these displacements need: {}; pass --extrapolate to use it anyway (its answer is then an extrapolation)",
                    r.path.display(),
                    outside.join("; ")
                ),
            ));
        }
        r.check_range(&report.q)?;
        // held tendons may lock a reduced model straight: no sign of a spurious root there
        if !built.displacement_driven() {
            check_not_spurious_rest(built, report)?;
        }
    }
    Ok(())
}

/// Refuses a reduced solution that is the straight rod (every `|ξ − ξ*| ≤ 1e-9`) where the full
/// model's straight rod is not an equilibrium (its residual above the solver's tolerance): a
/// spurious root where the decoder degenerates. A [`rom::nn::DecoderForm::Scaled`] decoder maps
/// the whole line `z₁ = 0` to the straight rod; there `C_z`'s other columns vanish and the reduced
/// residual's first component `−c̃(0, z₂)ᵀ f` vanishes wherever `c̃` is orthogonal to the load, a
/// saddle of the reduced potential that Newton can reach from a poor guess.
fn check_not_spurious_rest(built: &Built, report: &StaticsReport) -> Result<(), ScenarioError> {
    let m = &built.model;
    let off = report
        .strain
        .iter()
        .enumerate()
        .map(|(j, xi)| {
            let star = m.xi_star(j);
            (0..6).map(|a| (xi[a] - star[a]).abs()).fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    if off > 1e-9 {
        return Ok(());
    }
    let loads = m.prepare_loads(&built.loads)?;
    let mut ws = m.workspace();
    let mut res = DVector::zeros(m.n_dof());
    m.statics_residual(
        &DVector::zeros(m.n_dof()),
        &report.u,
        &loads,
        &mut ws,
        &mut res,
    );
    let tol = built.options.ftol * ws.residual_scale;
    if res.amax() <= tol {
        return Ok(());
    }
    Err(ScenarioError::invalid(
        "--model",
        format!(
            "the reduced solution q_r = {:?} is the straight rod, which is not an equilibrium of the full model under these inputs (its residual there is {:.3e}, the tolerance {:.1e}): a spurious root where the decoder maps several coordinates to the straight rod (a scaled decoder's z₁ = 0), reached from a poor initial guess. The model is poor here (more data, or more training)",
            report.q,
            res.amax(),
            tol
        ),
    ))
}

/// [`solve`] `repeat` times (≥ 1); the report's `solve_time_s` is the mean over the repetitions.
pub fn solve_repeated(built: &Built, repeat: u32) -> Result<StaticsReport, StaticsFailure> {
    repeated(repeat, || solve(built))
}

/// `solve()` `repeat` times (≥ 1): the first report, its `solve_time_s` the mean.
fn repeated(
    repeat: u32,
    mut solve: impl FnMut() -> Result<StaticsReport, StaticsFailure>,
) -> Result<StaticsReport, StaticsFailure> {
    let mut report = solve()?;
    let mut total = report.solve_time_s;
    for _ in 1..repeat {
        total += solve()?.solve_time_s;
    }
    report.solve_time_s = total / repeat.max(1) as f64;
    Ok(report)
}

/// The full model's equilibrium under the scenario's tensions, whether or not a reduced model
/// is attached: the reference of `statics --model --compare`.
pub fn solve_full(built: &Built, repeat: u32) -> Result<StaticsReport, StaticsFailure> {
    if built.displacement_driven() {
        return repeated(repeat, || solve_driven_on(built, &built.model));
    }
    repeated(repeat, || solve_on(built, &built.model, &built.u, None))
}

/// A `statics` run ([`run`]): the equilibrium of the model that runs and, with `compare`, the
/// full model's with the reduced one's errors against it.
pub struct StaticsRun {
    pub report: StaticsReport,
    /// The full model's equilibrium (`--compare` with a reduced model).
    pub full: Option<StaticsReport>,
    pub comparison: Option<Comparison>,
}

/// `gvsrom statics`: the equilibrium of `built` ([`solve_repeated`], `repeat` solves timed). For
/// an attached reduced model, its solution must lie where the model was trained
/// (`Reduced::check_range`), and with `compare` the full model is solved too and compared.
pub fn run(built: &Built, repeat: u32, compare_full: bool) -> anyhow::Result<StaticsRun> {
    let report = solve_repeated(built, repeat)?;
    if built.reduced.is_none() {
        return Ok(StaticsRun {
            report,
            full: None,
            comparison: None,
        });
    };
    check_reduced(built, &report)?;
    let (full, comparison) = if compare_full {
        let full = solve_full(built, repeat)?;
        let c = compare(built, &full, &report);
        (Some(full), Some(c))
    } else {
        (None, None)
    };
    Ok(StaticsRun {
        report,
        full,
        comparison,
    })
}

impl StaticsRun {
    /// The `--json` document of this run of `built`, made as `provenance` records.
    pub fn json<'a>(&'a self, built: &Built, provenance: &'a Provenance) -> StaticsJson<'a> {
        StaticsJson {
            report: &self.report,
            model: built.reduced.as_ref().map(|r| r.path.display().to_string()),
            model_extrapolated: built.model_extrapolated(&self.report.u),
            comparison: self.comparison.clone(),
            provenance: Some(provenance),
        }
    }
}

/// [`solve`] on `model`: the scenario's own or a reduced one with the same rod, points and tendons.
///
/// With an initial guess `q0` (a reduced model's, from its anchors: `reduce::anchor_guess`), the full
/// load is first solved from `q0` in one stage; if that fails, the scenario's load ramp from rest
/// follows.
fn solve_on<P: StrainParam>(
    built: &Built,
    model: &Model<P>,
    u: &[f64],
    q0: Option<&DVector<f64>>,
) -> Result<StaticsReport, StaticsFailure> {
    let t0 = Instant::now();
    let warm = q0.and_then(|q0| {
        let options = StaticsOptions {
            ramp_steps: 1,
            min_increment: 1.0,
            ..built.options.clone()
        };
        StaticsSolver::new(model, options)
            .solve(u, &built.loads, Some(q0))
            .ok()
    });
    let sol = match warm {
        Some(sol) => sol,
        None => StaticsSolver::new(model, built.options.clone())
            .solve(u, &built.loads, None)
            .map_err(|error| failure(built, u, error))?,
    };
    let solve_time_s = t0.elapsed().as_secs_f64();
    Ok(report(
        built,
        model,
        u,
        &sol,
        solve_time_s,
        &mut model.workspace(),
    ))
}

/// The `--json` document: the report, the reduced model used and the comparison with the full model.
#[derive(Debug, Serialize)]
pub struct StaticsJson<'a> {
    #[serde(flatten)]
    pub report: &'a StaticsReport,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    /// How the scenario lies outside what the model was trained on (`--extrapolate`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub model_extrapolated: Vec<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub comparison: Option<Comparison>,
    /// How the solution was made ([`crate::provenance`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub provenance: Option<&'a crate::provenance::Provenance>,
}

/// A reduced equilibrium against the full model's (`statics --model --compare`), see `rom::metrics`.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    /// Mean absolute strain error over the points and active components, % of the HOM's peak
    /// |ξ − ξ*|.
    pub strain_error_percent: f64,
    /// Tip position error, % of the rod length.
    pub tip_error_percent: f64,
    /// Largest tendon length error `max_k |ℓ_k,rom − ℓ_k,hom|` \[mm\]: what an actuator under
    /// position control would see (`None` without tendons).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tendon_length_error_mm: Option<f64>,
    pub hom_tip_position: [f64; 3],
    pub hom_solve_time_s: f64,
    pub rom_solve_time_s: f64,
    /// `hom_solve_time_s / rom_solve_time_s` (same process, same run).
    pub speedup: f64,
}

/// Strain deviations `ξ − ξ*` of a report at its points, the active components of `built` only.
pub fn active_deviations(built: &Built, report: &StaticsReport) -> Vec<f64> {
    let active = crate::layout::Layout::of(built).active;
    let m = &built.model;
    report
        .strain
        .iter()
        .enumerate()
        .flat_map(|(j, xi)| {
            let star = m.xi_star(j);
            active.iter().map(move |&a| xi[a] - star[a])
        })
        .collect()
}

/// Compares a reduced solution `rom` with the full one `hom` of the same scenario.
pub fn compare(built: &Built, hom: &StaticsReport, rom: &StaticsReport) -> Comparison {
    let length = built.model.disc.length();
    Comparison {
        strain_error_percent: rom::metrics::strain_error_percent(
            &active_deviations(built, hom),
            &active_deviations(built, rom),
        ),
        tip_error_percent: rom::metrics::tip_error_percent(
            &hom.tip_position,
            &rom.tip_position,
            length,
        ),
        tendon_length_error_mm: (hom.tendon_lengths.iter().zip(&rom.tendon_lengths))
            .map(|(a, b)| 1e3 * (a - b).abs())
            .reduce(f64::max),
        hom_tip_position: hom.tip_position,
        hom_solve_time_s: hom.solve_time_s,
        rom_solve_time_s: rom.solve_time_s,
        speedup: hom.solve_time_s / rom.solve_time_s.max(1e-12),
    }
}

/// The engine's error with, for a non-convergence, the largest load and a remedy.
fn failure(built: &Built, u: &[f64], error: StaticsError) -> StaticsFailure {
    let mut hint = String::new();
    if let StaticsError::DriveNotReached { .. } = error {
        let asked: Vec<String> = (built.displacement.iter().enumerate())
            .filter_map(|(k, d)| {
                d.map(|d| {
                    format!(
                        "tendons[{k}].displacement = {} m",
                        crate::build::significant(d)
                    )
                })
            })
            .collect();
        hint.push_str(&format!(
            "; asked: {} (lower it, or drive by tension)",
            asked.join(", ")
        ));
    }
    if let StaticsError::NotConverged {
        continuation,
        ref reason,
        ..
    } = error
    {
        if let Some(load) = crate::plausibility::largest_load(built, u, 1.0) {
            hint.push_str(&format!("; {load}"));
        }
        let steps = built.options.ramp_steps;
        let cap = built.options.max_iterations;
        let default_cap = gvs::solve::statics::StaticsOptions::default().max_iterations;
        // the scenario's own iteration cap stopped the solves: that, not the load, is the remedy
        let capped = cap < default_cap
            && reason.contains(&format!("maximum number of iterations ({cap}) reached"));
        match continuation {
            _ if capped => {
                hint.push_str(&format!(
                    "; solver.max_iterations = {cap} stopped the solves (the default is {default_cap}): raise it"
                ));
                if continuation == ContinuationOutcome::NotTried && steps < MAX_RAMP_STEPS {
                    let more = (steps * 10).clamp(10, MAX_RAMP_STEPS);
                    hint.push_str(&format!(", then, if it still fails, try solver.ramp_steps = {more}"));
                }
            }
            // continuation from the straight rod already failed (the reason says where and why)
            ContinuationOutcome::Stopped => hint.push_str(
                "; the equilibria from the straight rod were followed by continuation and do not reach the full load: a finer ramp will not help; lower the load",
            ),
            ContinuationOutcome::Reached => hint.push_str(
                "; continuation reached the full load, but the solve there did not converge: lower the load, or loosen solver.ftol",
            ),
            ContinuationOutcome::NotTried if steps < MAX_RAMP_STEPS => {
                let more = (steps * 10).clamp(10, MAX_RAMP_STEPS);
                hint.push_str(&format!("; try solver.ramp_steps = {more}"));
            }
            ContinuationOutcome::NotTried => {
                hint.push_str("; lower the load: the ramp is already at its limit")
            }
        }
    }
    StaticsFailure { error, hint }
}

/// `c` material abscissae X equally spaced on `[0, L]` (the undeformed arc length), both ends included (`c ≥ 2`): the
/// centreline samples of `statics --json` and of a trajectory.
pub fn centerline_abscissae(length: f64, c: usize) -> Vec<f64> {
    let c = c.max(2);
    (0..c).map(|i| length * i as f64 / (c - 1) as f64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn not_converged(continuation: ContinuationOutcome) -> StaticsError {
        StaticsError::NotConverged {
            load_factor: 0.5,
            iterations: 9,
            residual_norm: 1.0,
            tolerance: 1e-10,
            reason: "test".into(),
            continuation,
        }
    }

    fn built6() -> Built {
        crate::build(&crate::presets::load("six-tendon", &[]).unwrap()).unwrap()
    }

    #[test]
    fn the_remedy_of_a_failed_solve_follows_what_was_tried() {
        let built = crate::build(&crate::presets::load("single-tendon", &[]).unwrap()).unwrap();
        let hint = |e| failure(&built, &[-3.0], e).hint;
        // the ramp alone was tried: a finer one
        let h = hint(not_converged(ContinuationOutcome::NotTried));
        assert!(h.contains("try solver.ramp_steps = 10"), "{h}");
        // continuation from the straight rod stopped short of the full load: no finer ramp
        let h = hint(not_converged(ContinuationOutcome::Stopped));
        assert!(
            h.contains("do not reach the full load: a finer ramp will not help; lower the load")
                && !h.contains("ramp_steps ="),
            "{h}"
        );
        // it reached the full load but the last solve did not converge
        let h = hint(not_converged(ContinuationOutcome::Reached));
        assert!(
            h.contains("loosen solver.ftol") && !h.contains("ramp_steps ="),
            "{h}"
        );
        // the scenario's own iteration cap stopped every solve (a load the defaults solve): the
        // remedy is to raise it, not to lower the load
        let mut capped = crate::presets::load("single-tendon", &[]).unwrap();
        capped.solver.max_iterations = 1;
        let e = crate::statics::solve_checked(&crate::build(&capped).unwrap(), &[-5.0])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(
                "solver.max_iterations = 1 stopped the solves (the default is 400): raise it"
            ) && !e.contains("lower the load"),
            "{e}"
        );
        assert!(crate::statics::solve_checked(&built, &[-5.0]).is_ok());
        // a load continuation cannot follow to the end, through the CLI
        let e = crate::statics::solve_checked(&built6(), &[-200.0, 0.0, 0.0, 0.0, 0.0, 0.0])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("then from the straight rod, continuation stopped at")
                && e.contains("a finer ramp will not help")
                && !e.contains("ramp_steps ="),
            "{e}"
        );
    }
}
