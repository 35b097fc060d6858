//! Distributed loads that the computational points cannot resolve are refused, naming the field
//! that sets their extent: a load narrower than the points' spacing falls between them (and is
//! lost) or lands on one (and is inflated), so its resultant would be wrong by any amount. The
//! IV-B beam (0.8 m, 49 linear elements, 2 Gauss points each: points ≤ 9.4 mm apart) under the
//! paper's 4 N·m pulse bends about `M X₀/(EI)` = 20.1 rad at X₀ = 0.2 m whatever the pulse's width;
//! before this check a 0.005 m pulse bent it 49 rad, a 0.001 m one not at all.

use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::loads::{DistributedWrench, Frame, Loads, PulseMagnitude};
use gvs::model::Model;
use gvs::rod::{Material, Rod};
use gvs::solve::statics::{solve_statics, StaticsOptions};
use gvs::strain::{DivisionBasis, FemDegree, LinearBasis};
use std::f64::consts::PI;

const L: f64 = 0.8;
const RADIUS: f64 = 0.015;
const E: f64 = 1e6;

fn beam() -> Model<LinearBasis> {
    let material = Material {
        youngs_modulus: E,
        poisson_ratio: 0.5,
        density: 1000.0,
        damping: 0.0,
    };
    let rod = Rod::tapered(material, L, RADIUS, RADIUS);
    let disc = Discretization::new(
        &rod,
        &[Quadrature::Elements {
            elements: 49,
            gauss_per_element: 2,
        }],
        MagnusOrder::Z4,
        &[],
    )
    .unwrap();
    let basis = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Fem {
            modes: [false, true, false, false, false, false],
            elements: 49,
            degree: FemDegree::Linear,
        }],
    )
    .unwrap();
    Model::new(rod, disc, basis, vec![]).unwrap()
}

fn pulse(center: f64, width: f64) -> Loads {
    Loads {
        gravity: [0.0; 3],
        point: vec![],
        distributed: vec![DistributedWrench::TriangularPulse {
            center,
            width,
            magnitude: 4.0,
            axis: [0.0, 1.0, 0.0],
            convention: PulseMagnitude::Total,
        }],
    }
}

/// The bend angle `∫ κ_y dX` at the solved equilibrium, by the trapezoidal rule over the points.
fn bend_angle(m: &Model<LinearBasis>, loads: &Loads) -> f64 {
    let sol = solve_statics(m, &[], loads, None, &StaticsOptions::default()).unwrap();
    let mut ws = m.workspace();
    m.forward(&sol.q, &mut ws, false);
    let xi = m.point_strains(&ws);
    let xs: Vec<f64> = m.disc.points.iter().map(|p| p.x).collect();
    (1..xs.len())
        .map(|i| 0.5 * (xs[i] - xs[i - 1]) * (xi[i - 1][1] + xi[i][1]))
        .sum()
}

#[test]
fn a_pulse_narrower_than_the_points_is_refused_naming_its_width() {
    let m = beam();
    for (width, shown) in [(0.005, "0.005 m"), (0.001, "0.001 m"), (1e-12, "1e-12 m")] {
        let e = m.prepare_loads(&pulse(0.2, width)).unwrap_err().to_string();
        assert!(
            e.contains("loads.distributed[0].width")
                && e.contains(shown)
                && e.contains("accepted ≤ 5 %")
                && e.contains("refine the discretization"),
            "{e}"
        );
    }
}

#[test]
fn a_pulse_below_the_floats_resolution_or_at_the_rods_end_is_refused_with_what_it_is() {
    let m = beam();
    // X₀ ± w/2 round to X₀: no extent at all, said so (not a NaN ratio)
    let e = m
        .prepare_loads(&pulse(0.3, 1e-300))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("1e-300 m: the pulse at 0.3 m has no extent in floating point"),
        "{e}"
    );
    assert!(!e.contains("NaN") && !e.contains("inf"), "{e}");
    // at the clamped end the gap to the first point counts (it was reported as 0.00 mm)
    let e = m.prepare_loads(&pulse(0.0, 0.005)).unwrap_err().to_string();
    assert!(e.contains("the pulse at 0 m"), "{e}");
    assert!(!e.contains("up to 0.00 mm"), "{e}");
}

/// A global force density `w` along +z on `[a, b]`.
fn uniform_z(a: f64, b: f64, w: f64) -> Loads {
    Loads {
        gravity: [0.0; 3],
        point: vec![],
        distributed: vec![DistributedWrench::Uniform {
            x_start: a,
            x_end: b,
            density: [0.0, 0.0, 0.0, 0.0, 0.0, w],
            frame: Frame::Global,
        }],
    }
}

/// The tip's z at the solved equilibrium.
fn tip_z(m: &Model<LinearBasis>, loads: &Loads) -> f64 {
    let sol = solve_statics(m, &[], loads, None, &StaticsOptions::default()).unwrap();
    let mut ws = m.workspace();
    m.forward(&sol.q, &mut ws, false);
    m.tip_pose(&ws).pos[2]
}

#[test]
fn a_uniform_load_with_ends_between_points_deflects_the_cantilever_as_the_closed_form() {
    let m = beam();
    let ei = E * PI * RADIUS.powi(4) / 4.0;
    // Euler–Bernoulli (the basis bends about y only): a force P at x moves the tip by
    // P x² (3L − x)/(6EI), so w on [a, b] moves it by w/(6EI) [L x³ − x⁴/4]_a^b; w small enough
    // (tip ≈ 1e-4 L) that the large-deflection terms are below 1e-8
    let closed = |a: f64, b: f64, w: f64| {
        let f = |x: f64| L * x.powi(3) - x.powi(4) / 4.0;
        w * (f(b) - f(a)) / (6.0 * ei)
    };
    let (a, b, w) = (0.1, 0.2, 0.004);
    // both ends fall between the Gauss points of their elements (h = L/49: a = 6.125 h,
    // b = 12.25 h), where the points' weights applied 6.5 h of the 6.125 h span
    let old: f64 = (m.disc.points.iter())
        .filter(|p| p.x >= a && p.x <= b)
        .map(|p| p.weight)
        .sum();
    assert!(
        (old / (b - a) - 1.0).abs() > 0.05,
        "the span is not a hard case: {old}"
    );
    let expected = closed(a, b, w);
    let tip = tip_z(&m, &uniform_z(a, b, w));
    assert!(
        (tip - expected).abs() < 1e-3 * expected,
        "tip {tip} m against the closed form {expected} m"
    );
    // a span far shorter than a cell (0.1 mm; the cells are h/2 = 8.2 mm) acts at its cell's
    // point with its whole resultant (it was lost, or refused): within the shift of its point of
    // action, 1.4 % of its abscissa
    let (a, b, w) = (0.1, 0.1001, 500.0 * 0.004 / 0.0625);
    let expected = closed(a, b, w);
    let tip = tip_z(&m, &uniform_z(a, b, w));
    assert!(
        (tip - expected).abs() < 0.05 * expected,
        "tip {tip} m against the closed form {expected} m"
    );
}

#[test]
fn the_papers_pulse_is_resolved_at_every_centre_and_bends_the_beam_as_the_closed_form() {
    let m = beam();
    // the IV-B dataset draws centres in [0, L]: every one must be accepted
    for i in 0..=800 {
        let center = L * i as f64 / 800.0;
        m.prepare_loads(&pulse(center, 0.08))
            .unwrap_or_else(|e| panic!("centre {center}: {e}"));
    }
    // a follower moment density m(X) bends by κ_y(X) = (1/EI) ∫_X^L m, so the bend angle is
    // ∫₀ᴸ κ_y dX = (1/EI) ∫₀ᴸ X m(X) dX = M X₀/(EI) for a pulse of total M centred at X₀ inside
    // the rod, whatever its width
    let ei = E * PI * RADIUS.powi(4) / 4.0;
    let expected = 4.0 * 0.2 / ei;
    for width in [0.08, 0.16] {
        let angle = bend_angle(&m, &pulse(0.2, width));
        // the points integrate the 0.08 m pulse within 0.82 % (the check's measurement)
        assert!(
            (angle - expected).abs() < 0.01 * expected,
            "width {width}: bend angle {angle} rad against M X₀/(EI) = {expected} rad"
        );
    }
}
