//! Accuracy measures of a reduced model against the high-order model (paper Section IV).
//!
//! - **Strain error** (the paper's "< 1 % strain error"): mean absolute error of the strain deviation
//!   over the computational points and active components, as a percentage of the HOM's largest
//!   |strain deviation| over those points and components:
//!   `e = 100 · mean_{j,c} |ξ_rom,jc − ξ_hom,jc| / max_{j,c} |ξ_hom,jc − ξ*_c|`.
//!   (The paper does not state its normalisation; this one is dominated by the largest strain, the
//!   bending on the presets, and does not blow up on components that stay near zero.)
//! - **RMSE** of a reconstruction (Table I): `sqrt(mean (x̂ − x)²)` over all entries, in strain units.
//! - **Tip error**: `100 · ‖p_rom − p_hom‖ / L`, percent of the rod length.

/// Strain error in percent (see the module documentation). `hom` and `rom` hold the deviations
/// `ξ − ξ*` of the same points and components; 0 if the HOM strain is zero everywhere and the two agree.
pub fn strain_error_percent(hom: &[f64], rom: &[f64]) -> f64 {
    assert_eq!(hom.len(), rom.len(), "strain_error_percent: lengths differ");
    if hom.is_empty() {
        return 0.0;
    }
    let scale = hom.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mae = hom.iter().zip(rom).map(|(h, r)| (h - r).abs()).sum::<f64>() / hom.len() as f64;
    if scale == 0.0 {
        if mae == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    } else {
        100.0 * mae / scale
    }
}

/// Root-mean-square difference of two arrays of equal length.
pub fn rmse(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "rmse: lengths differ");
    if a.is_empty() {
        return 0.0;
    }
    (a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>() / a.len() as f64).sqrt()
}

/// Tip position error in percent of the rod length `length`.
pub fn tip_error_percent(hom: &[f64; 3], rom: &[f64; 3], length: f64) -> f64 {
    let d = (0..3)
        .map(|i| (hom[i] - rom[i]).powi(2))
        .sum::<f64>()
        .sqrt();
    100.0 * d / length
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strain_error_is_the_mean_absolute_error_over_the_peak() {
        let hom = [0.0, 2.0, -4.0, 1.0];
        let rom = [0.1, 2.0, -3.9, 1.2];
        // mean |Δ| = 0.4 / 4 = 0.1; peak 4 → 2.5 %
        assert!((strain_error_percent(&hom, &rom) - 2.5).abs() < 1e-12);
        assert_eq!(strain_error_percent(&[0.0; 3], &[0.0; 3]), 0.0);
        assert!(strain_error_percent(&[0.0], &[1.0]).is_infinite());
    }

    #[test]
    fn rmse_and_tip_error_match_hand_values() {
        assert!((rmse(&[0.0, 0.0], &[3.0, 4.0]) - (12.5f64).sqrt()).abs() < 1e-15);
        assert!((tip_error_percent(&[0.0; 3], &[0.003, 0.004, 0.0], 0.25) - 2.0).abs() < 1e-12);
    }
}
