//! Tendons driven by their displacement in dynamics ([`gvs::solve::dynamics::drive`]): an
//! elastic thread whose motor sets its unstretched length. A damped run settles onto the
//! equilibrium the statics drive finds with the same compliance ([`gvs::solve::tendon_drive`],
//! itself checked against closed forms in `tendon_displacement.rs`), by every integrator and
//! Jacobian path; a tendon paid out stays slack and leaves the rod at rest; the linearization in
//! the displacement has the statics drive's gain; an inextensible tendon is refused, naming its
//! axial stiffness.

use gvs::actuation::Tendon;
use gvs::inputs::Signal;
use gvs::loads::Loads;
use gvs::model::Model;
use gvs::solve::dynamics::drive::DisplacementDriven;
use gvs::solve::dynamics::{
    simulate_streaming_interruptible, InitialState, IntegratorOptions, Method, OdeJacobian,
};
use gvs::solve::never_stop;
use gvs::solve::ode::{FixedStepOptions, NdfOptions};
use gvs::solve::statics::StaticsOptions;
use gvs::solve::tendon_drive::{solve_driven, Drive};
use gvs::strain::LinearBasis;
use nalgebra::DVector;
use std::ops::ControlFlow;
mod common;

const L: f64 = 0.25;

/// The IV-A rod in 3-D with the paper's damping (1e4 Pa·s) and two tendons: the IV-A tendon with
/// friction 0.1 and axial stiffness `ea` (driven), and its antagonist on the lower side (by
/// tension).
fn arm(ea: Option<f64>) -> Model<LinearBasis> {
    let driven = Tendon {
        axial_stiffness: ea,
        ..common::iva_tendon(0.1)
    };
    let antagonist = Tendon {
        offset_start: [0.0, -0.01],
        offset_end: [0.0, -0.003],
        ..common::iva_tendon(0.0)
    };
    common::iva_rod_3d(1e4, 10, &[], vec![driven, antagonist])
}

fn gravity() -> Loads {
    Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Default::default()
    }
}

/// The last sample `(q, u)` of a run of `duration` from rest under the constant channels `u`
/// (channel 0 a displacement).
fn settle(
    m: &Model<LinearBasis>,
    u: [f64; 2],
    loads: &Loads,
    duration: f64,
    options: &IntegratorOptions,
) -> (DVector<f64>, Vec<f64>, Vec<Vec<f64>>) {
    let signal = Signal::constant(&u);
    let actuation = DisplacementDriven::new(&signal, vec![true, false]);
    let t_out: Vec<f64> = (0..=20).map(|k| duration * k as f64 / 20.0).collect();
    let mut last = (DVector::zeros(0), vec![]);
    let mut tensions = vec![];
    let summary = simulate_streaming_interruptible(
        m,
        &actuation,
        loads,
        None,
        &InitialState::Rest,
        &t_out,
        options,
        &mut |s| {
            last = (DVector::from_column_slice(s.q), s.u.to_vec());
            tensions.push(s.u.to_vec());
            ControlFlow::Continue(())
        },
        &never_stop,
    )
    .unwrap();
    assert!(summary.error.is_none(), "{:?}", summary.error);
    (last.0, last.1, tensions)
}

fn tip(m: &Model<LinearBasis>, q: &DVector<f64>) -> nalgebra::Vector3<f64> {
    let mut ws = m.workspace();
    m.forward(q, &mut ws, false);
    m.tip_pose(&ws).pos
}

/// Wound in by 4 mm under gravity, the thread (EA = 40 N: it stretches by a third of the
/// displacement) pulls the arm up; after 3 s of the paper's damping the run rests on the
/// statics drive's equilibrium, tension and tip, by the NDF in second-order form, the NDF in
/// first-order form with finite-difference Jacobians, and the fixed step in first-order form
/// with the structured Jacobian (the springs' `M⁻¹ B_D C⁻¹ ∇ℓ_Dᵀ`).
#[test]
fn a_run_wound_in_settles_onto_the_driven_equilibrium() {
    let m = arm(Some(40.0));
    let delta = 4e-3;
    let statics = solve_driven(
        &m,
        &StaticsOptions::default(),
        &[Drive::Displacement(delta), Drive::Tension(0.0)],
        &gravity(),
        &never_stop,
    )
    .unwrap();
    let u_eq = statics.u[0];
    let c = m.tendon_compliances()[0];
    assert!(
        u_eq < 0.0 && c * -u_eq > 0.2 * delta,
        "u = {u_eq}, stretch {}",
        c * -u_eq
    );
    let tip_eq = tip(&m, &statics.statics.q);
    let ndf = NdfOptions {
        rtol: 1e-6,
        atol: 1e-9,
        ..Default::default()
    };
    let paths = [
        (
            "ndf, structured",
            Method::Ndf(ndf.clone()),
            OdeJacobian::Structured,
        ),
        (
            "ndf, finite differences",
            Method::Ndf(ndf),
            OdeJacobian::FiniteDifference,
        ),
        (
            "fixed, first order",
            Method::Fixed(FixedStepOptions {
                h: 2e-3,
                second_order: false,
                ..Default::default()
            }),
            OdeJacobian::Structured,
        ),
    ];
    for (name, method, jacobian) in paths {
        let options = IntegratorOptions { method, jacobian };
        let (q, u, history) = settle(&m, [delta, 0.0], &gravity(), 3.0, &options);
        let off = (tip(&m, &q) - tip_eq).norm() / L;
        assert!(off < 1e-5, "{name}: tip {off:e} L from the equilibrium");
        assert!(
            ((u[0] - u_eq) / u_eq).abs() < 1e-3,
            "{name}: u = {} vs {u_eq}",
            u[0]
        );
        assert_eq!(
            u[1], 0.0,
            "{name}: the antagonist is driven by its zero tension"
        );
        // from the straight rod, the thread starts stretched by the whole displacement
        assert!(
            (history[0][0] - (-delta / c)).abs() < 1e-9 * delta / c,
            "{name}: u(0) = {}",
            history[0][0]
        );
    }
}

/// Paid out by 2 mm without gravity, the thread is slack throughout: no tension at any sample and
/// the rod stays straight.
#[test]
fn a_tendon_paid_out_stays_slack_and_the_rod_at_rest() {
    let m = arm(Some(40.0));
    let options = IntegratorOptions::default();
    let (q, _, history) = settle(&m, [-2e-3, 0.0], &Loads::default(), 0.5, &options);
    assert!(history.iter().all(|u| u[0] == 0.0), "{history:?}");
    assert!(q.amax() < 1e-12, "q = {q}");
}

/// An inextensible tendon driven by its displacement is a constraint: refused before the run,
/// naming the field to give.
#[test]
fn an_inextensible_tendon_driven_in_dynamics_is_refused() {
    let m = arm(None);
    let signal = Signal::constant(&[1e-3, 0.0]);
    let actuation = DisplacementDriven::new(&signal, vec![true, false]);
    let e = simulate_streaming_interruptible(
        &m,
        &actuation,
        &Loads::default(),
        None,
        &InitialState::Rest,
        &[0.0, 0.1],
        &IntegratorOptions::default(),
        &mut |_| ControlFlow::Continue(()),
        &never_stop,
    )
    .err()
    .unwrap()
    .to_string();
    assert!(e.contains("tendons[0].axial_stiffness"), "{e}");
}

/// Linearized about the driven equilibrium with the displacement as the input
/// ([`Model::linearize_equilibrium_driven`]), the settled response `−A⁻¹ B` of `q` per metre wound
/// in is the statics drive's own `dq/dδ`, by central differences of two drives 1 µm apart; a
/// slack channel has no column, and an inextensible thread is refused.
#[test]
fn the_linearization_in_the_displacement_has_the_statics_drive_s_gain() {
    use gvs::dynamics::Channel;
    let m = arm(Some(40.0));
    let drive = |delta: f64| {
        solve_driven(
            &m,
            &StaticsOptions::default(),
            &[Drive::Displacement(delta), Drive::Tension(-0.2)],
            &gravity(),
            &never_stop,
        )
        .unwrap()
    };
    let (delta, h) = (4e-3, 1e-6);
    let eq = drive(delta);
    let n = m.n_dof();
    let loads = m.prepare_loads(&gravity()).unwrap();
    let channels = [Channel::Displacement { taut: true }, Channel::Tension];
    let lin = m
        .linearize_equilibrium_driven(&eq.statics.q, &eq.u, &channels, &loads, &mut m.workspace())
        .unwrap();
    let gain = -lin.a.clone().lu().solve(&lin.b).unwrap();
    let dq = (drive(delta + h).statics.q - drive(delta - h).statics.q) / (2.0 * h);
    let err = (gain.view((0, 0), (n, 1)) - &dq).amax() / dq.amax();
    assert!(err < 1e-5, "dq/dδ off by {err:e} of its largest entry");
    // the tension channel is the plain tendon's: its column is M⁻¹ B_1
    let by_tension = m
        .linearize_equilibrium(&eq.statics.q, &eq.u, &loads, &mut m.workspace())
        .unwrap();
    assert!((lin.b.column(1) - by_tension.b.column(1)).amax() < 1e-12 * by_tension.b.amax());
    let slack = m
        .linearize_equilibrium_driven(
            &eq.statics.q,
            &eq.u,
            &[Channel::Displacement { taut: false }, Channel::Tension],
            &loads,
            &mut m.workspace(),
        )
        .unwrap();
    assert_eq!(slack.b.column(0).amax(), 0.0);
    let rigid = arm(None);
    let e = rigid
        .linearize_equilibrium_driven(
            &eq.statics.q,
            &eq.u,
            &channels,
            &loads,
            &mut rigid.workspace(),
        )
        .unwrap_err();
    assert!(e.to_string().contains("tendons[0].axial_stiffness"), "{e}");
}
