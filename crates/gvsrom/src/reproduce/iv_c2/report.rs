//! IV-C2's report: Fig. 9's table, the Table III row, the λ and models tables, the paper's
//! conclusions as measured and the differences from the paper (the figures: `figures`).

use super::super::paper;
use super::super::report::{ratio, Cell, Finding, Table};
use super::super::sim_test::SimRun;
use super::{Dof, Variant, LAMBDA, LAMBDA_OTHER};
use crate::compare::Trajectory;

/// Fig. 9's numbers: per r, both ROMs' mean tip error and wall time, and the HOM's time.
pub(super) fn fig9_table(dofs: &[Dof], hom: &SimRun) -> Table {
    let reached = |x: &SimRun| Cell::sig(x.t_reached, 3);
    Table {
        id: "fig9".into(),
        title: format!(
            "Fig. 9: mean tip error and wall time of the {} s test per DOF",
            hom.t_reached
        ),
        columns: [
            "DOF r",
            "AE-ROM tip error [% L]",
            "AE-ROM time [s]",
            "AE-ROM reached [s]",
            "POD-ROM tip error [% L]",
            "POD-ROM time [s]",
            "POD-ROM reached [s]",
            "energy-norm POD-ROM tip error [% L]",
            "energy-norm POD-ROM time [s]",
            "HOM time [s]",
        ]
        .map(String::from)
        .to_vec(),
        rows: dofs
            .iter()
            .map(|d| {
                vec![
                    Cell::int(d.r),
                    Cell::sig(d.ae_run.tip_mean(), 3),
                    Cell::sig(d.ae_run.wall_time_s, 3),
                    reached(&d.ae_run),
                    Cell::sig(d.pod_run.tip_mean(), 3),
                    Cell::sig(d.pod_run.wall_time_s, 3),
                    reached(&d.pod_run),
                    Cell::sig(d.pod_energy_run.tip_mean(), 3),
                    Cell::sig(d.pod_energy_run.wall_time_s, 3),
                    Cell::sig(hom.wall_time_s, 3),
                ]
            })
            .collect(),
        note: format!("Tip error: mean over the samples of ‖p_ROM − p_HOM‖ / L, L = 0.6 m. Time: wall time of the integration (smallest of the repetitions), one thread. Reached: the time of the last sample; a run that stopped before {} s (the decoder left its training region, or the integrator failed: reasons in results.json) is partial, and its error and time are up to where it stopped. Energy-norm POD (not in the paper): the POD of the same data in the norm the autoencoders are trained in (`gvsrom pod --norm energy`), its runs complete unless the error is marked.", hom.t_reached),
    }
}

/// Table III's same-DOF row (r = 7 in the full run) beside the paper's.
pub(super) fn table_iii(d: &Dof, hom: &SimRun) -> Table {
    let p = &paper::TABLE_III_IV_C2;
    let (p_pod, p_ae) = (
        p.pod_error.unwrap_or(f64::NAN),
        p.ae_error.unwrap_or(f64::NAN),
    );
    let (ae, pod) = (&d.ae_run, &d.pod_run);
    let num = |q: &str, ours: f64, paper: f64| {
        vec![
            Cell::text(q),
            Cell::sig(ours, 3),
            Cell::sig(paper, 3),
            ratio(ours, paper),
        ]
    };
    let rows = vec![
        vec![
            Cell::text("ROM DOF (POD modes = AE latent size)"),
            Cell::int(d.r),
            Cell::int(p.ae_dof),
            ratio(d.r as f64, p.ae_dof as f64),
        ],
        num("POD-ROM tip error [% L]", pod.tip_mean(), p_pod),
        num("POD-ROM time [s]", pod.wall_time_s, p.pod_time_s),
        num("AE-ROM tip error [% L]", ae.tip_mean(), p_ae),
        num("AE-ROM time [s]", ae.wall_time_s, p.ae_time_s),
        num("HOM time [s]", hom.wall_time_s, p.hom_time_s),
        num(
            "AE-ROM error reduction against POD [%]",
            (1.0 - ae.tip_mean() / pod.tip_mean()) * 100.0,
            (1.0 - p_ae / p_pod) * 100.0,
        ),
        num(
            "AE-ROM time / POD-ROM time",
            ae.wall_time_s / pod.wall_time_s,
            p.ae_time_s / p.pod_time_s,
        ),
        num(
            "AE-ROM speed-up over the HOM",
            hom.wall_time_s / ae.wall_time_s,
            p.hom_time_s / p.ae_time_s,
        ),
        num(
            "POD-ROM speed-up over the HOM",
            hom.wall_time_s / pod.wall_time_s,
            p.hom_time_s / p.pod_time_s,
        ),
    ];
    Table {
        id: "table-iii".into(),
        title: format!("Table III row (same DOF study: {} DOF)", d.r),
        columns: ["quantity", "ours", "paper", "ratio"].map(String::from).to_vec(),
        rows,
        note: format!(
            "Tip errors: mean over the {} s test of ‖p_ROM − p_HOM‖ / L. Times: wall time of the whole simulation. Ours: gvsrom, one thread, this machine; the paper's: MATLAB on an i9-13900HX. A run that stopped early has its error and time up to where it stopped: AE-{}: {}; POD-{}: {}. Other seeds of AE-{}: the λ table.",
            hom.t_reached,
            d.r,
            ae.status(),
            d.r,
            pod.status(),
            d.r
        ),
    }
}

/// The weight decay: the AE-ROMs at the inset's r with λ = 1e-6 (used) and 1e-4 (the paper's),
/// one row per training seed.
pub(super) fn lambda_table(r: usize, lambdas: &[Variant]) -> Table {
    Table {
        id: "lambda".into(),
        title: format!("Weight decay λ and training seed of the AE-ROM with r = {r}"),
        columns: [
            "λ",
            "seed",
            "RMSE over the dataset",
            "validation RMSE",
            "reached [s]",
            "tip error [% L]",
            "time [s]",
            "run",
        ]
        .map(String::from)
        .to_vec(),
        rows: lambdas
            .iter()
            .map(|v| {
                vec![
                    Cell::sig(v.lambda, 1),
                    Cell::int(v.seed as usize),
                    Cell::sig(v.model.rmse_full, 3),
                    Cell::sig(v.model.val_rmse.unwrap_or(f64::NAN), 3),
                    Cell::sig(v.run.t_reached, 3),
                    Cell::sig(v.run.tip_mean(), 3),
                    Cell::sig(v.run.wall_time_s, 3),
                    Cell::text(v.run.status()),
                ]
            })
            .collect(),
        note: "Same data, architecture and epochs; λ and the seed (initial weights, train/validation split, mini-batch order) differ. The first row is the AE-ROM of Fig. 9 and Table III. RMSE: of the reconstruction D(E(x)) − x over every entry of every snapshot. A run that leaves the training region (q_r beyond the range of the training encodings by more than half its width) is stopped there: the decoder would extrapolate. Tip error and time up to where the run stopped.".into(),
    }
}

/// The models per r: the autoencoders' reconstruction and epochs, POD's captured energy.
pub(super) fn models_table(dofs: &[Dof]) -> Table {
    Table {
        id: "models".into(),
        title: "The reduced models".into(),
        columns: [
            "r",
            "AE RMSE over the dataset",
            "AE validation RMSE",
            "AE epochs",
            "POD RMSE over the dataset",
            "POD captured energy",
            "AE start offset max |ξ − ξ*|",
        ]
        .map(String::from)
        .to_vec(),
        rows: dofs
            .iter()
            .map(|d| {
                let (a, p) = (&d.ae.value, &d.pod.value);
                vec![
                    Cell::int(d.r),
                    Cell::sig(a.rmse_full, 3),
                    Cell::sig(a.val_rmse.unwrap_or(f64::NAN), 3),
                    Cell::int(a.epochs_run.unwrap_or(0)),
                    Cell::sig(p.rmse_full, 3),
                    Cell::sig(p.captured_energy.unwrap_or(f64::NAN), 4),
                    Cell::sig(d.ae_run.start_offset, 3),
                ]
            })
            .collect(),
        note: "RMSE of x̂ − x over every entry of every snapshot, x = ξ − ξ* at the 14 points, six components (curvatures in 1/m, the others unitless). Epochs: Adam epochs plus L-BFGS iterations. Start offset: how far the AE's rest point (where its simulation starts) decodes from the straight rod the HOM starts from, largest |ξ − ξ*| over the points [1/m for curvatures].".into(),
    }
}

/// The paper's conclusions on Fig. 9, as measured.
pub(super) fn findings(dofs: &[Dof], hom: &SimRun, inset: &Dof) -> Vec<Finding> {
    let list = |f: &dyn Fn(&Dof) -> bool| {
        let v: Vec<String> = dofs
            .iter()
            .filter(|d| f(d))
            .map(|d| d.r.to_string())
            .collect();
        (
            v.len(),
            if v.is_empty() {
                "none".into()
            } else {
                v.join(", ")
            },
        )
    };
    let n = dofs.len();
    // the AE is better at r when it completes and POD either stops or errs more
    let ae_better = |d: &Dof| {
        d.ae_run.complete && (!d.pod_run.complete || d.ae_run.tip_mean() < d.pod_run.tip_mean())
    };
    let (k_acc, acc_at) = list(&ae_better);
    let reduction = dofs
        .iter()
        .filter(|d| d.ae_run.complete && d.pod_run.complete)
        .map(|d| 1.0 - d.ae_run.tip_mean() / d.pod_run.tip_mean())
        .fold(f64::NAN, f64::max);
    // speed is known where a run that went through the test took less time than the other run
    // took (to its end, or to where it stopped): see `faster`
    let (k_ae_fast, ae_fast_at) = list(&|d| faster(&d.ae_run, hom) == Some(true));
    let (k_ae_slow, ae_slow_at) = list(&|d| faster(&d.ae_run, hom) == Some(false));
    let (k_pod_fast, pod_fast_at) = list(&|d| faster(&d.pod_run, hom) == Some(true));
    let (k_pod_slow, pod_slow_at) = list(&|d| faster(&d.pod_run, hom) == Some(false));
    let (k_pod_ae, pod_ae_at) = list(&|d| faster(&d.pod_run, &d.ae_run) == Some(true));
    let (k_ae_pod, ae_pod_at) = list(&|d| faster(&d.pod_run, &d.ae_run) == Some(false));
    let partial: Vec<String> = dofs
        .iter()
        .flat_map(|d| [&d.ae_run, &d.pod_run])
        .filter(|x| !x.complete)
        .map(|x| format!("{} at t = {:.2} s", x.label, x.t_reached))
        .collect();
    let partial = if partial.is_empty() {
        "every ROM run completed".to_string()
    } else {
        format!("stopped early: {}", partial.join(", "))
    };
    let (ae, pod) = (&inset.ae_run, &inset.pod_run);
    let p = &paper::TABLE_III_IV_C2;
    vec![
        Finding {
            claim: "the AE-ROM is more accurate than the POD-ROM at every tested DOF".into(),
            holds: k_acc == n,
            evidence: format!(
                "at {k_acc} of {n} DOFs (r = {acc_at}); the largest error reduction of a complete AE-ROM against a complete POD-ROM {} % (paper: up to {} %); {partial}",
                Cell::sig(reduction * 100.0, 3).render(),
                Cell::sig(paper::IV_C2_MAX_ERROR_REDUCTION * 100.0, 2).render(),
            ),
        },
        Finding {
            claim: format!("at {} DOF the AE-ROM is more accurate than the POD-ROM", inset.r),
            holds: ae_better(inset),
            evidence: format!(
                "mean tip error {} % L (AE-{}, {}) against {} % L (POD-{}, {}); paper {} % against {} %",
                Cell::sig(ae.tip_mean(), 3).render(),
                inset.r,
                ae.status(),
                Cell::sig(pod.tip_mean(), 3).render(),
                inset.r,
                pod.status(),
                Cell::sig(p.ae_error.unwrap_or(f64::NAN), 2).render(),
                Cell::sig(p.pod_error.unwrap_or(f64::NAN), 2).render(),
            ),
        },
        Finding {
            claim: "both ROMs are faster than the HOM (at every tested DOF)".into(),
            holds: k_ae_slow == 0 && k_pod_slow == 0 && k_ae_fast > 0 && k_pod_fast > 0,
            evidence: format!(
                "HOM {} s; the AE-ROM is faster at {k_ae_fast} of {n} DOFs (r = {ae_fast_at}) and slower at {k_ae_slow} (r = {ae_slow_at}), the POD-ROM faster at {k_pod_fast} (r = {pod_fast_at}) and slower at {k_pod_slow} (r = {pod_slow_at}); unknown at the others (stopped early, in less time than the HOM's whole run); at r = {}: AE {} s, POD {} s (paper at r = {}: {} s and {} s against {} s)",
                Cell::sig(hom.wall_time_s, 3).render(),
                inset.r,
                Cell::sig(ae.wall_time_s, 3).render(),
                Cell::sig(pod.wall_time_s, 3).render(),
                p.ae_dof,
                Cell::sig(p.ae_time_s, 3).render(),
                Cell::sig(p.pod_time_s, 3).render(),
                Cell::sig(p.hom_time_s, 4).render(),
            ),
        },
        Finding {
            claim: "at equal DOF the POD-ROM is faster than the AE-ROM".into(),
            holds: k_ae_pod == 0 && k_pod_ae > 0,
            evidence: format!(
                "POD faster at {k_pod_ae} of {n} DOFs (r = {pod_ae_at}), AE faster at {k_ae_pod} (r = {ae_pod_at}), unknown at the others (a run stopped early in less time than the other took); at r = {}: AE / POD time {} (paper at r = {}: {})",
                inset.r,
                Cell::sig(ae.wall_time_s / pod.wall_time_s, 3).render(),
                p.ae_dof,
                Cell::sig(p.ae_time_s / p.pod_time_s, 3).render()
            ),
        },
    ]
}

/// Whether run `a` is faster than run `b` over the whole test: `Some(true)` when `a` went through
/// it in less time than `b` took (to its end or to where it stopped), `Some(false)` the other way
/// round, `None` when neither did.
fn faster(a: &SimRun, b: &SimRun) -> Option<bool> {
    if a.complete && a.wall_time_s < b.wall_time_s {
        Some(true)
    } else if b.complete && b.wall_time_s <= a.wall_time_s {
        Some(false)
    } else {
        None
    }
}

/// The largest distance the tip travels within `window` seconds over the trajectory [m].
pub(super) fn tip_travel(t: &Trajectory, window: f64) -> f64 {
    let p = |k: usize| [t.tip[3 * k], t.tip[3 * k + 1], t.tip[3 * k + 2]];
    let mut best = 0.0f64;
    for i in 0..t.samples() {
        for j in i + 1..t.samples() {
            if t.t[j] - t.t[i] > window + 1e-9 {
                break;
            }
            let (a, b) = (p(i), p(j));
            best = best.max((0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f64>().sqrt());
        }
    }
    best
}

/// "ndf (r = 3, 4), sdirk (r = 1, 2)": the integrators `simulate` chose for a kind of ROM.
fn methods(dofs: &[Dof], run: impl Fn(&Dof) -> &SimRun) -> String {
    let mut by: Vec<(String, Vec<String>)> = vec![];
    for d in dofs {
        let m = &run(d).method;
        match by.iter_mut().find(|(name, _)| name == m) {
            Some((_, rs)) => rs.push(d.r.to_string()),
            None => by.push((m.clone(), vec![d.r.to_string()])),
        }
    }
    by.iter()
        .map(|(m, rs)| format!("{m} (r = {})", rs.join(", ")))
        .collect::<Vec<_>>()
        .join(", ")
}

/// What the notes are made of besides the runs.
pub(super) struct Context<'a> {
    pub(super) data_s: f64,
    /// The HOM tip's largest travel within one second [m].
    pub(super) swing: f64,
    /// Rod length [m].
    pub(super) length: f64,
    pub(super) lambdas: &'a [Variant],
}

/// Where and why the results differ from the paper's.
pub(super) fn notes(dofs: &[Dof], hom: &SimRun, inset: &Dof, c: &Context) -> Vec<String> {
    let (ae, pod) = (&inset.ae_run, &inset.pod_run);
    let p = &paper::TABLE_III_IV_C2;
    let start = dofs
        .iter()
        .map(|d| d.ae_run.start_offset)
        .fold(0.0, f64::max);
    let slowest_ae = dofs
        .iter()
        .map(|d| &d.ae_run)
        .max_by(|a, b| a.wall_time_s.total_cmp(&b.wall_time_s));
    vec![
        format!(
            "Accuracy: at r = {} the AE-ROM's mean tip error is {} % L and POD's {} % L; the paper's (r = {}) are {} % and {} %. An earlier measurement gave 5.7 % (AE-7) against 15.5 % (POD-7) without gravity and with 720 s of babbling; here gravity acts (as in IV-C1) and the data are {} s of babbling. The arm swings under the steps (the HOM's tip travels up to {} m within a second of the test, the arm being {} m long), so the snapshots vary with the velocity as well as the position, and r coordinates hold less of them than in statics (POD's captured energy, models table).",
            inset.r,
            Cell::sig(ae.tip_mean(), 3).render(),
            Cell::sig(pod.tip_mean(), 3).render(),
            p.ae_dof,
            Cell::sig(p.ae_error.unwrap_or(f64::NAN), 2).render(),
            Cell::sig(p.pod_error.unwrap_or(f64::NAN), 2).render(),
            c.data_s,
            Cell::sig(c.swing, 2).render(),
            Cell::sig(c.length, 2).render(),
        ),
        format!(
            "Speed: our HOM runs the {} s test in {} s (the paper's MATLAB HOM: {} s): {} DOF, 14 computational points, integrated by `{}` in second-order form with its analytic iteration matrix. A ROM saves little on such a model. The POD-ROMs use the same structured Jacobian with fewer unknowns: {}. The AE-ROMs use the same second-order form, with the decoder's Hessian term in the tangent stiffness and the mass matrix renewed at every attempt (a decoder's M(q) varies fast): {}. Each of their residuals costs about as much as the HOM's (the 14 points' kinematics, plus the decoder and its first and second derivatives), and they take about as many steps (the same dynamics at the same tolerance), so they can be slower than the HOM{}. Compare the ratios between models, not the absolute times; on this shared 2-core machine times of runs under a second vary by tens of per cent.",
            hom.t_reached,
            Cell::sig(hom.wall_time_s, 3).render(),
            Cell::sig(p.hom_time_s, 4).render(),
            hom.dof,
            hom.method,
            methods(dofs, |d| &d.pod_run),
            methods(dofs, |d| &d.ae_run),
            slowest_ae.map_or(String::new(), |a| format!(
                " (the slowest AE-ROM here, {}, took {} s)",
                a.label,
                Cell::sig(a.wall_time_s, 3).render()
            )),
        ),
        format!(
            "Weight decay: the AE-ROMs use the paper's λ = {LAMBDA:e}, against the squared error of a whole snapshot as eq. (15) writes it; the λ table compares it with {LAMBDA_OTHER:e} at r = {}: {}. The training seed matters as much: an AE-ROM may run through or leave its region depending on it, and Fig. 9 shows one seed per r.",
            inset.r,
            [LAMBDA, LAMBDA_OTHER]
                .iter()
                .map(|&l| lambda_summary(l, c.lambdas))
                .collect::<Vec<_>>()
                .join("; "),
        ),
        format!(
            "Start: every model starts at rest, as the data do (the dataset starts from the straight rod, and the arm first falls under gravity): the HOM's start is no problem. An AE-ROM starts from its rest point, the encoding of the straight rod (trained in as 1 % zero-strain rows), which decodes to the straight rod only up to the autoencoder's error: up to max |ξ − ξ*| = {} here (models table), so the AE-ROMs do not start quite where the HOM does, and that offset counts in their mean error.",
            Cell::sig(start, 3).render()
        ),
        "A ROM run that stops early (its trajectory leaves the range of the training encodings, where the decoder extrapolates, or the integrator fails) is not an error of the case: it is recorded as partial, with its reason, and its error and time are those up to where it stopped (Fig. 9 table, \"reached\"); the accuracy findings count it as not more accurate; the speed findings as slower when it had taken longer than the other run by the time it stopped, else as unknown.".into(),
    ]
}

/// "λ = …: k of n runs complete (mean tip error …)" over the seeds of the λ table.
fn lambda_summary(lambda: f64, lambdas: &[Variant]) -> String {
    let of: Vec<&SimRun> = lambdas
        .iter()
        .filter(|v| v.lambda == lambda)
        .map(|v| &v.run)
        .collect();
    let complete: Vec<String> = of
        .iter()
        .filter(|x| x.complete)
        .map(|x| Cell::sig(x.tip_mean(), 3).render() + " % L")
        .collect();
    let stopped: Vec<String> = of
        .iter()
        .filter(|x| !x.complete)
        .map(|x| format!("{} s", Cell::sig(x.t_reached, 3).render()))
        .collect();
    format!(
        "λ = {lambda:e}: {} of {} runs complete{}{}",
        complete.len(),
        of.len(),
        if complete.is_empty() {
            String::new()
        } else {
            format!(" (mean tip error {})", complete.join(", "))
        },
        if stopped.is_empty() {
            String::new()
        } else {
            format!(", the others stopped at t = {}", stopped.join(", "))
        }
    )
}
