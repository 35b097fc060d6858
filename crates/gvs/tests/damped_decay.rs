//! Free decay of a Kelvin–Voigt rod against the damped oscillator of its first mode: the decay rate
//! and the damped frequency of a simulated release, fitted from the samples, against
//! `σ = ζ ω`, `ω_d = ω √(1 − ζ²)`.

mod common;

use gvs::inputs::Signal;
use gvs::loads::Loads;
use gvs::model::Model;
use gvs::rod::{Material, Rod, SectionProps};
use gvs::solve::dynamics::{
    method_for_rod, simulate, InitialState, IntegratorOptions, OdeJacobian,
};
use gvs::strain::LinearBasis;
use nalgebra::DVector;
use std::f64::consts::PI;

const L: f64 = 0.5;
const R: f64 = 0.005;
const E: f64 = 1e6;
const RHO: f64 = 1000.0;

/// The uniform cantilever (L = 0.5 m, r = 5 mm, E = 1 MPa, ν = ½, ρ = 1000 kg/m³) with damping
/// constant `eta`: bending, elongation and shear in the x–z plane, Legendre order 6, 21 Gauss
/// points.
fn cantilever(eta: f64) -> Model<LinearBasis> {
    let mat = Material {
        youngs_modulus: E,
        poisson_ratio: 0.5,
        density: RHO,
        damping: eta,
    };
    common::legendre_model(
        Rod::tapered(mat, L, R, R),
        21,
        [false, true, false, true, false, true],
        6,
    )
}

/// Two-pole Prony fit of uniformly sampled `a_k = A e^{−σ t_k} cos(ω_d t_k + φ)`: the least-squares
/// `a_{k+1} = c₁ a_k + c₂ a_{k−1}` has the roots `z = e^{(−σ ± i ω_d) h}` of `z² − c₁ z − c₂`, so
/// `e^{−2σh} = −c₂` and `cos ω_d h = c₁ / (2 √(−c₂))`. Returns `(σ, ω_d)`.
fn prony(a: &[f64], h: f64) -> (f64, f64) {
    let (mut s11, mut s12, mut s22, mut b1, mut b2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for k in 1..a.len() - 1 {
        let (x1, x2, y) = (a[k], a[k - 1], a[k + 1]);
        s11 += x1 * x1;
        s12 += x1 * x2;
        s22 += x2 * x2;
        b1 += x1 * y;
        b2 += x2 * y;
    }
    let det = s11 * s22 - s12 * s12;
    let c1 = (b1 * s22 - b2 * s12) / det;
    let c2 = (s11 * b2 - s12 * b1) / det;
    let rho = (-c2).sqrt();
    (-rho.ln() / h, (c1 / (2.0 * rho)).acos() / h)
}

/// The free decay of the first mode of `cantilever(eta)`, started on its shape at `amplitude` (tip
/// deflection / L) and at rest, over four periods sampled 40 times a period: the fitted `σ` and
/// `ω_d` ([`prony`] of the modal amplitude `φᵀ M q`) relative to `ζ ω` and `ω √(1 − ζ²)`, `ω` the
/// first linearized mode's at rest, `ζ = τω/2`, `τ = 3η/E`. Returns `(σ error, ω_d error, ζ, ω)`.
fn decay_errors(eta: f64, amplitude: f64) -> (f64, f64, f64, f64) {
    let m = cantilever(eta);
    let n = m.n_dof();
    let tau = 3.0 * eta / E;
    assert!(
        (m.damping_time() - tau).abs() < 1e-15 * tau,
        "τ = {}",
        m.damping_time()
    );
    let q0 = DVector::zeros(n);
    let prepared = m.prepare_loads(&Loads::default()).unwrap();
    let mut ws = m.workspace();
    let modes = m.linearized_modes(&q0, &[], &prepared, &mut ws).unwrap();
    let omega = modes[0].omega_squared.sqrt();
    let zeta = tau * omega / 2.0;
    let (sigma, omega_d) = (zeta * omega, omega * (1.0 - zeta * zeta).sqrt());
    // the first mode scaled to the amplitude at the tip (φ is mass-normalized: O(1) coordinates,
    // a large deflection, so its linear tip is taken from a small multiple)
    let phi = &modes[0].shape;
    let mut tip_z = |q: &DVector<f64>| {
        m.forward(q, &mut ws, false);
        ws.g.last().unwrap().pos[2]
    };
    let small = 1e-6 / phi.amax();
    let q_start = phi * (amplitude * L * small / tip_z(&(phi * small)).abs());
    let phi_m = m.mass_matrix(&q0, &mut m.workspace()) * phi;
    let h = 2.0 * PI / omega_d / 40.0;
    let t: Vec<f64> = (0..=160).map(|k| k as f64 * h).collect();
    // the integrator the CLI picks for this rod (the NDF), tight
    let (method, _) = method_for_rod(&m, Some(1e-9), 1e-13).unwrap();
    let sim = simulate(
        &m,
        &Signal::constant(&[]),
        &Loads::default(),
        None,
        &InitialState::Given {
            q: q_start,
            qd: DVector::zeros(n),
        },
        &t,
        &IntegratorOptions {
            method,
            jacobian: OdeJacobian::Structured,
        },
    )
    .unwrap();
    assert!(sim.error.is_none(), "{:?}", sim.error);
    let a: Vec<f64> = sim.trajectory.q.iter().map(|q| q.dot(&phi_m)).collect();
    let (s_fit, w_fit) = prony(&a, h);
    (s_fit / sigma - 1.0, w_fit / omega_d - 1.0, zeta, omega)
}

/// Kelvin–Voigt damping `D_s = η diag(J, 3I, 3I, 3A, A, A)` is, for ν = ½ (G = E/3), the stiffness
/// `E_s` times `τ = 3η/E`, so the damping matrix at rest is `τ K` and the modes of the undamped rod
/// decay independently: the mode ω as a damped oscillator with `ζ = τω/2`, decay rate `σ = ζω`,
/// damped frequency `ω_d = ω √(1 − ζ²)`. Released from its first mode at 1 % L ([`decay_errors`]),
/// at η = 12 kPa·s (ζ = 0.02) and 60 kPa·s (ζ = 0.1): measured relative errors of σ 3.0e-6 and
/// 2.0e-6, of ω_d 1.3e-6 and 9.5e-7; bounds 2e-5 and 1e-5. What is left is mostly the geometric
/// nonlinearity, O((A/L)²): at a quarter of the amplitude the errors fall to 6.0e-7 and 1.7e-7 (σ;
/// the integrator's rtol 1e-9 floors it, 2.3e-7 and 1.3e-7 at 1e-10) and 8.1e-8 and 5.8e-8 (ω_d),
/// required below half of those at 1 % L. The ω of the linearized mode is the Euler–Bernoulli
/// cantilever's `1.8751² √(EI/ρAL⁴)` less 2.3e-4: the shear and rotary inertia it leaves out,
/// O((β r)²) = O(4e-4) with βL = 1.875; bound 1e-3. About 0.1 s.
#[test]
fn kelvin_voigt_free_decay_has_rate_zeta_omega_and_damped_frequency() {
    for (eta, zeta_expected) in [(12e3, 0.02), (60e3, 0.1)] {
        let (e_sigma, e_omega, zeta, omega) = decay_errors(eta, 0.01);
        assert!(
            (zeta - zeta_expected).abs() < 1e-3 * zeta_expected,
            "ζ = {zeta}"
        );
        let s = SectionProps::circular(&cantilever(eta).rod.material, R);
        let omega_eb =
            1.875_104_068_711_961f64.powi(2) * (s.es[1] / (RHO * s.area * L.powi(4))).sqrt();
        let (e_small_sigma, e_small_omega, _, _) = decay_errors(eta, 0.0025);
        eprintln!(
            "ζ = {zeta:.5}: σ {e_sigma:+.2e}, ω_d {e_omega:+.2e} at 1 % L; \
             σ {e_small_sigma:+.2e}, ω_d {e_small_omega:+.2e} at 0.25 % L; \
             ω {omega:.8} against Euler–Bernoulli {omega_eb:.8} ({:+.2e})",
            omega / omega_eb - 1.0
        );
        assert!(e_sigma.abs() < 2e-5, "ζ = {zeta}: σ off by {e_sigma:e}");
        assert!(e_omega.abs() < 1e-5, "ζ = {zeta}: ω_d off by {e_omega:e}");
        assert!(
            e_small_sigma.abs() < 0.5 * e_sigma.abs() && e_small_omega.abs() < 0.5 * e_omega.abs(),
            "ζ = {zeta}: at 0.25 % L σ off by {e_small_sigma:e}, ω_d by {e_small_omega:e}"
        );
        assert!(
            (omega / omega_eb - 1.0).abs() < 1e-3,
            "ω {omega} against {omega_eb}"
        );
    }
}
