//! Custom tendon routing (gvs-spec §7.6 "Custom"): the offset `d(X) = [0, d_y(X), d_z(X)]` through
//! knots `(X_i, d_y,i, d_z,i)`, a piecewise cubic Hermite curve whose slope at each knot is that of
//! the parabola through the knot and its two neighbours (Bessel's slopes; at the two ends the
//! parabola through the first or the last three knots):
//!
//! `m_i = (h_i δ_{i−1} + h_{i−1} δ_i) / (h_{i−1} + h_i)`, `h_i = X_{i+1} − X_i`,
//! `δ_i = (d_{i+1} − d_i) / h_i`;
//! `m_0 = ((2h_0 + h_1) δ_0 − h_0 δ_1) / (h_0 + h_1)` and its mirror image at the last knot.
//!
//! On `[X_i, X_{i+1}]`, `t = (X − X_i)/h_i`:
//! `d = (2t³ − 3t² + 1) d_i + (t³ − 2t² + t) h_i m_i + (−2t³ + 3t²) d_{i+1} + (t³ − t²) h_i m_{i+1}`.
//!
//! The curve passes through every knot, `d'` is continuous (`C¹`: the tendon's tangent
//! `t_u = ν + k × d + d'` has no jump between knots), a path of two knots is the straight
//! ("oblique") one and a quadratic path is reproduced exactly. Each slope depends on the knots next
//! to it only, so a knot moves the curve over its neighbouring intervals alone. Evaluation finds the
//! interval by bisection and allocates nothing.

use crate::lie::V3;

/// Fewest knots of a path (two: the straight path between them).
pub const MIN_KNOTS: usize = 2;
/// Most knots of a path: far beyond any routing a strain basis of practical order resolves.
pub const MAX_KNOTS: usize = 10_000;

/// Slope `(m_y, m_z)` of the path at knot `i` (module documentation).
fn slope(path: &[[f64; 3]], i: usize) -> [f64; 2] {
    let n = path.len();
    let delta = |j: usize| {
        let h = path[j + 1][0] - path[j][0];
        (
            h,
            [
                (path[j + 1][1] - path[j][1]) / h,
                (path[j + 1][2] - path[j][2]) / h,
            ],
        )
    };
    if n == 2 {
        return delta(0).1;
    }
    let blend = |(ha, da): (f64, [f64; 2]), (hb, db): (f64, [f64; 2]), wa: f64, wb: f64| {
        [
            (wa * da[0] + wb * db[0]) / (ha + hb),
            (wa * da[1] + wb * db[1]) / (ha + hb),
        ]
    };
    if i == 0 {
        let (a, b) = (delta(0), delta(1));
        blend(a, b, 2.0 * a.0 + b.0, -a.0)
    } else if i == n - 1 {
        let (a, b) = (delta(n - 3), delta(n - 2));
        blend(a, b, -b.0, 2.0 * b.0 + a.0)
    } else {
        let (a, b) = (delta(i - 1), delta(i));
        blend(a, b, b.0, a.0)
    }
}

/// `(d(X), d'(X))` of the path (module documentation), `X` clamped to the path's span. `path` must
/// hold at least [`MIN_KNOTS`] knots with strictly increasing `X` ([`check`]).
pub fn offset_and_rate(path: &[[f64; 3]], x: f64) -> (V3, V3) {
    let n = path.len();
    // the interval [X_i, X_{i+1}] holding x: the last knot with X_i <= x, at most n − 2
    let i = path
        .partition_point(|k| k[0] <= x)
        .saturating_sub(1)
        .min(n - 2);
    let (a, b) = (&path[i], &path[i + 1]);
    let h = b[0] - a[0];
    let t = ((x - a[0]) / h).clamp(0.0, 1.0);
    let (ma, mb) = (slope(path, i), slope(path, i + 1));
    let (t2, t3) = (t * t, t * t * t);
    let (h00, h10, h01, h11) = (
        2.0 * t3 - 3.0 * t2 + 1.0,
        t3 - 2.0 * t2 + t,
        -2.0 * t3 + 3.0 * t2,
        t3 - t2,
    );
    let (g00, g10, g01, g11) = (
        (6.0 * t2 - 6.0 * t) / h,
        3.0 * t2 - 4.0 * t + 1.0,
        (-6.0 * t2 + 6.0 * t) / h,
        3.0 * t2 - 2.0 * t,
    );
    let value = |c: usize| h00 * a[c] + h10 * h * ma[c - 1] + h01 * b[c] + h11 * h * mb[c - 1];
    let rate = |c: usize| g00 * a[c] + g10 * ma[c - 1] + g01 * b[c] + g11 * mb[c - 1];
    (
        V3::new(0.0, value(1), value(2)),
        V3::new(0.0, rate(1), rate(2)),
    )
}

/// The least distance along the rod between two knots: closer ones make the curve's slope between
/// them unbounded (knots 1e-300 m apart gave an infinite offset rate, reported as `inf`).
pub const MIN_KNOT_SPACING: f64 = 1e-6;

/// What is wrong with `path` as a routing, if anything: the number of knots, a value that is not
/// finite, or abscissae that do not increase by at least [`MIN_KNOT_SPACING`]; `(knot index or
/// None, message)`.
pub fn check(path: &[[f64; 3]]) -> Result<(), (Option<usize>, String)> {
    if !(MIN_KNOTS..=MAX_KNOTS).contains(&path.len()) {
        return Err((
            None,
            format!(
                "{} knots (accepted: {MIN_KNOTS} to {MAX_KNOTS} knots [X, d_y, d_z] in m)",
                path.len()
            ),
        ));
    }
    for (i, k) in path.iter().enumerate() {
        if let Some(c) = k.iter().position(|v| !v.is_finite()) {
            return Err((
                Some(i),
                format!("entry {c} is {}, not a finite number of metres", k[c]),
            ));
        }
        if i > 0 && k[0] <= path[i - 1][0] {
            return Err((
                Some(i),
                format!(
                    "X = {} m does not follow the knot before it (X = {} m): the abscissae must strictly increase",
                    crate::error::fmt_value(k[0]),
                    crate::error::fmt_value(path[i - 1][0])
                ),
            ));
        }
        if i > 0 && k[0] - path[i - 1][0] < MIN_KNOT_SPACING {
            return Err((
                Some(i),
                format!(
                    "X = {} m is {} m after the knot before it (X = {} m): knots at least {MIN_KNOT_SPACING:e} m apart are accepted (closer, the path's slope between them is unbounded)",
                    crate::error::fmt_value(k[0]),
                    crate::error::fmt_value(k[0] - path[i - 1][0]),
                    crate::error::fmt_value(path[i - 1][0])
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quadratic path `d(X) = a + b X + c X²` per component through uneven knots.
    fn quadratic(x: f64) -> [f64; 4] {
        let (y, z) = (
            0.01 - 0.02 * x + 0.05 * x * x,
            -0.004 + 0.03 * x - 0.08 * x * x,
        );
        let (yp, zp) = (-0.02 + 0.1 * x, 0.03 - 0.16 * x);
        [y, z, yp, zp]
    }

    #[test]
    fn a_quadratic_path_is_reproduced_exactly_with_its_rate() {
        let xs = [0.0, 0.03, 0.1, 0.11, 0.2, 0.25];
        let path: Vec<[f64; 3]> = xs
            .iter()
            .map(|&x| {
                let q = quadratic(x);
                [x, q[0], q[1]]
            })
            .collect();
        for k in 0..=250 {
            let x = 0.001 * k as f64;
            let (d, dp) = offset_and_rate(&path, x);
            let q = quadratic(x);
            assert!(
                (d[1] - q[0]).abs() < 1e-15 && (d[2] - q[1]).abs() < 1e-15,
                "{x}"
            );
            assert!(
                (dp[1] - q[2]).abs() < 1e-13 && (dp[2] - q[3]).abs() < 1e-13,
                "{x}"
            );
            assert_eq!((d[0], dp[0]), (0.0, 0.0));
        }
    }

    #[test]
    fn knots_closer_than_a_micrometre_are_refused_with_readable_numbers() {
        // a review's knots 1e-300 m apart: the offset rate between them was infinite, and the
        // abscissa was printed with 300 digits
        let (i, m) =
            check(&[[0.0, 0.0, 0.01], [1e-300, 0.0, -0.01], [0.25, 0.0, 0.0]]).unwrap_err();
        assert_eq!(i, Some(1));
        assert!(
            m.starts_with("X = 1e-300 m is 1e-300 m after the knot before it (X = 0 m)"),
            "{m}"
        );
        assert!(check(&[[0.0, 0.0, 0.01], [1e-6, 0.0, -0.01], [0.25, 0.0, 0.0]]).is_ok());
    }

    #[test]
    fn two_knots_are_the_straight_path() {
        let path = [[0.05, 0.01, -0.002], [0.25, 0.003, 0.004]];
        for x in [0.05, 0.1, 0.2, 0.25] {
            let s = (x - 0.05) / 0.2;
            let (d, dp) = offset_and_rate(&path, x);
            assert!((d[1] - (0.01 - 0.007 * s)).abs() < 1e-16);
            assert!((d[2] - (-0.002 + 0.006 * s)).abs() < 1e-16);
            assert!((dp[1] + 0.035).abs() < 1e-14 && (dp[2] - 0.03).abs() < 1e-14);
        }
    }

    #[test]
    fn the_curve_passes_through_the_knots_and_its_rate_is_the_derivative_of_its_value() {
        // an S-shaped path: knots hit exactly, d' continuous across every knot and equal to
        // central differences of d inside the intervals
        let path = [
            [0.0, 0.0, 0.01],
            [0.04, 0.006, 0.008],
            [0.1, 0.0, 0.004],
            [0.17, -0.007, 0.002],
            [0.25, 0.0, 0.0],
        ];
        for k in &path {
            let (d, _) = offset_and_rate(&path, k[0]);
            assert!((d[1] - k[1]).abs() < 1e-17 && (d[2] - k[2]).abs() < 1e-17);
        }
        for k in &path[1..4] {
            let (_, left) = offset_and_rate(&path, k[0] - 1e-12);
            let (_, right) = offset_and_rate(&path, k[0] + 1e-12);
            assert!((left - right).norm() < 1e-9, "{left} {right}");
        }
        let h = 1e-6;
        for k in 1..250 {
            let x = 0.001 * k as f64 + 3e-4;
            let (_, dp) = offset_and_rate(&path, x);
            let fd =
                (offset_and_rate(&path, x + h).0 - offset_and_rate(&path, x - h).0) / (2.0 * h);
            assert!((dp - fd).norm() < 1e-8, "{x}: {dp} vs {fd}");
        }
    }

    #[test]
    fn bad_paths_name_the_knot() {
        assert!(check(&[[0.0, 0.0, 0.0]]).unwrap_err().1.contains("1 knots"));
        let e = check(&[[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.0, 0.0]]).unwrap_err();
        assert_eq!(e.0, Some(2));
        assert!(e.1.contains("strictly increase"), "{}", e.1);
        let e = check(&[[0.0, 0.0, 0.0], [0.1, f64::NAN, 0.0]]).unwrap_err();
        assert_eq!(e.0, Some(1));
        assert!(e.1.contains("entry 1 is NaN"), "{}", e.1);
        assert!(check(&[[0.0, 0.0, 0.0], [0.1, 0.01, 0.0]]).is_ok());
    }
}
