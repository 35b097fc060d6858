//! Warnings about tendons the discretization renders poorly: spans ending inside a division,
//! loads on strain components a basis lacks, helices sampled by too few points.

use crate::scenario::StrainMode;
use gvs::actuation::tendon_local;
use gvs::model::Model;
use gvs::strain::LinearBasis;

/// Tendons whose span ends inside a division: the strain jumps at a termination (and at a start
/// away from the base), which the division's continuous basis can only smooth over (gvs-spec §7.6:
/// a tendon's domain is whole divisions). The load itself is exact
/// ([`gvs::model::Model::tendon_weights`]), the strain around the end rings: a straight tendon
/// ending at 0.4 L inside one 33-DOF Legendre division is 11 % RMS off in bending strain (45 % at
/// its end) against the closed form, its tip 0.002 % L. One sentence per end, naming the split.
pub fn tendon_ends_inside_divisions(model: &Model<LinearBasis>) -> Vec<String> {
    let disc = &model.disc;
    let tol = 1e-12 * disc.length().max(1.0);
    let mut out = vec![];
    for (k, t) in model.tendons.iter().enumerate() {
        for (field, x) in [("x_start", t.x_start), ("x_end", t.x_end)] {
            let inside = (0..disc.div_start.len()).find(|&j| {
                let (a, l) = (disc.div_start[j], disc.div_length[j]);
                x > a + tol && x < a + l - tol
            });
            if let Some(j) = inside {
                // 0.15, not 0.15000000000000002
                let m = gvs::error::fmt_rounded;
                let (a, b) = (disc.div_start[j], disc.div_start[j] + disc.div_length[j]);
                out.push(format!(
                    "tendons[{k}].{field} = {x} m lies inside divisions[{j}] ([{}, {}] m): the strain jumps there, which the division's continuous basis only smooths over (ringing around it); split the division at {x} m (two [[divisions]] of lengths {} and {} m) for an exact jump",
                    m(a),
                    m(b),
                    m(x - a),
                    m(b - x),
                ));
            }
        }
    }
    out
}

/// What a tendon would do that the strain basis cannot: for each tendon, the strain components its
/// wrench `Φ_a = [d × t; t]` loads on the rod at rest (its reference strain; gvs-spec §7.6) at a weighted point of a
/// division whose basis lacks them. The Galerkin projection `Σ W Φᵀ Φ_a u` drops that part of the
/// load silently: a helical or off-plane tendon on a planar basis neither twists nor bends the rod
/// out of plane. One sentence per such tendon, for the front-ends to warn with.
pub fn uncovered_tendon_components(model: &Model<LinearBasis>) -> Vec<String> {
    let disc = &model.disc;
    let n_div = disc.div_start.len();
    // the components each division's basis has: a row of Φ_s non-zero at one of its sites
    let mut has = vec![[false; 6]; n_div];
    for (s, site) in disc.sites.iter().enumerate() {
        let phi = model.param.phi_at(s);
        for (a, flag) in has[site.div].iter_mut().enumerate() {
            *flag |= phi.row(a).iter().any(|v| *v != 0.0);
        }
    }
    let mut out = vec![];
    for (k, td) in model.tendons.iter().enumerate() {
        // per division, the components its basis lacks that the tendon loads there
        let mut missing = std::collections::BTreeMap::<usize, [bool; 6]>::new();
        for &i in model.tendon_points(k) {
            let p = disc.points[i];
            if p.weight <= 0.0 {
                continue;
            }
            let (d, dp) = td.offset_and_rate(p.x);
            let phi_a = tendon_local(&model.xi_star(i), &d, &dp).phi_a;
            let scale = phi_a.amax();
            for a in 0..6 {
                if !has[p.div][a] && phi_a[a].abs() > 1e-9 * scale {
                    missing.entry(p.div).or_default()[a] = true;
                }
            }
        }
        if missing.is_empty() {
            continue;
        }
        let names = |m: &[bool; 6]| {
            (StrainMode::ALL.iter())
                .filter(|mode| m[mode.index()])
                .map(|mode| mode.name())
                .collect::<Vec<_>>()
        };
        let all = missing.values().fold([false; 6], |mut acc, m| {
            (0..6).for_each(|a| acc[a] |= m[a]);
            acc
        });
        // one list when every division lacks the same, else division by division
        let what = match missing.values().all(|m| *m == all) {
            true => {
                let divs: Vec<String> = missing.keys().map(|j| j.to_string()).collect();
                let (s, verb) = if divs.len() == 1 {
                    ("", "lacks")
                } else {
                    ("s", "lack")
                };
                format!(
                    "{}, which the basis of division{s} {} {verb}",
                    names(&all).join(", "),
                    divs.join(", ")
                )
            }
            false => {
                let parts: Vec<String> = (missing.iter())
                    .map(|(j, m)| format!("{} in division {j}", names(m).join(", ")))
                    .collect();
                format!("{}, which those bases lack", parts.join("; "))
            }
        };
        let modes = names(&all).len();
        out.push(format!(
            "tendons[{k}] also loads {what}: that part of its load is dropped (add the mode{} to the basis to keep it)",
            if modes == 1 { "" } else { "s" }
        ));
    }
    out
}

/// Quadrature points per helical turn below which a helix's load is aliased: measured on the
/// six-tendon arm's tendon 0 (0.6 m over two 5-point divisions) against 60 points per division,
/// its tip is 11 mm (1.8 % L) off at 2 points per turn (5 turns), 0.46 mm at 3.3 (3 turns),
/// 0.3 mm at 5 (2 turns, the basis's own error) and 0.02 mm at 4 points per turn with 10 points.
pub const MIN_POINTS_PER_TURN: f64 = 4.0;

/// Helical tendons whose turns in a division are sampled by fewer than [`MIN_POINTS_PER_TURN`]
/// weighted points each: the tendon's wrench rotates once per turn, and the Galerkin load
/// `Σ W Φᵀ Φ_a u` sums it over those points, so too few alias it into a wrong net bending (the
/// helix of 5 turns on the six-tendon arm's default points bends the tip 11 mm the wrong way).
/// One sentence per such division, naming the points to give.
pub fn under_resolved_helices(model: &Model<LinearBasis>) -> Vec<String> {
    let disc = &model.disc;
    let mut out = vec![];
    for (k, t) in model.tendons.iter().enumerate() {
        let span = t.x_end - t.x_start;
        if t.turns == 0.0 || span <= 0.0 {
            continue;
        }
        for j in 0..disc.div_start.len() {
            let (a, b) = (disc.div_start[j], disc.div_start[j] + disc.div_length[j]);
            let overlap = b.min(t.x_end) - a.max(t.x_start);
            if overlap <= 1e-12 * span {
                continue;
            }
            let turns = t.turns.abs() * overlap / span;
            let points = (disc.points.iter())
                .filter(|p| p.div == j && p.weight > 0.0)
                .filter(|p| p.x >= t.x_start && p.x <= t.x_end)
                .count();
            if (points as f64) < MIN_POINTS_PER_TURN * turns {
                // a whole-division quadrature of that many Gauss points puts enough in the span
                let needed = (MIN_POINTS_PER_TURN * turns * disc.div_length[j] / overlap).ceil();
                out.push(format!(
                    "tendons[{k}] makes {} turns along divisions[{j}], where {points} quadrature points sample its load ({:.1} per turn, fewer than {MIN_POINTS_PER_TURN}): its rotating wrench is aliased into a wrong bending; give divisions[{j}].quadrature = {{ gauss = {needed} }} or more",
                    crate::build::significant(turns),
                    points as f64 / turns,
                ));
            }
        }
    }
    out
}
