//! The report of a statics solution ([`StaticsReport`]): the tip pose, the centreline, the strains,
//! the tendons' threads and lengths and the rigid bodies' positions by forward kinematics at the
//! solution, with the solver's statistics.

use super::{centerline_abscissae, ContinuationSummary, StaticsReport};
use crate::build::Built;
use gvs::lie::V3;
use gvs::model::{Model, Workspace};
use gvs::solve::statics::StaticsSolution;
use gvs::strain::StrainParam;
use serde::Serialize;

/// The report of the solution `sol` of `model` under `u`: the tip pose, the centreline and the
/// strains by forward kinematics at `sol.q` (in `ws`), and the solver's statistics.
pub(super) fn report<P: StrainParam>(
    built: &Built,
    model: &Model<P>,
    u: &[f64],
    sol: &StaticsSolution,
    solve_time_s: f64,
    ws: &mut Workspace,
) -> StaticsReport {
    model.forward_pose(&sol.q, ws);
    let tip = ws.g[model.disc.tip()];
    let length = model.disc.length();
    let centerline_x = centerline_abscissae(length, built.centerline_points);
    let centerline = centerline_x
        .iter()
        .map(|&x| arr3(&model.position_at(ws, x)))
        .collect();
    let tendon_paths = tendon_paths(model, ws, &centerline_x);
    let strain = model
        .point_strains(ws)
        .iter()
        .map(|xi| [xi[0], xi[1], xi[2], xi[3], xi[4], xi[5]])
        .collect();
    let mut tendon_lengths = vec![0.0; model.n_actuators()];
    model.tendon_lengths_after_forward(ws, &mut tendon_lengths);
    StaticsReport {
        scenario: built.name.clone(),
        u: u.to_vec(),
        n_dof: model.n_dof(),
        n_points: model.disc.n_points(),
        q: sol.q.iter().copied().collect(),
        tip_position: arr3(&tip.pos),
        tip_rotation: std::array::from_fn(|i| std::array::from_fn(|j| tip.rot[(i, j)])),
        centerline_x,
        centerline,
        strain_x: model.disc.points.iter().map(|p| p.x).collect(),
        strain,
        strain_reference: (0..model.disc.n_points())
            .map(|j| {
                let s = model.xi_star(j);
                [s[0], s[1], s[2], s[3], s[4], s[5]]
            })
            .collect(),
        tendon_paths,
        tendon_lengths,
        tendon_rest_lengths: model.tendon_rest_lengths(),
        bodies: (model.bodies().zip(model.body_positions(ws)))
            .map(|(b, (section, center))| BodyPosition {
                x: b.x,
                mass: b.mass,
                section: arr3(&section),
                center: arr3(&center),
            })
            .collect(),
        drives: vec![],
        drive_iterations: None,
        iterations: sol.iterations,
        load_stages: sol.load_stages,
        residual_evaluations: sol.residual_evaluations,
        jacobian_evaluations: sol.jacobian_evaluations,
        residual_norm: sol.residual_norm,
        solve_time_s,
        continuation: sol.continuation.as_ref().map(|c| ContinuationSummary {
            steps: c.steps,
            rejected_steps: c.rejected,
            folds: c.folds.clone(),
            lambda_max: c.lambda_max,
            after_unstable: sol.unstable_start,
        }),
        divergence: sol.divergence,
        buckled: sol.buckled,
        descent_steps: sol.descent_steps,
        stability_checked: built.options.check_stability,
    }
}

/// The world positions `r + R d(X)` of every tendon ([`Model::tendon_position_at`]) at its ends
/// and at the centreline abscissae `xs` between them, after a forward pass in `ws`.
fn tendon_paths<P: StrainParam>(
    model: &Model<P>,
    ws: &Workspace,
    xs: &[f64],
) -> Vec<Vec<[f64; 3]>> {
    (0..model.tendons.len())
        .map(|k| {
            let Some((xa, xb)) = model.tendon_extent(k) else {
                return vec![];
            };
            std::iter::once(xa)
                .chain(xs.iter().copied().filter(|&x| x > xa && x < xb))
                .chain(std::iter::once(xb))
                .map(|x| arr3(&model.tendon_position_at(ws, k, x)))
                .collect()
        })
        .collect()
}

/// Where a rigid body is at an equilibrium ([`StaticsReport::bodies`]).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct BodyPosition {
    /// The arc length of its section \[m\].
    pub x: f64,
    /// Its mass \[kg\].
    pub mass: f64,
    /// The world position of that section \[m\].
    pub section: [f64; 3],
    /// The world position of its centre of mass \[m\].
    pub center: [f64; 3],
}

fn arr3(v: &V3) -> [f64; 3] {
    [v[0], v[1], v[2]]
}
