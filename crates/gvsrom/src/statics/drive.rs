//! Statics with tendons driven by their displacement ([`gvs::solve::tendon_drive`]) as a run
//! answers it: the tension bounds of the plausibility check, the report's drives, and the tensions
//! found held to the check a given tension meets.

use super::{failure, report::report, StaticsReport};
use crate::build::Built;
use crate::error::StaticsFailure;
use gvs::model::Model;
use gvs::solve::tendon_drive::solve_driven_within;
use gvs::strain::StrainParam;
use serde::Serialize;
use std::time::Instant;

/// How a tendon was driven ([`StaticsReport::drives`]).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct DriveReport {
    /// The displacement δ \[m\] it was wound in by (negative: paid out), or `None` if it was
    /// driven by its tension.
    pub displacement: Option<f64>,
    /// A displacement-driven tendon whose path is shorter than the tendon: slack, `u = 0`.
    pub slack: bool,
}

/// [`solve`] on `model` with the tendons driven as `built` says ([`Built::drives`]): the
/// tensions of the displacement-driven ones found, from the straight rod.
pub(super) fn solve_driven_on<P: StrainParam>(
    built: &Built,
    model: &Model<P>,
) -> Result<StaticsReport, StaticsFailure> {
    let t0 = Instant::now();
    let drives = built.drives();
    let limits = crate::plausibility::tension_limits(built);
    let sol = solve_driven_within(
        model,
        &built.options,
        &drives,
        &built.loads,
        &limits,
        &gvs::solve::never_stop,
    )
    .map_err(|error| failure(built, &built.u, error))?;
    let solve_time_s = t0.elapsed().as_secs_f64();
    plausible_tensions(built, &sol.u)?;
    let mut r = report(
        built,
        model,
        &sol.u,
        &sol.statics,
        solve_time_s,
        &mut model.workspace(),
    );
    r.drives = (built.displacement.iter().zip(&sol.slack))
        .map(|(d, &slack)| DriveReport {
            displacement: *d,
            slack,
        })
        .collect();
    r.drive_iterations = Some(sol.drive_iterations);
    Ok(r)
}

/// The tensions found for displacement drives, held to the bounds a tension drive is held to
/// ([`crate::plausibility::check`]): a displacement the model reaches only beyond the rod's
/// elastic range (an axial strain past 1) is refused naming it, as its tension would be.
fn plausible_tensions(built: &Built, u: &[f64]) -> Result<(), StaticsFailure> {
    let u_abs: Vec<f64> = u.iter().map(|v| v.abs()).collect();
    let Err(e) = crate::plausibility::check(built, &u_abs, 1.0) else {
        return Ok(());
    };
    let k = (0..u.len())
        .filter(|&k| built.displacement[k].is_some())
        .max_by(|&a, &b| u_abs[a].total_cmp(&u_abs[b]))
        .unwrap_or(0);
    let delta = built.displacement.get(k).copied().flatten().unwrap_or(0.0);
    Err(StaticsFailure {
        error: gvs::error::ModelError::invalid(
            format!("tendons[{k}].displacement"),
            format!(
                "{} m is reached only at the tensions u = [{}] N: {e}",
                crate::build::significant(delta),
                (u.iter().map(|v| crate::build::significant(*v)))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )
        .into(),
        hint: String::new(),
    })
}
