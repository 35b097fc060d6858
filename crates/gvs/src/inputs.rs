//! Time-varying inputs (gvs-spec §9.2, paper IV-C2): actuation sequences held piecewise constant or
//! interpolated linearly, the paper's random step actuation and **actuator babbling**, ramps, and
//! their discontinuity times (where a stiff integrator must stop and restart).
//!
//! Random signals use a self-contained SplitMix64 generator, so a seed gives the same signal on every
//! platform and every version of the dependencies.

use crate::error::{check_range, ModelError};
use serde::{Deserialize, Serialize};

/// How a signal behaves between its knots.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Interpolation {
    /// Zero-order hold: the value of the last knot at or before t.
    #[default]
    Hold,
    /// Linear between knots (ramps).
    Linear,
}

/// A vector signal `u(t)` defined by knots `(t_k, u_k)`; constant before the first and after the last.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Signal {
    pub times: Vec<f64>,
    pub values: Vec<Vec<f64>>,
    pub interpolation: Interpolation,
}

impl Signal {
    /// A constant signal.
    pub fn constant(u: &[f64]) -> Self {
        Signal {
            times: vec![0.0],
            values: vec![u.to_vec()],
            interpolation: Interpolation::Hold,
        }
    }

    /// A linear ramp from `u0` at `t0` to `u1` at `t1`, held afterwards.
    pub fn ramp(u0: &[f64], u1: &[f64], t0: f64, t1: f64) -> Self {
        Signal {
            times: vec![t0, t1],
            values: vec![u0.to_vec(), u1.to_vec()],
            interpolation: Interpolation::Linear,
        }
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.values.first().map_or(0, |v| v.len())
    }

    /// Checks knots ascending and finite, values finite, every knot with `channels` entries.
    pub fn validate(&self, field: &str, channels: usize) -> Result<(), ModelError> {
        if self.times.is_empty() || self.times.len() != self.values.len() {
            return Err(ModelError::invalid(
                field,
                format!(
                    "{} times for {} value rows (need the same number, at least one)",
                    self.times.len(),
                    self.values.len()
                ),
            ));
        }
        for (k, (t, v)) in self.times.iter().zip(&self.values).enumerate() {
            check_range(
                &format!("{field}.times[{k}]"),
                *t,
                None,
                None,
                "a finite time in s",
            )?;
            if k > 0 && *t < self.times[k - 1] {
                return Err(ModelError::value(
                    format!("{field}.times[{k}]"),
                    *t,
                    format!("times in ascending order (>= {})", self.times[k - 1]),
                ));
            }
            if let Some(why) = self.repeated_time(k) {
                return Err(ModelError::invalid(format!("{field}.times[{k}]"), why));
            }
            if v.len() != channels {
                return Err(ModelError::invalid(
                    format!("{field}.values[{k}]"),
                    format!("{} entries, the scenario has {channels} actuators", v.len()),
                ));
            }
            for (j, x) in v.iter().enumerate() {
                check_range(
                    &format!("{field}.values[{k}][{j}]"),
                    *x,
                    None,
                    None,
                    "a finite number",
                )?;
            }
        }
        Ok(())
    }

    /// Why knot `k` may not repeat the time of the knots before it, if it may not: held piecewise
    /// constant, two knots at one time would lose the first (only the last value at a time is
    /// applied); interpolated linearly, two knots at one time are a step (the value before and the
    /// value after) and a third would never be applied.
    pub fn repeated_time(&self, k: usize) -> Option<String> {
        let t = self.times[k];
        let same = |j: usize| k >= j && self.times[k - j] == t;
        match self.interpolation {
            Interpolation::Hold if same(1) => Some(format!(
                "t = {t} repeats the time of the knot before: held piecewise constant, only the last value at one time is applied and the one before would be lost; give each time once"
            )),
            Interpolation::Linear if same(1) && same(2) => Some(format!(
                "t = {t} is the third knot at one time: interpolated linearly, two knots at one time make a step (the value before and the value after) and a third would never be applied; give a time at most twice"
            )),
            _ => None,
        }
    }

    /// `u(t)` into `out`.
    pub fn eval(&self, t: f64, out: &mut [f64]) {
        let k = self.times.partition_point(|&tk| tk <= t);
        if k == 0 {
            out.copy_from_slice(&self.values[0]);
            return;
        }
        let a = k - 1;
        if self.interpolation == Interpolation::Hold || k == self.times.len() {
            out.copy_from_slice(&self.values[a]);
            return;
        }
        let (t0, t1) = (self.times[a], self.times[k]);
        let s = if t1 > t0 { (t - t0) / (t1 - t0) } else { 1.0 };
        for (j, o) in out.iter_mut().enumerate() {
            *o = self.values[a][j] + s * (self.values[k][j] - self.values[a][j]);
        }
    }

    /// Times in `(t0, t1)` where `u` or its derivative jumps: the knots where a held value
    /// changes, or where the slope of a linear one does by more than 1e-6 of itself (the value is
    /// held before the first knot and after the last). A knot that changes nothing (rows of one
    /// value sampled at 1 kHz) is none: the integrator restarts at every breakpoint, which costs
    /// far more than a step.
    pub fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        let n = self.times.len();
        let slope = |a: usize, b: usize, j: usize| -> f64 {
            match (a < n, b < n) {
                (true, true) if self.times[b] > self.times[a] => {
                    (self.values[b][j] - self.values[a][j]) / (self.times[b] - self.times[a])
                }
                _ => 0.0, // held before the first knot and after the last
            }
        };
        let jumps = |k: usize| -> bool {
            let channels = self.values[k].len();
            match self.interpolation {
                Interpolation::Hold => k > 0 && self.values[k] != self.values[k - 1],
                Interpolation::Linear => {
                    // a step (a time given twice) jumps where its two values differ
                    let step = k > 0 && self.times[k] == self.times[k - 1];
                    let before = if k == 0 { n } else { k - 1 };
                    // slopes of rows on one line differ in their rounding only (1e-13 relative
                    // for `linspace`): a corner of 1e-6 of the slope is none the integrator sees
                    // (an infinite slope, of knots 1e-308 apart, is a corner)
                    let corner = |a: f64, b: f64| {
                        let (d, tol) = ((a - b).abs(), 1e-6 * a.abs().max(b.abs()));
                        d > tol || !d.is_finite()
                    };
                    (step && self.values[k] != self.values[k - 1])
                        || (0..channels).any(|j| corner(slope(before, k, j), slope(k, k + 1, j)))
                }
            }
        };
        let mut b: Vec<f64> = (0..n)
            .filter(|&k| self.times[k] > t0 && self.times[k] < t1 && jumps(k))
            .map(|k| self.times[k])
            .collect();
        b.dedup();
        b
    }
}

/// An actuation `u(t)` as the integrators use it: a [`Signal`] of knots, or any function of time (a
/// callable of a front-end). The integrators evaluate it at the times they need, in any order (a
/// rejected step goes back in time), and step onto its breakpoints.
pub trait Actuation {
    /// `u(t)` into `out` (one entry per actuator).
    fn eval(&self, t: f64, out: &mut [f64]);
    /// Times in `(t0, t1)` where `u` or its derivative jumps (the integrator restarts there).
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64>;
    /// Checks it for `channels` actuators before a run.
    fn validate(&self, field: &str, channels: usize) -> Result<(), ModelError>;
    /// Called by the dynamics driver with the state `(q, q̇)` of every output sample at `t`, in
    /// order, before `u(t)` is read for that sample: a sampled-data controller
    /// ([`crate::feedback::SampledFeedback`]) renews its held value here. `Err(reason)` stops
    /// the run with that reason. Default: nothing (an input that is a function of time alone).
    fn observe(&self, _t: f64, _q: &[f64], _qd: &[f64]) -> Result<(), String> {
        Ok(())
    }
    /// Per channel, whether it is the displacement `δ_k(t)` \[m\] of a tendon's motor rather than
    /// a tension ([`crate::solve::dynamics::drive`]); empty (the default) when every channel is a
    /// tension. [`crate::solve::dynamics::drive::DisplacementDriven`] marks channels so.
    fn displacement_driven(&self) -> &[bool] {
        &[]
    }
}

impl Actuation for Signal {
    fn eval(&self, t: f64, out: &mut [f64]) {
        Signal::eval(self, t, out)
    }

    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        Signal::breakpoints(self, t0, t1)
    }

    fn validate(&self, field: &str, channels: usize) -> Result<(), ModelError> {
        Signal::validate(self, field, channels)
    }
}

/// SplitMix64: a tiny, well-mixed, seedable generator (Steele, Lea & Flood 2014).
#[derive(Debug, Clone)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in `[a, b)`.
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.uniform()
    }
}

/// The paper's random step actuation (Section IV-C2 test): every `period` seconds all actuators draw
/// new values uniformly in `[lo, hi]`, held until the next draw.
pub fn random_steps(
    channels: usize,
    lo: f64,
    hi: f64,
    period: f64,
    duration: f64,
    seed: u64,
) -> Signal {
    let mut rng = SplitMix64::new(seed);
    let mut times = vec![];
    let mut values = vec![];
    let mut t = 0.0;
    while t < duration {
        times.push(t);
        values.push((0..channels).map(|_| rng.range(lo, hi)).collect());
        t += period;
    }
    Signal {
        times,
        values,
        interpolation: Interpolation::Hold,
    }
}

/// **Actuator babbling** (paper IV-C2): each actuator independently draws a value uniformly in
/// `[lo, hi]` and holds it for a time drawn uniformly in `[hold_min, hold_max]`, over `[0, duration]`.
/// The result merges all actuators' switching times into one piecewise-constant signal.
pub fn babble(
    channels: usize,
    lo: f64,
    hi: f64,
    hold_min: f64,
    hold_max: f64,
    duration: f64,
    seed: u64,
) -> Signal {
    let mut rng = SplitMix64::new(seed);
    // per-actuator switching sequences
    let mut per: Vec<Vec<(f64, f64)>> = vec![];
    for _ in 0..channels {
        let mut seq = vec![];
        let mut t = 0.0;
        while t < duration {
            seq.push((t, rng.range(lo, hi)));
            t += rng.range(hold_min, hold_max);
        }
        per.push(seq);
    }
    let mut times: Vec<f64> = per.iter().flat_map(|s| s.iter().map(|p| p.0)).collect();
    times.sort_by(|a, b| a.partial_cmp(b).unwrap());
    times.dedup();
    let values = times
        .iter()
        .map(|&t| {
            per.iter()
                .map(|s| {
                    let k = s.partition_point(|p| p.0 <= t);
                    s[k - 1].1
                })
                .collect()
        })
        .collect();
    Signal {
        times,
        values,
        interpolation: Interpolation::Hold,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hold_and_linear_evaluation() {
        let s = Signal {
            times: vec![0.0, 1.0, 2.0],
            values: vec![vec![0.0], vec![2.0], vec![-1.0]],
            interpolation: Interpolation::Hold,
        };
        let mut u = [0.0];
        s.eval(0.5, &mut u);
        assert_eq!(u[0], 0.0);
        s.eval(1.0, &mut u);
        assert_eq!(u[0], 2.0);
        s.eval(5.0, &mut u);
        assert_eq!(u[0], -1.0);
        let r = Signal::ramp(&[0.0], &[4.0], 1.0, 3.0);
        r.eval(2.5, &mut u);
        assert!((u[0] - 3.0).abs() < 1e-15);
        r.eval(0.0, &mut u);
        assert_eq!(u[0], 0.0);
        assert_eq!(s.breakpoints(0.0, 10.0), vec![1.0, 2.0]);
    }

    #[test]
    fn knots_that_change_nothing_are_no_breakpoints() {
        // 1 kHz rows of one held value, then a switch at 0.5 s: one breakpoint
        let times: Vec<f64> = (0..1000).map(|k| k as f64 * 1e-3).collect();
        let values: Vec<Vec<f64>> = (times.iter())
            .map(|&t| vec![if t < 0.5 { -1.0 } else { -2.0 }, 3.0])
            .collect();
        let held = Signal {
            times: times.clone(),
            values: values.clone(),
            interpolation: Interpolation::Hold,
        };
        assert_eq!(held.breakpoints(0.0, 1.0), vec![0.5]);
        // interpolated, the same rows ramp from -1 to -2 over [0.499, 0.5]: its two corners
        let linear = Signal {
            interpolation: Interpolation::Linear,
            ..held
        };
        assert_eq!(linear.breakpoints(0.0, 1.0), vec![times[499], times[500]]);
        // a ramp sampled at its knots: corners at its start and end only, where the value is
        // held before the first knot and after the last
        let ramp = Signal {
            times: vec![0.5, 1.0, 1.5, 2.0],
            values: vec![vec![0.0], vec![1.0], vec![2.0], vec![3.0]],
            interpolation: Interpolation::Linear,
        };
        assert_eq!(ramp.breakpoints(0.0, 3.0), vec![0.5, 2.0]);
        // rows of a ramp as NumPy's linspace rounds them: on one line to the rounding
        let n = 1000;
        let line = Signal {
            times: (0..n).map(|k| k as f64 / (n - 1) as f64).collect(),
            values: (0..n)
                .map(|k| vec![-3.0 * k as f64 / (n - 1) as f64])
                .collect(),
            interpolation: Interpolation::Linear,
        };
        assert_eq!(line.breakpoints(-1.0, 2.0), vec![0.0, 1.0]);
    }

    #[test]
    fn a_repeated_time_is_a_step_when_linear_and_refused_when_held() {
        let step = Signal {
            times: vec![0.0, 1.0, 1.0, 2.0],
            values: vec![vec![0.0], vec![0.0], vec![4.0], vec![4.0]],
            interpolation: Interpolation::Linear,
        };
        step.validate("input", 1).unwrap();
        let mut u = [0.0];
        step.eval(1.0 - 1e-12, &mut u);
        assert!(u[0].abs() < 1e-15, "before the step: {}", u[0]);
        step.eval(1.0, &mut u);
        assert_eq!(u[0], 4.0);
        assert_eq!(step.breakpoints(0.0, 2.0), vec![1.0]);
        let mut triple = step.clone();
        triple.times.insert(2, 1.0);
        triple.values.insert(2, vec![2.0]);
        let e = triple.validate("input", 1).unwrap_err().to_string();
        assert!(
            e.contains("input.times[3]") && e.contains("third knot"),
            "{e}"
        );
        let held = Signal {
            interpolation: Interpolation::Hold,
            ..step
        };
        let e = held.validate("input", 1).unwrap_err().to_string();
        assert!(
            e.contains("input.times[2]") && e.contains("t = 1 repeats"),
            "{e}"
        );
    }

    #[test]
    fn babbling_is_seeded_in_range_with_hold_times_in_range() {
        let a = babble(6, -15.0, 0.0, 0.5, 1.0, 20.0, 7);
        let b = babble(6, -15.0, 0.0, 0.5, 1.0, 20.0, 7);
        let c = babble(6, -15.0, 0.0, 0.5, 1.0, 20.0, 8);
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert!(a.values.iter().flatten().all(|v| (-15.0..0.0).contains(v)));
        // per actuator, each value is held between 0.5 and 1 s (except the last, cut by the duration)
        for j in 0..6 {
            let mut switches = vec![0.0];
            for k in 1..a.times.len() {
                if a.values[k][j] != a.values[k - 1][j] {
                    switches.push(a.times[k]);
                }
            }
            for w in switches.windows(2) {
                let hold = w[1] - w[0];
                assert!((0.5..=1.0).contains(&hold), "actuator {j}: hold {hold}");
            }
        }
    }

    #[test]
    fn random_steps_switch_every_period() {
        let s = random_steps(6, -15.0, 0.0, 1.0, 10.0, 3);
        assert_eq!(s.times.len(), 10);
        assert_eq!(s.breakpoints(0.0, 10.0).len(), 9);
        s.validate("input", 6).unwrap();
        assert!(s
            .validate("input", 5)
            .unwrap_err()
            .to_string()
            .contains("input.values[0]"));
    }
}
