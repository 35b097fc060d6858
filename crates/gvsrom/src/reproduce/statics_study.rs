//! What the static studies IV-A and IV-B measure alike: the AE-r ROM against POD-r, the fewest POD
//! modes below 1 % strain error (POD-k, Table III's same-accuracy row) and the HOM, at the case's
//! test inputs, and the four conclusions of the paper drawn from them.

use super::evaluation::Evaluation;
use super::paper;
use super::report::{ratio, Cell, Digits, Finding, Table};

/// The fewest POD modes among `modes` (ascending) whose largest strain error over the test inputs
/// is below `limit` %.
pub fn fewest_pod_below(ev: &Evaluation, modes: &[usize], limit: f64) -> Option<usize> {
    modes
        .iter()
        .copied()
        .find(|k| ev.stats(&format!("POD-{k}"), |s| s.strain_error_percent).1 < limit)
}

/// Means and maxima over the test inputs of an evaluation with models `HOM`, `AE-r`, `POD-r` and
/// POD with 1 … `max_modes` modes (NaN where a model failed an input).
#[derive(Debug, Clone, PartialEq)]
pub struct StaticsComparison {
    pub r: usize,
    /// AE-r's mean and largest strain error [%].
    pub ae_err: f64,
    pub ae_max: f64,
    /// POD-r's mean strain error [%].
    pub pod_r_err: f64,
    /// The fewest POD modes below 1 % at every test input, if any up to `max_modes`.
    pub pod_k: Option<usize>,
    pub max_modes: usize,
    /// Mean times per equilibrium \[s\]: HOM, AE-r, POD-k (NaN without a POD-k).
    pub hom_t: f64,
    pub ae_t: f64,
    pub pod_k_t: f64,
}

impl StaticsComparison {
    /// The comparison of `AE-r` in `ev`, whose POD models have the modes `modes` (ascending).
    pub fn of(ev: &Evaluation, r: usize, modes: &[usize]) -> StaticsComparison {
        let ae = format!("AE-{r}");
        let (ae_err, ae_max) = ev.stats(&ae, |s| s.strain_error_percent);
        let pod_k = fewest_pod_below(ev, modes, 1.0);
        let time = |label: &str| ev.stats(label, |s| s.time_s).0;
        StaticsComparison {
            r,
            ae_err,
            ae_max,
            pod_r_err: ev.stats(&format!("POD-{r}"), |s| s.strain_error_percent).0,
            pod_k,
            max_modes: modes.last().copied().unwrap_or(0),
            hom_t: time("HOM"),
            ae_t: time(&ae),
            pod_k_t: pod_k.map_or(f64::NAN, |k| time(&format!("POD-{k}"))),
        }
    }

    /// Table III (same-accuracy rows): our POD-k and AE-r DOF and times beside the paper's `p`.
    pub fn table_iii(&self, p: &paper::TableIiiRow) -> Table {
        let (pod_k, pod_t, ae_dof, ae_t, hom_t) =
            (self.pod_k, self.pod_k_t, self.r, self.ae_t, self.hom_t);
        let row = |q: &str, ours: Cell, paper: Cell, r: Cell| vec![Cell::text(q), ours, paper, r];
        let pod_dof = pod_k.map_or(Cell::num(f64::NAN, Digits::Fixed(0)), Cell::int);
        let rows = vec![
            row(
                "POD DOF for < 1 % strain error",
                pod_dof,
                Cell::int(p.pod_dof),
                ratio(pod_k.map_or(f64::NAN, |k| k as f64), p.pod_dof as f64),
            ),
            row(
                "POD-ROM time [s]",
                Cell::sig(pod_t, 3),
                Cell::sig(p.pod_time_s, 3),
                ratio(pod_t, p.pod_time_s),
            ),
            row(
                "AE DOF",
                Cell::int(ae_dof),
                Cell::int(p.ae_dof),
                ratio(ae_dof as f64, p.ae_dof as f64),
            ),
            row(
                "AE-ROM time [s]",
                Cell::sig(ae_t, 3),
                Cell::sig(p.ae_time_s, 3),
                ratio(ae_t, p.ae_time_s),
            ),
            row(
                "HOM time [s]",
                Cell::sig(hom_t, 3),
                Cell::sig(p.hom_time_s, 3),
                ratio(hom_t, p.hom_time_s),
            ),
            row(
                "AE-ROM speed-up over POD-ROM",
                Cell::sig(pod_t / ae_t, 3),
                Cell::sig(p.pod_time_s / p.ae_time_s, 3),
                ratio(pod_t / ae_t, p.pod_time_s / p.ae_time_s),
            ),
            row(
                "AE-ROM speed-up over the HOM",
                Cell::sig(hom_t / ae_t, 3),
                Cell::sig(p.hom_time_s / p.ae_time_s, 3),
                ratio(hom_t / ae_t, p.hom_time_s / p.ae_time_s),
            ),
            row(
                "POD-ROM speed-up over the HOM",
                Cell::sig(hom_t / pod_t, 3),
                Cell::sig(p.hom_time_s / p.pod_time_s, 3),
                ratio(hom_t / pod_t, p.hom_time_s / p.pod_time_s),
            ),
        ];
        Table {
            id: "table-iii".into(),
            title: "Table III row (same accuracy level, < 1 % strain error)".into(),
            columns: ["quantity", "ours", "paper", "ratio"].map(String::from).to_vec(),
            rows,
            note: "Times: mean wall time of one static equilibrium over the test inputs. Ours: gvsrom, one thread, this machine; the paper's: MATLAB fsolve on an i9-13900HX.".into(),
        }
    }

    /// `POD-k`'s label, if there is one.
    pub fn pod_k_label(&self) -> Option<String> {
        self.pod_k.map(|k| format!("POD-{k}"))
    }

    /// The paper's four conclusions of a static study, as measured here: AE-r more accurate than
    /// POD-r; AE-r below 1 % at every test input (`inputs` names them, e.g. "the two test loads");
    /// at equal accuracy (< 1 %) AE-r faster than POD-k (which needs AE-r below 1 % too); both
    /// ROMs faster than the HOM.
    pub fn findings(&self, inputs: &str) -> Vec<Finding> {
        let r = self.r;
        let sig = |v: f64| Cell::sig(v, 3).render();
        let ms = |t: f64| sig(t * 1e3);
        let pod_k = self.pod_k_label();
        let below_one = self.ae_max < 1.0;
        vec![
            Finding {
                claim: format!(
                    "the AE-ROM is more accurate than the POD-ROM of equal DOF (r = {r})"
                ),
                holds: self.ae_err < self.pod_r_err,
                evidence: format!(
                    "mean strain error {} % (AE-{r}) against {} % (POD-{r})",
                    sig(self.ae_err),
                    sig(self.pod_r_err)
                ),
            },
            Finding {
                claim: format!("the AE-ROM reaches < 1 % strain error with {r} DOF"),
                holds: below_one,
                evidence: format!("largest strain error over {inputs} {} %", sig(self.ae_max)),
            },
            Finding {
                claim: "at equal accuracy (< 1 %) the AE-ROM is faster than the POD-ROM".into(),
                holds: below_one && self.ae_t < self.pod_k_t,
                evidence: match &pod_k {
                    Some(l) => format!(
                        "AE-{r} {} ms against {l} {} ms per equilibrium{}",
                        ms(self.ae_t),
                        ms(self.pod_k_t),
                        if below_one {
                            ""
                        } else {
                            "; but the AE-ROM itself is not below 1 %"
                        }
                    ),
                    None => format!(
                        "no POD model up to {} modes reaches < 1 % at {inputs}",
                        self.max_modes
                    ),
                },
            },
            Finding {
                claim: "both ROMs are faster than the HOM".into(),
                holds: self.ae_t < self.hom_t && self.pod_k_t < self.hom_t,
                evidence: format!(
                    "HOM {} ms, AE-{r} {} ms, {} {} ms",
                    ms(self.hom_t),
                    ms(self.ae_t),
                    pod_k.as_deref().unwrap_or("POD-k"),
                    ms(self.pod_k_t)
                ),
            },
        ]
    }
}
