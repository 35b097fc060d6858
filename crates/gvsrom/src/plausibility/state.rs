//! The verdict on a computed state: a strain no elastic rod holds ends a run, where the load
//! estimate ([`super::check`]) could not foresee it (a dynamic overshoot, a load the linear
//! estimate underrates, an integrator that diverged).
//!
//! With `d = ξ − ξ*` at a computational point, a state is refused when
//!
//! - the stretch `ν = ξ₄ ≤ 0` (`d₄ ≤ −1`): the section has passed through itself;
//! - `|d₄|`, `|d₅|` or `|d₆|` > [`STATE_MAX_STRAIN`] (10: a tenfold stretch, a shear angle past 84°);
//! - `‖(d₁, d₂, d₃)‖ L >` [`STATE_MAX_BENDING`] (2000 rad: a curvature that would coil the whole
//!   rod 300 times).
//!
//! The bounds are ten times the load estimate's ([`super::MAX_STRAIN`], [`super::MAX_BENDING`]),
//! so that a state the load check lets through by its estimate is never stopped, while a diverged
//! one (strains of 1e5 and a tip kilometres away) is stopped at its first sample.

use gvs::lie::V6;

/// Largest axial or shear strain `|ξ − ξ*|` of a state (a tenfold stretch).
pub const STATE_MAX_STRAIN: f64 = 10.0 * super::MAX_STRAIN;
/// Largest `‖κ − κ*‖ L` of a state \[rad\].
pub const STATE_MAX_BENDING: f64 = 10.0 * super::MAX_BENDING;

/// The first point `j` (at abscissa `x[j]`) whose strain `strain[j]` no elastic rod holds, as a
/// phrase ("at X = 0.12 m the stretch ν = −3.4e5 ≤ 0: a section has passed through itself"); `None`
/// for a state inside the bounds. `xi_star(j)` is the reference strain, `length` the rod's.
pub fn state_violation(
    strain: &[V6],
    x: &[f64],
    xi_star: impl Fn(usize) -> V6,
    length: f64,
) -> Option<String> {
    // called at every sample of a run: nothing is formatted until a bound is crossed
    let at = |j: usize| format!("at X = {:.4} m", x.get(j).copied().unwrap_or(f64::NAN));
    for (j, xi) in strain.iter().enumerate() {
        let d = xi - xi_star(j);
        let nu = xi[3];
        // NaN fails every bound: each test is "not within", written with `is_nan` spelled out
        if nu.is_nan() || nu <= 0.0 {
            return Some(format!(
                "{} the stretch ν = {} ≤ 0: a section has passed through itself",
                at(j),
                gvs::error::fmt_value(nu)
            ));
        }
        for (k, name) in [(3, "axial strain"), (4, "shear y"), (5, "shear z")] {
            if d[k].is_nan() || d[k].abs() > STATE_MAX_STRAIN {
                return Some(format!(
                    "{} the {name} is {} (accepted |·| <= {STATE_MAX_STRAIN})",
                    at(j),
                    gvs::error::fmt_value(d[k])
                ));
            }
        }
        let bend = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() * length;
        if bend.is_nan() || bend > STATE_MAX_BENDING {
            return Some(format!(
                "{} the curvature times the rod's length is {} rad (accepted <= {STATE_MAX_BENDING} rad)",
                at(j),
                gvs::error::fmt_value(bend)
            ));
        }
    }
    None
}

/// Why the coordinates `q` of the model that runs in `built` (the HOM's, or the reduced model's
/// attached) are no state of an elastic rod ([`state_violation`] of the strains they give), as a
/// phrase; `None` for a physical state. It allocates a workspace: a check of a start, not of every
/// sample.
pub fn coordinates_violation(built: &crate::Built, q: &[f64]) -> Option<String> {
    let q = nalgebra::DVector::from_column_slice(q);
    match &built.reduced {
        Some(r) => model_state_violation(&r.model, &q, &mut r.model.workspace()),
        None => model_state_violation(&built.model, &q, &mut built.model.workspace()),
    }
}

/// [`state_violation`] of the strains that `m` gives at `q` (evaluated in `ws`, without the
/// kinematics).
pub fn model_state_violation<P: gvs::strain::StrainParam>(
    m: &gvs::model::Model<P>,
    q: &nalgebra::DVector<f64>,
    ws: &mut gvs::model::Workspace,
) -> Option<String> {
    let x: Vec<f64> = m.disc.points.iter().map(|p| p.x).collect();
    state_violation(m.strains_at(q, ws), &x, |j| m.xi_star(j), m.disc.length())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rest() -> V6 {
        V6::new(0.0, 0.0, 0.0, 1.0, 0.0, 0.0)
    }

    #[test]
    fn a_state_within_the_elastic_range_passes_and_each_bound_is_named_when_crossed() {
        let x = [0.0, 0.5];
        let ok = [rest(), V6::new(1.0, 20.0, 0.0, 1.9, 0.3, -0.2)];
        assert_eq!(state_violation(&ok, &x, |_| rest(), 1.0), None);
        let cases = [
            (V6::new(0.0, 0.0, 0.0, -0.1, 0.0, 0.0), "stretch ν = -0.1"),
            (V6::new(0.0, 0.0, 0.0, 12.0, 0.0, 0.0), "axial strain is 11"),
            (V6::new(0.0, 0.0, 0.0, 1.0, -10.5, 0.0), "shear y is -10.5"),
            (V6::new(0.0, 0.0, 0.0, 1.0, 0.0, f64::NAN), "shear z is NaN"),
            (
                V6::new(0.0, 1500.0, 1600.0, 1.0, 0.0, 0.0),
                "length is 2193.17",
            ),
        ];
        for (bad, needle) in cases {
            let m = state_violation(&[rest(), bad], &x, |_| rest(), 1.0).unwrap();
            assert!(m.starts_with("at X = 0.5000 m"), "{m}");
            assert!(m.contains(needle), "{m}");
        }
        // the reference strain is subtracted: a precurved rod at rest is inside
        let star = V6::new(0.0, 3000.0, 0.0, 1.0, 0.0, 0.0);
        assert_eq!(state_violation(&[star], &[0.0], |_| star, 1.0), None);
    }
}
