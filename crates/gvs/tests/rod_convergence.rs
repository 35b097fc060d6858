//! Spatial convergence of the rod (gvs-spec §4.2–4.3, §10.3.3): the static tip deflection of the
//! tapered IV-A cantilever under a small tip force, as the strain basis is refined, against the
//! closed-form compliance `δ/P = ∫₀ᴸ (L−X)²/EI(X) dX + ∫₀ᴸ dX/GA(X)` — at the rate the basis
//! predicts: fourth order in the element size for linear FEM-like elements (the compliance is the
//! square of the energy-norm error of a Galerkin strain, `O(h²)²`), and geometric in the order for
//! the Legendre basis (the strain `P(L−X)/EI(X)` is analytic on [0, L]).

use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::loads::{Frame, Loads, PointWrench};
use gvs::model::Model;
use gvs::rod::{Material, Rod, SectionProps};
use gvs::solve::statics::{solve_statics, StaticsOptions};
use gvs::strain::{DivisionBasis, FemDegree, LinearBasis};

const L: f64 = 0.25;
const R0: f64 = 0.0125;
const R1: f64 = 0.005;
/// Tip force [N]: small enough that the geometric nonlinearity, `~(δ/L)² ≈ 2e-11`, is far below
/// the discretization errors measured here.
const P: f64 = 1e-6;

fn material() -> Material {
    Material {
        youngs_modulus: 0.617e6,
        poisson_ratio: 0.5,
        density: 1121.0,
        damping: 0.0,
    }
}

/// `∫(L−X)²/EI + ∫1/GA` by composite Simpson on 20 000 intervals (gvs-spec §10.3.3: 1.106776 m/N).
fn exact_compliance() -> f64 {
    let nq = 20000;
    let mut c = 0.0;
    for k in 0..=nq {
        let x = L * k as f64 / nq as f64;
        let s = SectionProps::circular(&material(), R0 + (R1 - R0) * x / L);
        let w = if k == 0 || k == nq {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        };
        c += w * ((L - x).powi(2) / s.es[1] + 1.0 / s.es[5]);
    }
    c * L / nq as f64 / 3.0
}

/// Tip compliance `−z_tip/P` of the equilibrium under the world force `(0, 0, −P)` at the tip.
fn compliance(disc_q: Quadrature, magnus: MagnusOrder, basis: DivisionBasis) -> f64 {
    let rod = Rod::tapered(material(), L, R0, R1);
    let disc = Discretization::new(&rod, &[disc_q], magnus, &[]).unwrap();
    let b = LinearBasis::per_division(&disc, &[basis]).unwrap();
    let m = Model::new(rod, disc, b, vec![]).unwrap();
    let loads = Loads {
        gravity: [0.0; 3],
        point: vec![PointWrench {
            x: L,
            wrench: [0.0, 0.0, 0.0, 0.0, 0.0, -P],
            frame: Frame::Global,
        }],
        distributed: vec![],
    };
    // the tightest residual tolerance: the forces are ~1e-7, below the default's absolute floor
    let opts = StaticsOptions {
        ftol: 1e-14,
        ..StaticsOptions::default()
    };
    let sol = solve_statics(&m, &[], &loads, None, &opts).unwrap();
    let mut ws = m.workspace();
    m.forward(&sol.q, &mut ws, false);
    -m.tip_pose(&ws).pos[2] / P
}

/// Bending about y and shear along z: the planar modes of a force along −z.
const BEND_SHEAR: [bool; 6] = [false, true, false, false, false, true];

/// Linear FEM-like strain (hat functions, 2 Gauss points per element, spec §4.3) on 8, 16, 32, 64
/// elements: the compliance error falls by 2⁴ per halving of the element size (observed order in
/// [3.8, 4.2]; measured 4.08, 4.06, 4.02, down to 2.3e-8) and from below (a Galerkin strain is
/// stiffer than the continuum).
#[test]
fn tapered_cantilever_compliance_converges_at_fourth_order_with_linear_elements() {
    let c = exact_compliance();
    assert!((c - 1.106776).abs() < 1e-6, "compliance integral {c}");
    let errs: Vec<f64> = [8usize, 16, 32, 64]
        .iter()
        .map(|&elements| {
            let ch = compliance(
                Quadrature::Elements {
                    elements,
                    gauss_per_element: 2,
                },
                MagnusOrder::Z4,
                DivisionBasis::Fem {
                    modes: BEND_SHEAR,
                    elements,
                    degree: FemDegree::Linear,
                },
            );
            (c - ch) / c
        })
        .collect();
    for w in errs.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!(
            (3.8..=4.2).contains(&order),
            "observed order {order:.3}; relative errors {errs:?}"
        );
    }
    assert!(
        errs.iter().all(|e| *e > 0.0),
        "a Galerkin strain is stiffer: errors {errs:?}"
    );
}

/// Legendre strain of orders 2…7 in bending and shear with N = 60 Gauss points (the kinematic
/// floor of the next test is then 3e-8): spectral convergence — the error falls faster than any
/// power of the order, i.e. the observed algebraic order `log(e_p/e_{p+1}) / log((p+1)/p)` grows
/// by more than 1 per added order (measured 2.8, 5.6, 8.4, 11.3, 14.1; errors 1.1e-2 … 1.6e-6), as
/// for a strain analytic on [0, L] (`P(L−X)/EI(X)`: its nearest singularity is the pole of `1/r⁴`
/// where the taper would reach r = 0, at X = 0.417 m) — and from below.
#[test]
fn tapered_cantilever_compliance_converges_spectrally_with_legendre_order() {
    let c = exact_compliance();
    let orders: Vec<usize> = (2..=7).collect();
    let errs: Vec<f64> = orders
        .iter()
        .map(|&order| {
            let ch = compliance(
                Quadrature::Gauss { n: 60 },
                MagnusOrder::Z4,
                DivisionBasis::Legendre {
                    modes: BEND_SHEAR,
                    orders: [0, order, 0, 0, 0, order],
                },
            );
            (c - ch) / c
        })
        .collect();
    assert!(errs.iter().all(|e| *e > 0.0), "errors {errs:?}");
    let alg: Vec<f64> = (0..errs.len() - 1)
        .map(|k| (errs[k] / errs[k + 1]).ln() / ((orders[k + 1] as f64) / orders[k] as f64).ln())
        .collect();
    for w in alg.windows(2) {
        assert!(
            w[1] > w[0] + 1.0,
            "algebraic orders {alg:?} do not grow; errors {errs:?}"
        );
    }
    assert!(
        *alg.last().unwrap() > 8.0 && *errs.last().unwrap() < 3e-6,
        "orders {alg:?}, errors {errs:?}"
    );
}

/// With the strain fixed by an order-14 Legendre basis (its Galerkin error is below the 1.8e-9
/// reached here; N ≥ 17 integrates its stiffness exactly), the remaining error is the kinematics'
/// (Magnus) integration of `r' = R ν` between the N + 2 points: it falls as `N⁻⁴` with the Zanna
/// step (Z4) and as `N⁻²` with the midpoint step (Z2), gvs-spec §5.3 — observed orders for
/// N = 30 → 60 → 120 within 0.2 of 4 and 2 (measured 3.90, 3.96 and 2.05, 2.01).
/// (An order-10 basis on N = 16 → 32 → 64 gave 3.80 and 3.86: not yet asymptotic.)
#[test]
fn tapered_cantilever_compliance_converges_with_points_at_the_magnus_order() {
    let c = exact_compliance();
    for (magnus, expected) in [(MagnusOrder::Z4, 4.0), (MagnusOrder::Z2, 2.0)] {
        let errs: Vec<f64> = [30usize, 60, 120]
            .iter()
            .map(|&n| {
                let ch = compliance(
                    Quadrature::Gauss { n },
                    magnus,
                    DivisionBasis::Legendre {
                        modes: BEND_SHEAR,
                        orders: [0, 14, 0, 0, 0, 14],
                    },
                );
                (c - ch) / c
            })
            .collect();
        for w in errs.windows(2) {
            let order = (w[0] / w[1]).abs().log2();
            assert!(
                (order - expected).abs() <= 0.2,
                "{magnus:?}: observed order {order:.3}; relative errors {errs:?}"
            );
        }
    }
}
