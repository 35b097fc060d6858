//! Intrinsic dimension of a snapshot set, two ways (the paper reads it off its latent plots by eye):
//!
//! - **Correlation dimension** (Grassberger & Procaccia, Physica D 1983): the fraction of sample
//!   pairs closer than ε grows as `C(ε) ∝ ε^d` on a d-dimensional manifold, so
//!   `d = ln(C₂/C₁) / ln(ε₂/ε₁)` between two small scales, taken here at the 0.5 % and 5 %
//!   quantiles of the pair distances. Unlike nearest-neighbour estimators (TwoNN), it also holds on
//!   evenly spaced samples (a sweep), whose two nearest neighbours are equally far.
//! - **Elbow** of the reconstruction error over the latent size r: the smallest r after which one
//!   more coordinate no longer halves the error (`RMSE(r) / RMSE(r + 1) < 2`).

/// The quantiles of the pair distances between which the correlation dimension is measured.
pub const CORRELATION_QUANTILES: [f64; 2] = [0.005, 0.05];

/// Correlation dimension of at most `max_points` rows of `rows` (`n × dim`, row-major), taken
/// evenly spaced. `None` with fewer than 20 points or when the two scales coincide.
pub fn correlation_dimension(rows: &[f64], dim: usize, max_points: usize) -> Option<f64> {
    if dim == 0 {
        return None;
    }
    let n = rows.len() / dim;
    let stride = n.div_ceil(max_points.max(20)).max(1);
    let pts: Vec<&[f64]> = (0..n)
        .step_by(stride)
        .map(|i| &rows[i * dim..(i + 1) * dim])
        .collect();
    if pts.len() < 20 {
        return None;
    }
    let mut d2 = Vec::with_capacity(pts.len() * (pts.len() - 1) / 2);
    for (i, a) in pts.iter().enumerate() {
        for b in &pts[i + 1..] {
            d2.push(
                a.iter()
                    .zip(b.iter())
                    .map(|(x, y)| (x - y) * (x - y))
                    .sum::<f64>(),
            );
        }
    }
    if d2.iter().any(|v| !v.is_finite()) {
        return None;
    }
    d2.sort_by(f64::total_cmp);
    let [q1, q2] = CORRELATION_QUANTILES;
    // ε at the quantiles, and C(ε) counting every pair within ε (ties included: on an evenly
    // spaced sweep many pairs share a distance, up to rounding)
    let scale = |q: f64| d2[((q * d2.len() as f64) as usize).min(d2.len() - 1)];
    let count = |e2: f64| d2.partition_point(|&v| v <= e2 * (1.0 + 1e-9)) as f64;
    let (s1, s2) = (scale(q1), scale(q2));
    (s1 > 0.0 && s2 > s1).then(|| (count(s2) / count(s1)).ln() / (0.5 * (s2 / s1).ln()))
}

/// The elbow of `rmse` over r = 1, 2, …: the smallest r with `rmse[r−1] / rmse[r] < 2`, or the
/// largest r tried when every step still halves the error.
pub fn elbow(rmse: &[f64]) -> usize {
    for r in 1..rmse.len() {
        if rmse[r - 1] / rmse[r] < 2.0 {
            return r;
        }
    }
    rmse.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform numbers in [0, 1) from a xorshift generator (the test needs no dependency).
    fn uniform(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn the_correlation_dimension_of_a_curve_a_sweep_and_a_surface() {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        // a curve: random points on a helix in 3-D
        let mut helix = vec![];
        for _ in 0..1000 {
            let t = 8.0 * uniform(&mut s);
            helix.extend([t.cos(), t.sin(), 0.3 * t]);
        }
        let d1 = correlation_dimension(&helix, 3, 1000).unwrap();
        assert!((d1 - 1.0).abs() < 0.15, "helix: {d1}");
        // evenly spaced along the curve (a sweep): the same
        let sweep: Vec<f64> = (0..500)
            .flat_map(|i| {
                let t = 8.0 * i as f64 / 499.0;
                [t.cos(), t.sin(), 0.3 * t]
            })
            .collect();
        let ds = correlation_dimension(&sweep, 3, 1000).unwrap();
        assert!((ds - 1.0).abs() < 0.15, "sweep: {ds}");
        // a surface: a tilted unit square in 10-D
        let mut plane = vec![];
        for _ in 0..1500 {
            let (a, b) = (uniform(&mut s), uniform(&mut s));
            let mut x = vec![0.0; 10];
            x[0] = a;
            x[1] = b;
            x[5] = 0.5 * a - 0.25 * b;
            plane.extend(x);
        }
        // (edges lower C(ε) at the larger scale: the estimate sits a little below 2)
        let d2 = correlation_dimension(&plane, 10, 1500).unwrap();
        assert!((d2 - 2.0).abs() < 0.3, "plane: {d2}");
        // a 3-D cube is told from the plane
        let cube: Vec<f64> = (0..1500)
            .flat_map(|_| [uniform(&mut s), uniform(&mut s), uniform(&mut s)])
            .collect();
        let d3 = correlation_dimension(&cube, 3, 1500).unwrap();
        assert!((d3 - 3.0).abs() < 0.45, "cube: {d3}");
    }

    #[test]
    fn the_elbow_is_where_one_more_coordinate_stops_halving_the_error() {
        assert_eq!(elbow(&[0.0383, 0.0310, 0.0248]), 1); // paper Table I, IV-A, 7 layers
        assert_eq!(elbow(&[4.81, 0.5923, 0.5318]), 2); // IV-B
        assert_eq!(elbow(&[8.0, 2.0, 0.5]), 3);
    }
}
