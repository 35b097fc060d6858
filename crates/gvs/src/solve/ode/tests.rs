//! Tests of the NDF integrator (and shared test problems).

use super::*;
use nalgebra::{DMatrix, DVector};

/// `y' = f(t, y)` from a closure, with an optional analytic Jacobian closure.
pub(super) struct FnSys<F, J = fn(f64, &DVector<f64>, &mut DMatrix<f64>)> {
    pub n: usize,
    pub f: F,
    pub jac: Option<J>,
    pub calls: Vec<f64>,
}

pub(super) fn sys<F>(n: usize, f: F) -> FnSys<F>
where
    F: FnMut(f64, &DVector<f64>, &mut DVector<f64>),
{
    FnSys {
        n,
        f,
        jac: None,
        calls: Vec::new(),
    }
}

impl<F, J> OdeSystem for FnSys<F, J>
where
    F: FnMut(f64, &DVector<f64>, &mut DVector<f64>),
    J: FnMut(f64, &DVector<f64>, &mut DMatrix<f64>),
{
    fn dim(&self) -> usize {
        self.n
    }
    fn rhs(&mut self, t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) -> Result<(), RhsError> {
        self.calls.push(t);
        (self.f)(t, y, dy);
        Ok(())
    }
    fn jacobian(
        &mut self,
        t: f64,
        y: &DVector<f64>,
        jac: &mut DMatrix<f64>,
    ) -> Result<bool, RhsError> {
        match &mut self.jac {
            Some(j) => {
                j(t, y, jac);
                Ok(true)
            }
            None => Ok(false),
        }
    }
}

/// Output samples `(t, y)`.
pub(super) type Samples = Vec<(f64, DVector<f64>)>;

pub(super) fn ndf<S: OdeSystem>(
    s: &mut S,
    y0: &[f64],
    t_out: &[f64],
    bps: &[f64],
    o: &NdfOptions,
) -> (Samples, Result<OdeStats, OdeError>) {
    let mut out = Vec::new();
    let r = integrate_ndf(
        s,
        0.0,
        &DVector::from_column_slice(y0),
        t_out,
        bps,
        o,
        &mut |t, y| {
            out.push((t, y.clone()));
            std::ops::ControlFlow::Continue(())
        },
    );
    (out, r.map_err(|f| f.error))
}

pub(super) fn linspace(a: f64, b: f64, m: usize) -> Vec<f64> {
    (0..m)
        .map(|i| a + (b - a) * i as f64 / (m - 1) as f64)
        .collect()
}

/// `A = R diag(−1, −1e4) Rᵀ` (rotation by 0.5 rad) and its exact solution `exp(At) y0`.
pub(super) fn stiff_matrix() -> DMatrix<f64> {
    let (c, s) = (0.5f64.cos(), 0.5f64.sin());
    let r = DMatrix::from_row_slice(2, 2, &[c, -s, s, c]);
    &r * DMatrix::from_diagonal(&DVector::from_vec(vec![-1.0, -1e4])) * r.transpose()
}

pub(super) fn stiff_exact(t: f64, y0: &DVector<f64>) -> DVector<f64> {
    let (c, s) = (0.5f64.cos(), 0.5f64.sin());
    let r = DMatrix::from_row_slice(2, 2, &[c, -s, s, c]);
    let e = DMatrix::from_diagonal(&DVector::from_vec(vec![(-t).exp(), (-1e4 * t).exp()]));
    &r * e * r.transpose() * y0
}

/// `y' = −y + sin t`, exact `y = (sin t − cos t)/2 + (y0 + ½)e^{−t}`.
pub(super) fn forced_exact(t: f64, y0: f64) -> f64 {
    0.5 * (t.sin() - t.cos()) + (y0 + 0.5) * (-t).exp()
}

pub(super) fn forced_rhs(t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) {
    dy[0] = -y[0] + t.sin();
}

fn robertson(_t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) {
    dy[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
    dy[1] = 0.04 * y[0] - 1e4 * y[1] * y[2] - 3e7 * y[1] * y[1];
    dy[2] = 3e7 * y[1] * y[1];
}

fn robertson_jac(_t: f64, y: &DVector<f64>, j: &mut DMatrix<f64>) {
    j.copy_from_slice(&[
        -0.04,
        0.04,
        0.0,
        1e4 * y[2],
        -1e4 * y[2] - 6e7 * y[1],
        6e7 * y[1],
        1e4 * y[1],
        -1e4 * y[1],
        0.0,
    ]);
}

fn vdp(mu: f64) -> impl FnMut(f64, &DVector<f64>, &mut DVector<f64>) {
    move |_t, y, dy| {
        dy[0] = y[1];
        dy[1] = mu * (1.0 - y[0] * y[0]) * y[1] - y[0];
    }
}

#[test]
fn stiff_linear_matches_matrix_exponential_in_few_steps() {
    let a = stiff_matrix();
    let mut s = sys(2, move |_t, y: &DVector<f64>, dy: &mut DVector<f64>| {
        dy.gemv(1.0, &a, y, 0.0)
    });
    let y0 = DVector::from_vec(vec![1.0, 1.0]);
    let t_out = linspace(0.0, 10.0, 101);
    let o = NdfOptions {
        rtol: 1e-4,
        atol: 1e-8,
        ..Default::default()
    };
    let (out, r) = ndf(&mut s, y0.as_slice(), &t_out, &[], &o);
    let st = r.unwrap();
    println!("stiff linear: {st:?}");
    assert_eq!(out.len(), t_out.len());
    for (t, y) in &out {
        let ex = stiff_exact(*t, &y0);
        for i in 0..2 {
            let tol = 10.0 * (o.rtol * ex[i].abs() + o.atol);
            assert!(
                (y[i] - ex[i]).abs() <= tol,
                "t = {t}: y[{i}] = {} vs {}",
                y[i],
                ex[i]
            );
        }
    }
    assert!(st.steps < 200, "{} steps: stiffness not handled", st.steps);
    // The fast mode (time constant 1e-4) must not force tiny steps over the smooth part.
    assert!(st.steps > 10);
}

#[test]
fn robertson_matches_reference_at_t40() {
    let mut s = FnSys {
        n: 3,
        f: robertson,
        jac: Some(robertson_jac),
        calls: Vec::new(),
    };
    let o = NdfOptions {
        rtol: 1e-4,
        atol: 1e-8,
        ..Default::default()
    };
    let (out, r) = ndf(&mut s, &[1.0, 0.0, 0.0], &[0.0, 0.4, 4.0, 40.0], &[], &o);
    let st = r.unwrap();
    println!("Robertson: {st:?}");
    let y = &out.last().unwrap().1;
    let reference = [0.7158270687, 9.185534764e-6, 0.2841637457];
    for i in 0..3 {
        let rel = (y[i] - reference[i]).abs() / reference[i];
        assert!(
            rel < 1e-4,
            "y[{i}] = {} vs {} (rel. error {rel:e})",
            y[i],
            reference[i]
        );
    }
    assert!(
        (y.sum() - 1.0).abs() < 1e-8,
        "mass conservation: {}",
        y.sum()
    );
    assert!(st.steps < 300, "{} steps", st.steps);
}

#[test]
fn van_der_pol_mu1000_completes_and_matches_tight_run() {
    let t_out = linspace(0.0, 3000.0, 31);
    let mut s = sys(2, vdp(1000.0));
    let (out, r) = ndf(&mut s, &[2.0, 0.0], &t_out, &[], &NdfOptions::default());
    let st = r.unwrap();
    println!("Van der Pol mu = 1000, rtol 1e-3: {st:?}");
    let mut s = sys(2, vdp(1000.0));
    let tight = NdfOptions {
        rtol: 1e-8,
        atol: 1e-10,
        ..Default::default()
    };
    let (ref_out, r) = ndf(&mut s, &[2.0, 0.0], &t_out, &[], &tight);
    println!("Van der Pol mu = 1000, rtol 1e-8: {:?}", r.unwrap());
    let y = &out.last().unwrap().1;
    let yr = &ref_out.last().unwrap().1;
    println!("y1(3000) = {} (rtol 1e-3), {} (rtol 1e-8)", y[0], yr[0]);
    assert!(
        yr[0] < -1.4 && yr[0] > -1.7,
        "reference y1(3000) = {}",
        yr[0]
    );
    assert!((y[0] - yr[0]).abs() < 0.02, "{} vs {}", y[0], yr[0]);
    assert!((300..2500).contains(&st.steps), "{} steps", st.steps);
    // The relaxation oscillation: y1 stays within about [−2.1, 2.1].
    assert!(out.iter().all(|(_, y)| y[0].abs() < 2.1));
}

fn forced_error(rtol: f64) -> (f64, usize) {
    let mut s = sys(1, forced_rhs);
    let t_out = linspace(0.0, 10.0, 201);
    let o = NdfOptions {
        rtol,
        atol: rtol * 1e-3,
        ..Default::default()
    };
    let (out, r) = ndf(&mut s, &[1.0], &t_out, &[], &o);
    let st = r.unwrap();
    let err = out
        .iter()
        .map(|(t, y)| (y[0] - forced_exact(*t, 1.0)).abs())
        .fold(0.0, f64::max);
    (err, st.steps)
}

#[test]
fn global_error_shrinks_with_tolerance() {
    let (e1, n1) = forced_error(1e-4);
    let (e2, n2) = forced_error(1e-6);
    let (e3, n3) = forced_error(1e-8);
    println!("rtol 1e-4: err {e1:e} ({n1} steps); 1e-6: {e2:e} ({n2}); 1e-8: {e3:e} ({n3})");
    for (a, b) in [(e1, e2), (e2, e3)] {
        let ratio = a / b;
        assert!(
            (8.0..=300.0).contains(&ratio),
            "100x tighter rtol reduced the error by {ratio}"
        );
    }
    assert!(e1 < 1e-2 && e2 < 1e-4 && e3 < 1e-6);
    assert!(n1 < n2 && n2 < n3);
}

#[test]
fn dense_output_between_steps_is_accurate() {
    let mut s = sys(1, forced_rhs);
    let t_out = linspace(0.0, 10.0, 2001);
    let o = NdfOptions {
        rtol: 1e-6,
        atol: 1e-9,
        ..Default::default()
    };
    let (out, r) = ndf(&mut s, &[1.0], &t_out, &[], &o);
    let st = r.unwrap();
    assert_eq!(out.len(), 2001);
    assert!(out.iter().zip(&t_out).all(|((t, _), tq)| t == tq));
    // Far fewer steps than outputs: the outputs are interpolated, not stepped to.
    assert!(st.steps < 400, "{} steps", st.steps);
    let err = out
        .iter()
        .map(|(t, y)| (y[0] - forced_exact(*t, 1.0)).abs())
        .fold(0.0, f64::max);
    assert!(err < 2e-5, "max interpolation error {err:e}");
}

#[test]
fn breakpoints_are_stepped_onto_and_piecewise_linear_solution_is_exact() {
    // y' = u(t), u = 1 on [0, 1), −2 on [1, 2), 0.5 from 2 (a zero-order hold, right-continuous).
    let u = |t: f64| {
        if t < 1.0 {
            1.0
        } else if t < 2.0 {
            -2.0
        } else {
            0.5
        }
    };
    let exact = |t: f64| {
        if t < 1.0 {
            t
        } else if t < 2.0 {
            1.0 - 2.0 * (t - 1.0)
        } else {
            -1.0 + 0.5 * (t - 2.0)
        }
    };
    let mut s = sys(1, move |t, _y: &DVector<f64>, dy: &mut DVector<f64>| {
        dy[0] = u(t)
    });
    let t_out = linspace(0.0, 3.0, 61); // includes 1.0 and 2.0
    let (out, r) = ndf(&mut s, &[0.0], &t_out, &[1.0, 2.0], &NdfOptions::default());
    r.unwrap();
    assert_eq!(out.len(), 61);
    for (t, y) in &out {
        assert!(
            (y[0] - exact(*t)).abs() < 1e-10,
            "t = {t}: {} vs {}",
            y[0],
            exact(*t)
        );
    }
    // A step ended on each breakpoint (f called at the float just below it) and the next piece
    // started there (f called at the float just above it); no call straddles the switch.
    for b in [1.0f64, 2.0] {
        assert!(s.calls.contains(&next_down(b)), "no step ended at {b}");
        assert!(s.calls.contains(&next_up(b)), "no restart at {b}");
        assert!(!s.calls.contains(&b));
    }
    // Without the breakpoints the same problem is not solved exactly.
    let mut s = sys(1, move |t, _y: &DVector<f64>, dy: &mut DVector<f64>| {
        dy[0] = u(t)
    });
    let (out, r) = ndf(&mut s, &[0.0], &t_out, &[], &NdfOptions::default());
    r.unwrap();
    assert!(out.iter().any(|(t, y)| (y[0] - exact(*t)).abs() > 1e-8));
}

fn oscillator(c: f64, k: f64) -> impl FnMut(f64, &DVector<f64>, &mut DVector<f64>) {
    move |_t, y, dy| {
        dy[0] = y[1];
        dy[1] = -k * y[0] - c * y[1];
    }
}

#[test]
fn damped_oscillator_energy_decreases_monotonically() {
    let (c, k) = (2.0, 100.0);
    let mut s = sys(2, oscillator(c, k));
    let t_out = linspace(0.0, 5.0, 101);
    let o = NdfOptions {
        rtol: 1e-6,
        atol: 1e-9,
        ..Default::default()
    };
    let (out, r) = ndf(&mut s, &[1.0, 0.0], &t_out, &[], &o);
    r.unwrap();
    let e: Vec<f64> = out
        .iter()
        .map(|(_, y)| 0.5 * y[1] * y[1] + 0.5 * k * y[0] * y[0])
        .collect();
    for i in 1..e.len() {
        assert!(
            e[i] < e[i - 1],
            "energy rose at t = {}: {} -> {}",
            out[i].0,
            e[i - 1],
            e[i]
        );
    }
    assert!(e[e.len() - 1] < 1e-3 * e[0]);
}

#[test]
fn undamped_oscillator_energy_drift_is_small() {
    let mut s = sys(2, oscillator(0.0, 1.0));
    let t_out = linspace(0.0, 20.0 * std::f64::consts::PI, 401);
    let o = NdfOptions {
        rtol: 1e-8,
        atol: 1e-10,
        ..Default::default()
    };
    let (out, r) = ndf(&mut s, &[1.0, 0.0], &t_out, &[], &o);
    r.unwrap();
    let drift = out
        .iter()
        .map(|(_, y)| (0.5 * (y[0] * y[0] + y[1] * y[1]) - 0.5).abs())
        .fold(0.0, f64::max)
        / 0.5;
    println!("relative energy drift over 10 periods: {drift:e}");
    assert!(drift < 3e-5, "relative energy drift {drift:e}");
    let (t, y) = out.last().unwrap();
    assert!((y[0] - t.cos()).abs() < 1e-5);
}

#[test]
fn analytic_and_finite_difference_jacobians_agree_and_jacobian_is_reused() {
    let t_out = linspace(0.0, 40.0, 41);
    let o = NdfOptions {
        rtol: 1e-5,
        atol_components: Some(vec![1e-8, 1e-12, 1e-8]),
        ..Default::default()
    };
    let mut sa = FnSys {
        n: 3,
        f: robertson,
        jac: Some(robertson_jac),
        calls: Vec::new(),
    };
    let (out_a, ra) = ndf(&mut sa, &[1.0, 0.0, 0.0], &t_out, &[], &o);
    let mut sf = sys(3, robertson);
    let (out_f, rf) = ndf(&mut sf, &[1.0, 0.0, 0.0], &t_out, &[], &o);
    let (sta, stf) = (ra.unwrap(), rf.unwrap());
    println!("Robertson, analytic Jacobian: {sta:?}\nRobertson, finite differences: {stf:?}");
    for ((_, ya), (_, yf)) in out_a.iter().zip(&out_f) {
        for i in 0..3 {
            let scale = ya[i]
                .abs()
                .max(o.atol_components.as_ref().unwrap()[i] / o.rtol);
            assert!(
                (ya[i] - yf[i]).abs() < 10.0 * o.rtol * scale,
                "{} vs {}",
                ya[i],
                yf[i]
            );
        }
    }
    for st in [&sta, &stf] {
        assert!(
            st.jacobian_evals * 4 < st.steps,
            "Jacobian not reused: {st:?}"
        );
        assert!(st.lu_decompositions < st.steps, "LU not reused: {st:?}");
    }
    // Finite differences cost dim + 1 evaluations per Jacobian.
    assert!(stf.rhs_evals >= sta.rhs_evals + 3 * stf.jacobian_evals);
}

#[test]
fn plain_bdf_and_low_max_order_also_converge() {
    for o in [
        NdfOptions {
            bdf: true,
            rtol: 1e-6,
            atol: 1e-9,
            ..Default::default()
        },
        NdfOptions {
            max_order: 2,
            rtol: 1e-6,
            atol: 1e-9,
            ..Default::default()
        },
        NdfOptions {
            max_order: 1,
            rtol: 1e-5,
            atol: 1e-8,
            ..Default::default()
        },
        NdfOptions {
            initial_step: Some(1e-3),
            max_step: 0.05,
            rtol: 1e-6,
            atol: 1e-9,
            ..Default::default()
        },
    ] {
        let mut s = sys(1, forced_rhs);
        let t_out = linspace(0.0, 5.0, 51);
        let (out, r) = ndf(&mut s, &[1.0], &t_out, &[], &o);
        let st = r.unwrap();
        let err = out
            .iter()
            .map(|(t, y)| (y[0] - forced_exact(*t, 1.0)).abs())
            .fold(0.0, f64::max);
        assert!(err < 100.0 * o.rtol, "{o:?}: error {err:e}");
        if o.max_step < 1.0 {
            assert!(st.steps >= 100, "max_step not honoured: {} steps", st.steps);
        }
    }
}

#[test]
fn ndf_coefficients_give_the_efficiency_gains_of_shampine_reichelt() {
    // Table 2.1 of the paper: at equal error the NDFs of orders 1..5 allow steps 26, 26, 26, 12
    // and 0 % longer than the BDFs: (C_k^BDF / C_k^NDF)^{1/(k+1)}.
    let (inv_ga_ndf, c_ndf) = ndf::coefficients(false);
    let (inv_ga_bdf, c_bdf) = ndf::coefficients(true);
    let gain = [1.26, 1.26, 1.26, 1.12, 1.0];
    let gamma = [1.0, 1.5, 11.0 / 6.0, 25.0 / 12.0, 137.0 / 60.0];
    for k in 0..5 {
        assert!((c_bdf[k] - 1.0 / (k + 2) as f64).abs() < 1e-15);
        assert!((inv_ga_bdf[k] * gamma[k] - 1.0).abs() < 1e-15);
        let g = (c_bdf[k] / c_ndf[k]).powf(1.0 / (k + 2) as f64);
        assert!((g - gain[k]).abs() < 0.005, "order {}: gain {g}", k + 1);
        assert!(inv_ga_ndf[k] <= inv_ga_bdf[k]);
    }
}

/// `∇^j p(t_n)`, `j = 1..5`, at step `h` for a cubic `p`, in a 1 × 7 difference table.
fn cubic_differences(tn: f64, h: f64) -> DMatrix<f64> {
    let p = |t: f64| 1.0 + 2.0 * t - 3.0 * t * t + 0.5 * t * t * t;
    let mut d = DMatrix::zeros(1, 7);
    for j in 1..=5usize {
        let mut binom = 1.0;
        let mut s = 0.0;
        for i in 0..=j {
            s += if i % 2 == 0 { binom } else { -binom } * p(tn - i as f64 * h);
            binom = binom * (j - i) as f64 / (i + 1) as f64;
        }
        d[(0, j - 1)] = s;
    }
    d
}

#[test]
fn step_change_rescaling_and_interpolation_are_exact_for_polynomials() {
    let p = |t: f64| 1.0 + 2.0 * t - 3.0 * t * t + 0.5 * t * t * t;
    for k in 3..=5 {
        for r in [0.3, 0.5, 1.0, 1.7, 4.0] {
            let mut d = cubic_differences(1.0, 0.1);
            ndf::rescale(&mut d, k, r);
            let expected = cubic_differences(1.0, 0.1 * r);
            for j in 0..k {
                // roundoff grows like r^k
                assert!(
                    (d[(0, j)] - expected[(0, j)]).abs() < 1e-13 * r.max(1.0).powi(k as i32),
                    "k = {k}, r = {r}, j = {j}: {} vs {}",
                    d[(0, j)],
                    expected[(0, j)]
                );
            }
        }
        let d = cubic_differences(1.0, 0.1);
        let ynew = DVector::from_element(1, p(1.0));
        let mut out = DVector::zeros(1);
        for s in [-1.0, -0.75, -0.3, 0.0] {
            let t = 1.0 + 0.1 * s;
            ndf::interpolate(t, 1.0, 0.1, &ynew, &d, k, &mut out);
            assert!((out[0] - p(t)).abs() < 1e-13, "k = {k}, s = {s}");
        }
    }
}
