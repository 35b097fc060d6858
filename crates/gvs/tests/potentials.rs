//! The conservative generalized forces are gradients of the engine's own potentials, on a fully 3-D
//! state (torsion, bending about both axes, stretch and shear; gravity oblique to the rod):
//! `F_g = −∇_q U_g` and `K₁ = ∇_q U_e` with `U_g`, `U_e` of [`Model::energy`] (gvs-spec §7.3, §7.5,
//! §9.4), and the tendon column `B_k = ∇_q ℓ_k` with `ℓ_k` the length of the routed tendon path
//! `p(X) = r(X) + R(X) d(X)` (the tension's virtual work, spec §7.6), for an off-plane routing whose
//! offset sweeps around the axis. Every gradient is a central difference of a scalar evaluated
//! here; the force comes from the engine's force path.

use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::lie::V3;
use gvs::loads::Loads;
use gvs::model::Model;
use gvs::rod::{Material, Rod};
use gvs::strain::{LinearBasis, SigmoidBend, StrainParam};
use nalgebra::DVector;
mod common;

use common::pseudo_random;

/// Oblique gravity [m/s²]: components along, across and below the rod.
const GRAVITY: [f64; 3] = [3.0, -4.0, -8.0];

fn material() -> Material {
    Material {
        youngs_modulus: 0.617e6,
        poisson_ratio: 0.5,
        density: 1121.0,
        damping: 0.0,
    }
}

/// The off-plane tendon: its offset turns by ≈ 140° about the axis (from (6, −2) mm at the base to
/// (−2, 3) mm at the tip), so with torsion and two-plane bending the path is a skew space curve.
fn skew_tendon() -> Tendon {
    Tendon {
        offset_start: [0.006, -0.002],
        offset_end: [-0.002, 0.003],
        x_start: 0.0,
        x_end: 0.25,
        friction: 0.0,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: None,
    }
}

/// IV-A tapered rod (L = 0.25 m, r 12.5 → 5 mm) with all six modes active (Legendre orders
/// [1, 2, 2, 1, 1, 1], 14 coordinates), 12 Gauss points, Z4, the skew tendon; `extra` adds
/// weight-0 points (they refine the kinematics only).
fn model_3d(extra: &[f64]) -> Model<LinearBasis> {
    model_3d_with(extra, skew_tendon())
}

fn model_3d_with(extra: &[f64], tendon: Tendon) -> Model<LinearBasis> {
    common::iva_rod_3d(0.0, 12, extra, vec![tendon])
}

/// A 3-D state: every coordinate random in [−0.6, 0.6] (angles in rad, strains dimensionless),
/// then checked to twist, bend out of both planes and stretch.
fn state_3d(m: &Model<LinearBasis>) -> DVector<f64> {
    let q = pseudo_random(m.n_dof(), 17, 0.6);
    let mut ws = m.workspace();
    m.forward(&q, &mut ws, false);
    let tip = m.tip_pose(&ws).pos;
    let xi = m.point_strains(&ws);
    let mid = xi[xi.len() / 2];
    assert!(
        tip[1].abs() > 0.01 && tip[2].abs() > 0.01,
        "tip {tip} leaves both planes"
    );
    assert!(
        mid[0].abs() > 0.5 && mid[1].abs() > 0.5 && mid[2].abs() > 0.5,
        "torsion and both curvatures at mid-span: {mid}"
    );
    assert!((mid[3] - 1.0).abs() > 0.01, "stretched at mid-span: {mid}");
    q
}

/// Central-difference gradient of `f` at `q` with step `h`.
fn gradient(q: &DVector<f64>, h: f64, mut f: impl FnMut(&DVector<f64>) -> f64) -> DVector<f64> {
    DVector::from_fn(q.len(), |j, _| {
        let mut qp = q.clone();
        qp[j] += h;
        let mut qm = q.clone();
        qm[j] -= h;
        (f(&qp) - f(&qm)) / (2.0 * h)
    })
}

fn rel_err(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).amax() / b.amax()
}

/// `F_g(q) = −∇_q U_g`, `U_g = −Σ_i W_i ρA_i g·r_i` (gvs-spec §7.5, §9.4): the gravity part of the
/// external force from the backward pass against central differences of the gravitational energy.
#[test]
fn gravity_force_is_minus_gradient_of_gravitational_energy_in_3d() {
    let m = model_3d(&[]);
    let q = state_3d(&m);
    let loads = m
        .prepare_loads(&Loads {
            gravity: GRAVITY,
            ..Loads::default()
        })
        .unwrap();
    let mut ws = m.workspace();
    let f_g = m.external_force(&q, &loads, &mut ws);
    let zero = DVector::zeros(m.n_dof());
    let grad = gradient(&q, 1e-5, |x| {
        m.energy(x, &zero, &GRAVITY, &mut ws).gravitational
    });
    let err = rel_err(&f_g, &(-&grad));
    // O(h²) truncation with h = 1e-5 on unit-scale angles: ~1e-10
    assert!(err < 1e-9, "F_g vs −∇U_g: relative {err:e}\nF_g = {f_g}");
}

/// `K₁(q) = ∇_q U_e`, `U_e = ½ Σ_i W_i Ψ_iᵀ Es_i Ψ_i` (gvs-spec §7.3): the elastic force of the
/// residual assembly against central differences of the elastic energy (quadratic for a linear
/// basis, so the difference is exact up to round-off).
#[test]
fn elastic_force_is_gradient_of_elastic_energy_in_3d() {
    let m = model_3d(&[]);
    let q = state_3d(&m);
    let mut ws = m.workspace();
    let k1 = m.elastic_force(&q, &mut ws);
    let zero = DVector::zeros(m.n_dof());
    let grad = gradient(&q, 1e-4, |x| m.energy(x, &zero, &[0.0; 3], &mut ws).elastic);
    let err = rel_err(&k1, &grad);
    assert!(err < 1e-9, "K₁ vs ∇U_e: relative {err:e}\nK₁ = {k1}");
}

/// `K₁(q) = Σ W Ψ_qᵀ Es Ψ(q) = ∇_q U_e` for a nonlinear parameterization too (gvs-spec §7.3), with
/// the bending-y sigmoid `Ψ₂ = q₁/ℓ σ(−q₂(X̄ − q₃))`.
#[test]
fn elastic_force_is_gradient_of_elastic_energy_for_nonlinear_sigmoid() {
    let rod = Rod::tapered(material(), 0.8, 0.015, 0.015);
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 16 }], MagnusOrder::Z4, &[]).unwrap();
    let p = SigmoidBend::new(&disc);
    let m = Model::new(rod, disc, p, vec![]).unwrap();
    let q = DVector::from_vec(vec![1.3, 9.0, 0.4]);
    let mut ws = m.workspace();
    let k1 = m.elastic_force(&q, &mut ws);
    let zero = DVector::zeros(m.n_dof());
    let grad = gradient(&q, 1e-6, |x| m.energy(x, &zero, &[0.0; 3], &mut ws).elastic);
    let err = rel_err(&k1, &grad);
    assert!(err < 1e-8, "K₁ vs ∇U_e: relative {err:e}\nK₁ = {k1}");
}

/// The custom path of [`path_tendon`]: `d_y = 6 mm − 0.05 X + 0.1 X²`, `d_z = −2 mm + 0.05 X −
/// 0.12 X²` (X in m), a quadratic the engine's cubic through its knots reproduces exactly.
fn quadratic_offset(x: f64) -> V3 {
    V3::new(
        0.0,
        0.006 - 0.05 * x + 0.1 * x * x,
        -0.002 + 0.05 * x - 0.12 * x * x,
    )
}

/// A custom path (spec §7.6 "Custom") through five uneven knots of [`quadratic_offset`]: a
/// curved, non-planar routing from (6, −2) mm at the base to (−0.25, 3) mm at the tip.
fn path_tendon() -> Tendon {
    let path: Vec<[f64; 3]> = [0.0, 0.04, 0.1, 0.18, 0.25]
        .iter()
        .map(|&x| {
            let d = quadratic_offset(x);
            [x, d[1], d[2]]
        })
        .collect();
    Tendon {
        offset_start: [path[0][1], path[0][2]],
        offset_end: [path[4][1], path[4][2]],
        path,
        ..skew_tendon()
    }
}

/// The routed offset `d(X) = d₀ + (X − X_s)/(X_e − X_s) (d₁ − d₀)` ("oblique" routing, spec §7.6),
/// turned for a helical routing; [`quadratic_offset`] for a custom path.
fn offset_at(t: &Tendon, x: f64) -> V3 {
    if !t.path.is_empty() {
        return quadratic_offset(x);
    }
    let s = (x - t.x_start) / (t.x_end - t.x_start);
    let y = t.offset_start[0] + s * (t.offset_end[0] - t.offset_start[0]);
    let z = t.offset_start[1] + s * (t.offset_end[1] - t.offset_start[1]);
    // a helical routing turns the interpolated offset about +x by 2π·turns·s
    let phi = 2.0 * std::f64::consts::PI * t.turns * s;
    V3::new(
        0.0,
        phi.cos() * y - phi.sin() * z,
        phi.sin() * y + phi.cos() * z,
    )
}

/// `d'(X)` by a central difference of [`offset_at`] (independent of the engine's analytic rate).
fn offset_rate_at(t: &Tendon, x: f64) -> V3 {
    let h = 1e-6 * (t.x_end - t.x_start);
    (offset_at(t, x + h) - offset_at(t, x - h)) / (2.0 * h)
}

/// A tapered helix: 1.5 turns about the axis from the top of the section, radius 9 → 4 mm.
fn helical_tendon() -> Tendon {
    Tendon {
        offset_start: [0.0, 0.009],
        offset_end: [0.0, 0.004],
        turns: 1.5,
        ..skew_tendon()
    }
}

/// The discrete tendon length `ℓ_h(q) = Σ_i W_i ‖t_u(X_i)‖`, `t_u = ν + k × d + d'` (the speed
/// `‖dp/dX‖` of the tendon path `p = r + R d` in the section frame, spec §7.6), over the tendon's
/// weighted points, with `d(X)` interpolated here from the tendon's end offsets.
fn tendon_length<P: StrainParam>(
    m: &Model<P>,
    k: usize,
    q: &DVector<f64>,
    ws: &mut gvs::model::Workspace,
) -> f64 {
    let t = &m.tendons[k];
    let pts = m.tendon_points(k).to_vec();
    let xi = m.strains_at(q, ws);
    pts.iter()
        .map(|&i| {
            let p = m.disc.points[i];
            let kv = V3::new(xi[i][0], xi[i][1], xi[i][2]);
            let nu = V3::new(xi[i][3], xi[i][4], xi[i][5]);
            p.weight * (nu + kv.cross(&offset_at(t, p.x)) + offset_rate_at(t, p.x)).norm()
        })
        .sum()
}

/// `B_k(q) = ∇_q ℓ_k(q)` for a frictionless tendon (gvs-spec §7.6: `Bu = Σ W Φᵀ Φ_a u` with
/// `Φ_a = [d × t; t] = ∂‖t_u‖/∂ξ`), on the off-plane routing and a 3-D state. The length is first
/// checked to be the routed tendon length: the chord length of `p_i = r_i + R_i d(X_i)` on 1601
/// extra weight-0 points (which refine the kinematics but leave the Gauss points, weights and
/// strains unchanged).
#[test]
fn tendon_column_is_gradient_of_routed_tendon_length_off_plane() {
    tendon_column_is_gradient_of_routed_length(skew_tendon());
}

/// The same for a helical routing (1.5 turns about the axis, tapered radius), whose offset rate
/// `d'(X)` turns with it: the test's `d'` is a central difference of its own `d(X)`.
#[test]
fn tendon_column_is_gradient_of_routed_tendon_length_helical() {
    tendon_column_is_gradient_of_routed_length(helical_tendon());
}

/// The same for a custom path through five knots (a curved, non-planar routing).
#[test]
fn tendon_column_is_gradient_of_routed_tendon_length_custom_path() {
    tendon_column_is_gradient_of_routed_length(path_tendon());
}

fn tendon_column_is_gradient_of_routed_length(tendon: Tendon) {
    let m = model_3d_with(&[], tendon.clone());
    let q = state_3d(&m);
    let mut ws = m.workspace();
    let l_h = tendon_length(&m, 0, &q, &mut ws);

    // the same rod with a dense polyline: the tendon's geometric length
    let xs: Vec<f64> = (1..=1601).map(|k| 0.25 * k as f64 / 1602.0).collect();
    let fine = model_3d_with(&xs, tendon);
    let mut wf = fine.workspace();
    assert!(
        (tendon_length(&fine, 0, &q, &mut wf) - l_h).abs() < 1e-15,
        "extra points change ℓ_h"
    );
    fine.forward(&q, &mut wf, false);
    let t = &fine.tendons[0];
    let path: Vec<V3> = fine
        .tendon_points(0)
        .iter()
        .map(|&i| {
            let x = fine.disc.points[i].x;
            wf.g[i].pos + wf.g[i].rot * offset_at(t, x)
        })
        .collect();
    let chord: f64 = path.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    let geo_err = (chord - l_h).abs() / l_h;
    // chord error ~ (ΔX κ)²/24 (κ ≈ 8.5 1/m on the helix: 7e-8) and Gauss error of ∫‖t_u‖ with
    // 12 points
    assert!(
        geo_err < 1e-6,
        "ℓ_h = {l_h} vs chord length {chord}: {geo_err:e}"
    );

    // the engine's lengths are this one (up to this test's own d and d', a central difference:
    // measured ≤ 7e-14 m)
    let engine = m.tendon_lengths(&q, &mut ws)[0];
    assert!(
        (engine - l_h).abs() < 1e-12 * l_h,
        "Model::tendon_lengths {engine} vs ℓ_h {l_h}"
    );

    let b = m.actuation_matrix(&q, &mut ws);
    let grad = gradient(&q, 1e-6, |x| tendon_length(&m, 0, x, &mut ws));
    let col = b.column(0).into_owned();
    let err = rel_err(&col, &grad);
    assert!(err < 1e-8, "B vs ∇ℓ: relative {err:e}\nB = {col}");
    // the torsion coordinates take a real share: the routing is not planar
    assert!(
        col[0].abs().max(col[1].abs()) > 1e-3 * col.amax(),
        "torsion columns of B: {col}"
    );
}
