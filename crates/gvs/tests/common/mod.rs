//! Helpers shared by the engine's integration tests.
#![allow(dead_code)]

use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::model::Model;
use gvs::rod::{Material, Rod};
use gvs::strain::{DivisionBasis, LinearBasis};
use nalgebra::DVector;

/// `rod` clamped at X = 0 with a Legendre basis of order `order` on the active `modes`, `gauss`
/// Gauss points over its one division, Magnus Z4.
pub fn legendre_model(
    rod: Rod,
    gauss: usize,
    modes: [bool; 6],
    order: usize,
) -> Model<LinearBasis> {
    let disc = Discretization::new(
        &rod,
        &[Quadrature::Gauss { n: gauss }],
        MagnusOrder::Z4,
        &[],
    )
    .unwrap();
    let basis = DivisionBasis::Legendre {
        modes,
        orders: [order; 6],
    };
    let b = LinearBasis::per_division(&disc, &[basis]).unwrap();
    Model::new(rod, disc, b, vec![]).unwrap()
}

/// The uniform clamped rod of gvs-spec §10.5: L = 0.5 m, r = 5 mm, E = 1e6 Pa, ρ = 1000 kg/m³, no
/// damping, Legendre orders [2, 6, 6, 2, 2, 2] on all six modes, N = 12 Gauss points.
pub fn clamped_rod_10_5() -> (Model<LinearBasis>, Material) {
    let mat = Material {
        youngs_modulus: 1e6,
        poisson_ratio: 0.5,
        density: 1000.0,
        damping: 0.0,
    };
    let rod = Rod::tapered(mat, 0.5, 0.005, 0.005);
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 12 }], MagnusOrder::Z4, &[]).unwrap();
    let b = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes: [true; 6],
            orders: [2, 6, 6, 2, 2, 2],
        }],
    )
    .unwrap();
    (Model::new(rod, disc, b, vec![]).unwrap(), mat)
}

/// Deterministic pseudo-random vector with entries in [-a, a] (an LCG; no dependency, same on every
/// platform).
pub fn pseudo_random(n: usize, seed: u64, a: f64) -> DVector<f64> {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    DVector::from_fn(n, |_, _| {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * a
    })
}

/// The IV-A arm's rod: L = 0.25 m tapered 12.5 → 5 mm, E = 0.617 MPa, ν = 0.5, ρ = 1121 kg/m³,
/// material damping `damping` [Pa·s].
pub fn iva_rod(damping: f64) -> Rod {
    let mat = Material {
        youngs_modulus: 0.617e6,
        poisson_ratio: 0.5,
        density: 1121.0,
        damping,
    };
    Rod::tapered(mat, 0.25, 0.0125, 0.005)
}

/// The IV-A tapered rod in 3-D: L = 0.25 m, r 12.5 → 5 mm, E = 0.617 MPa, ν = ½, ρ = 1121 kg/m³,
/// Kelvin–Voigt `damping` [Pa·s]; all six modes (Legendre orders [1, 2, 2, 1, 1, 1]: torsion, two
/// bending planes, stretch and two shears; 14 coordinates), `gauss` points, Z4, the weight-0
/// points `extra`, and `tendons`.
pub fn iva_rod_3d(
    damping: f64,
    gauss: usize,
    extra: &[f64],
    tendons: Vec<gvs::actuation::Tendon>,
) -> Model<LinearBasis> {
    let rod = iva_rod(damping);
    let disc = Discretization::new(
        &rod,
        &[Quadrature::Gauss { n: gauss }],
        MagnusOrder::Z4,
        extra,
    )
    .unwrap();
    let b = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes: [true; 6],
            orders: [1, 2, 2, 1, 1, 1],
        }],
    )
    .unwrap();
    Model::new(rod, disc, b, tendons).unwrap()
}

/// The IV-A arm in the x-z plane ([`iva_rod`] with `damping`, 12 Gauss points, Z4): bending about
/// y, elongation and shear along z (Legendre orders 4, 2, 2), one tendon on its upper side from
/// 10 mm to 3 mm off the axis with capstan friction `friction`.
pub fn iva_arm(damping: f64, friction: f64) -> Model<LinearBasis> {
    let rod = iva_rod(damping);
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 12 }], MagnusOrder::Z4, &[]).unwrap();
    let b = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes: [false, true, false, true, false, true],
            orders: [0, 4, 0, 2, 0, 2],
        }],
    )
    .unwrap();
    Model::new(rod, disc, b, vec![iva_tendon(friction)]).unwrap()
}

/// The IV-A arm's tendon: full length, on the upper side from 10 mm to 3 mm off the axis, with
/// capstan friction `friction` (default smoothing).
pub fn iva_tendon(friction: f64) -> gvs::actuation::Tendon {
    gvs::actuation::Tendon {
        offset_start: [0.0, 0.01],
        offset_end: [0.0, 0.003],
        x_start: 0.0,
        x_end: 0.25,
        friction,
        friction_smoothing: gvs::actuation::DEFAULT_FRICTION_SMOOTHING,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: None,
    }
}
