//! The accepted ranges of a scenario's values, and the checks that name the field when one lies
//! outside.

use crate::error::ScenarioError;
use gvs::error::fmt_rounded;

/// Largest Legendre order per mode accepted (higher orders are numerically pointless here).
pub const MAX_LEGENDRE_ORDER: usize = 50;
/// Largest number of Gauss points per division, or of elements per division.
pub const MAX_POINTS: usize = 5000;
/// Largest number of Gauss points per element.
pub const MAX_GAUSS_PER_ELEMENT: usize = 20;
/// Largest `n_dof × strain sites`: the tabulated basis and Jacobians are 6 × n·sites matrices
/// (5e6 ≈ 240 MB each).
pub const MAX_BASIS_SIZE: usize = 5_000_000;
/// Largest number of generalized coordinates (DOF). Statics factorizes a dense n × n Jacobian per
/// iteration (O(n³)): 2000 DOF is about a second per iteration on one core.
pub const MAX_DOF: usize = 2000;
/// Accepted Young's modulus E \[Pa\]: from the softest hydrogels (≈ 1 kPa) with three decades of
/// room below, to stiffer than diamond (1.2e12 Pa).
pub const YOUNGS_MODULUS_RANGE: (f64, f64) = (1.0, 1e13);
/// Accepted density ρ [kg/m³] of a rod with mass: 1e-2, sixteen times below the lightest solid
/// (graphene aerogel, 0.16), to 1e5, five times the densest element (osmium 2.26e4). 0 (massless)
/// is accepted too, for statics. Below the range the mass matrix underflows: at ρ = 1e-300 `modes`
/// printed frequencies of 7e152 Hz beside 0 Hz.
pub const DENSITY_RANGE: (f64, f64) = (1e-2, 1e5);
/// Accepted capstan friction coefficient μ of a tendon: 0 (frictionless) to 10, five times the
/// grippiest pairs (rubber on dry rubber, μ ≈ 1–2; the paper's 0.88). A tension decays as
/// `exp(−μ θ)` along the wrap angle θ: at μ = 1e9 it vanishes at the first bend.
pub const FRICTION_RANGE: (f64, f64) = (0.0, 10.0);
/// Largest gravitational acceleration |g| [m/s²] (1000 g).
pub const MAX_GRAVITY: f64 = 1e4;
/// Largest distance of the base from the origin along each axis \[m\]: a kilometre. Far beyond it
/// the rod's own size vanishes in the rounding of its positions (at 1e308 m the tip equals the
/// base).
pub const MAX_BASE_POSITION: f64 = 1e3;
/// Accepted division length ℓ_j \[m\]: 1 µm to 1 km.
pub const DIVISION_LENGTH_RANGE: (f64, f64) = (1e-6, 1e3);
/// Smallest radius \[m\] (0.1 µm); the largest is the rod's total length L (a rod is slender).
pub const MIN_RADIUS: f64 = 1e-7;
/// Accepted angle in degrees (a base rotation, a tendon's polar angle): ±1e6, thousands of turns;
/// the angle's rounding is 1e-10° there (1e308 was accepted, and rounded to whole turns).
pub const ANGLE_RANGE_DEG: (f64, f64) = (-1e6, 1e6);
/// Largest number of centreline samples.
pub const MAX_CENTERLINE_POINTS: usize = 100_000;

pub(super) fn finite(field: &str, v: f64) -> Result<f64, ScenarioError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ScenarioError::value(field, v, "a finite number"))
    }
}

/// A bound for a message: plain in [1e-3, 1e4), else in exponent form (`1e13`).
pub(crate) fn num(v: f64) -> String {
    if v == 0.0 || (1e-3..1e4).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// `x` as an abscissa of a rod of length `l` ([`gvs::rod::abscissa_on`]: `[0, L]`, an end past
/// `L` by the rounding of the divisions' summed lengths is `L`), else an error naming `field`.
pub(super) fn on_rod(field: &str, x: f64, l: f64) -> Result<f64, ScenarioError> {
    gvs::rod::abscissa_on(l, x).ok_or_else(|| {
        ScenarioError::value(
            field,
            x,
            format!("an abscissa in [0, {}] m", fmt_rounded(l)),
        )
    })
}

/// `x_end` as the end of a span starting at `x_start` on a rod of length `l`: after `x_start`
/// and on the rod ([`on_rod`]'s tolerance at the tip), else an error naming `field`.
pub(super) fn span_end(
    field: &str,
    x_end: f64,
    x_start: f64,
    l: f64,
) -> Result<f64, ScenarioError> {
    match gvs::rod::abscissa_on(l, x_end) {
        Some(x) if x > x_start => Ok(x),
        _ => Err(ScenarioError::value(
            field,
            x_end,
            format!(
                "an abscissa in ({x_start}, {}] m (after x_start)",
                fmt_rounded(l)
            ),
        )),
    }
}

/// `v` in the closed range `[lo, hi]`, else an error naming `field` and the range.
pub(super) fn in_range(
    field: &str,
    v: f64,
    (lo, hi): (f64, f64),
    unit: &str,
) -> Result<f64, ScenarioError> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(v)
    } else {
        Err(ScenarioError::value(
            field,
            v,
            format!("a number in [{}, {}] {unit}", num(lo), num(hi)),
        ))
    }
}

pub(super) fn positive(field: &str, v: f64, unit: &str) -> Result<f64, ScenarioError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ScenarioError::value(
            field,
            v,
            format!("a finite number > 0 {unit}"),
        ))
    }
}

pub(super) fn non_negative(field: &str, v: f64, unit: &str) -> Result<f64, ScenarioError> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(ScenarioError::value(
            field,
            v,
            format!("a finite number >= 0 {unit}"),
        ))
    }
}

/// The unit vector along the axis `field` ([`gvs::loads::unit_axis`]: tiny and huge components
/// keep their direction), else an error naming the first non-finite component or the zero vector.
pub(super) fn direction(field: &str, axis: &[f64; 3]) -> Result<gvs::lie::V3, ScenarioError> {
    for (i, v) in axis.iter().enumerate() {
        finite(&format!("{field}[{i}]"), *v)?;
    }
    gvs::loads::unit_axis(axis).ok_or_else(|| {
        ScenarioError::invalid(
            field,
            "[0, 0, 0] has no direction: expected a non-zero axis vector",
        )
    })
}
