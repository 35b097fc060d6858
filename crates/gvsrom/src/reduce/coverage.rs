//! The training inputs as a whole: whether a combination of inputs lies near those a model was
//! trained on, not only each input inside its own range.
//!
//! A per-input range is a box. A model trained with all six tensions moved together
//! (`--sweep 'tendons.*.tension=-10:0'`) saw one line of that box, yet every corner passes a box
//! check: at `--tension=-10,0,0,0,0,0` its POD answered 44.8 % of the length off the full model
//! without a sign. So a model also checks the distance from the inputs `x` to the nearest training
//! input, each input measured in units of its training range's width:
//!
//! `d(x) = min_i ‖(x − x_i) ⊘ w‖`, accepted when `d(x) ≤ max(C s, m √k)`,
//!
//! where `s` is how far apart the training inputs themselves lie (the largest distance from a
//! training input to its nearest neighbour, over [`PROBES`] evenly spaced ones), `C` =
//! [`COVERAGE_FACTOR`], `m` the per-input margin ([`INPUT_MARGIN`]) and `k` the number of inputs
//! that vary (`m √k`: a point `m` beyond the range in every input). On 20 000 random draws of six
//! inputs a new draw lies at most 1.2 `s` from the data, a corner of the box (2 % beyond it) at most
//! 2 `s`; a point off a fine 1-D sweep lies many `s` away.
//!
//! A coarse sweep has a large `s`: six samples of six tensions moved together lie 0.49 apart, and
//! the box's corner is only 1.9 `s` from one. So where *all* training inputs lie in a subspace of
//! lower dimension than the inputs that vary (the scatter's eigenvalues vanish, to rounding, in
//! some directions: a sweep moving inputs together, a grid over fewer inputs), the distance off
//! that subspace must also be at most `m √k`, however coarse the sampling along it.
//!
//! Along a trajectory (a dynamic dataset) consecutive inputs are nearly equal: a ramp sampled at
//! 100 Hz would make `s` the sample spacing and refuse every other draw of the same babbling. So a
//! training input's neighbours within [`WINDOW_FRACTION`] of its trajectory's rows on either side
//! are left out of its own distance: `s` measures how well the data cover the inputs, not how
//! finely a signal was sampled. Independent samples (static datasets, whose sweeps and grids are
//! ordered too) are compared with every other sample.

use super::anchors::GuessInput;
use crate::build::reduced::JointInputs;
use crate::build::reduced::INPUT_MARGIN;
use crate::build::Built;
use crate::reduced_model::ReducedModel;

/// `C`: a combination of inputs is accepted within this many training spacings `s` of the nearest
/// training input.
pub const COVERAGE_FACTOR: f64 = 3.0;
/// An eigenvalue of the training inputs' scatter at most this fraction of the largest is a
/// direction they do not vary in (exact to rounding: sweeps move inputs together exactly).
pub const SPAN_TOLERANCE: f64 = 1e-10;
/// How many training inputs `s` is measured at.
pub const PROBES: usize = 256;
/// The neighbours left out of a training input's own distance: this fraction of its dataset's rows
/// on either side (at least one).
pub const WINDOW_FRACTION: f64 = 1.0 / 40.0;

/// The training inputs, scaled per input by its range, with their spacing `s`.
#[derive(Debug, Clone)]
pub struct InputCloud {
    /// Names of the inputs, in column order.
    names: Vec<String>,
    /// The columns that vary in training (a held input is checked by its range alone).
    dims: Vec<usize>,
    /// Per column in `dims`, the training minimum and width.
    lo: Vec<f64>,
    width: Vec<f64>,
    /// Distinct scaled training inputs, `n × dims.len()` row-major.
    points: Vec<f64>,
    /// The mean scaled training input.
    centre: Vec<f64>,
    /// Unit directions (rows of `dims.len()`) in which no training input differs from the mean,
    /// to rounding: the training inputs lie in a subspace of lower dimension (a sweep moving
    /// several inputs together). Empty when they span every direction.
    flat: Vec<f64>,
    /// `s`: the largest distance of a probed training input to its nearest neighbour.
    spacing: f64,
}

impl InputCloud {
    /// The cloud of the training inputs `rows` (`n × names.len()`, row-major, in the datasets'
    /// order), which came from datasets of `segments` rows each, `true` for a trajectory (one
    /// trajectory if they do not add up to `n`). `None` with fewer than two rows, no input that
    /// varies, or a value not finite.
    pub fn new(names: Vec<String>, rows: &[f64], segments: &[(usize, bool)]) -> Option<InputCloud> {
        let k = names.len();
        let n = rows.len().checked_div(k)?;
        if n < 2 || rows.len() != n * k || rows.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let (mut dims, mut lo, mut width) = (vec![], vec![], vec![]);
        for c in 0..k {
            let (min, max) = (0..n)
                .map(|i| rows[i * k + c])
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                    (a.min(v), b.max(v))
                });
            if max > min {
                dims.push(c);
                lo.push(min);
                width.push(max - min);
            }
        }
        if dims.is_empty() {
            return None;
        }
        let d = dims.len();
        let mut scaled = Vec::with_capacity(n * d);
        for i in 0..n {
            for (j, &c) in dims.iter().enumerate() {
                scaled.push((rows[i * k + c] - lo[j]) / width[j]);
            }
        }
        let segments = match segments.iter().map(|s| s.0).sum::<usize>() == n {
            true => segments.to_vec(),
            false => vec![(n, true)],
        };
        let spacing = spacing(&scaled, d, &segments, true)
            .or_else(|| spacing(&scaled, d, &segments, false))
            .unwrap_or(0.0);
        // the subspace the training inputs lie in: the scatter's directions without extent
        let mut centre = vec![0.0; d];
        for p in scaled.chunks_exact(d) {
            for (m, v) in centre.iter_mut().zip(p) {
                *m += v / n as f64;
            }
        }
        let mut scatter = nalgebra::DMatrix::<f64>::zeros(d, d);
        for p in scaled.chunks_exact(d) {
            for r in 0..d {
                for c in 0..d {
                    scatter[(r, c)] += (p[r] - centre[r]) * (p[c] - centre[c]);
                }
            }
        }
        let eig = scatter.symmetric_eigen();
        // distinct rows only: a held signal repeats its inputs at every sample
        let mut order: Vec<usize> = (0..n).collect();
        let row = |i: usize| &scaled[i * d..(i + 1) * d];
        order.sort_by(|&a, &b| {
            (row(a).iter().zip(row(b)))
                .map(|(x, y)| x.total_cmp(y))
                .find(|o| o.is_ne())
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        order.dedup_by(|a, b| row(*a) == row(*b));
        let points = order.iter().flat_map(|&i| row(i).to_vec()).collect();
        let largest = eig.eigenvalues.iter().fold(0.0f64, |m, v| m.max(*v));
        let flat = (0..d)
            .filter(|&i| eig.eigenvalues[i] <= SPAN_TOLERANCE * largest)
            .flat_map(|i| {
                eig.eigenvectors
                    .column(i)
                    .iter()
                    .copied()
                    .collect::<Vec<_>>()
            })
            .collect();
        Some(InputCloud {
            names,
            dims,
            lo,
            width,
            points,
            centre,
            flat,
            spacing,
        })
    }

    /// `s`, in units of each input's range.
    pub fn spacing(&self) -> f64 {
        self.spacing
    }

    /// `m √k`: the per-input margin over the `k` inputs that vary, the distance of a point
    /// [`INPUT_MARGIN`] beyond the range in every input.
    pub fn margin(&self) -> f64 {
        INPUT_MARGIN * (self.dims.len() as f64).sqrt()
    }

    /// The largest accepted distance to the nearest training input, `max(C s, m √k)`.
    pub fn radius(&self) -> f64 {
        (COVERAGE_FACTOR * self.spacing).max(self.margin())
    }

    /// `d(x)`: the distance to the nearest training input of the inputs whose column `c` holds
    /// `value(c)`, in units of each input's range; `stop_below` ends the search at the first
    /// training input closer than it (the distance returned is then that one's). Allocates nothing.
    fn distance_by(&self, value: impl Fn(usize) -> f64, stop_below: f64) -> f64 {
        let d = self.dims.len();
        let stop = stop_below * stop_below;
        let mut best = f64::INFINITY;
        for p in self.points.chunks_exact(d) {
            let mut s = 0.0;
            for (j, &c) in self.dims.iter().enumerate() {
                let e = (value(c) - self.lo[j]) / self.width[j] - p[j];
                s += e * e;
            }
            if s < best {
                best = s;
                if best < stop {
                    break;
                }
            }
        }
        best.sqrt()
    }

    /// `None` if the inputs `x` lie within [`Self::radius`] of a training input (or are not
    /// finite: the range check reports those); else `(d(x), a sentence saying how far)`.
    pub fn outside(&self, x: &[f64]) -> Option<(f64, String)> {
        if x.len() != self.names.len() {
            return None;
        }
        self.outside_by(|c| x[c])
    }

    /// [`Self::outside`] of the inputs whose column `c` holds `value(c)`; allocates only to say
    /// how far, when they lie outside.
    fn outside_by(&self, value: impl Fn(usize) -> f64) -> Option<(f64, String)> {
        if (0..self.names.len()).any(|c| !value(c).is_finite()) {
            return None;
        }
        let values = || {
            (self.names.iter().enumerate())
                .map(|(c, name)| format!("{name} = {}", value(c)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let radius = self.radius();
        if self.distance_by(&value, radius) > radius {
            let d = self.distance_by(&value, 0.0);
            return Some((
                d,
                format!(
                    "the inputs together ({}) lie {d:.3} from the nearest training input, where {} and at most {radius:.3} is accepted (distances in units of each input's training range): each input is inside its range, but training never came near this combination",
                    values(),
                    match self.spacing > 0.0 {
                        true => format!("training inputs lie within {:.3} of one another", self.spacing),
                        false => "training repeats a few combinations".to_string(),
                    }
                ),
            ));
        }
        let (off, rank) = self.off_span(&value)?;
        Some((
            off,
            format!(
                "the inputs together ({}) lie {off:.3} off the {} that all training inputs lie on, where at most {:.3} is accepted (distances in units of each input's training range): each input is inside its range, but training never varied them this way",
                values(),
                match rank {
                    0 => "point".to_string(),
                    1 => "line".to_string(),
                    2 => "plane".to_string(),
                    r => format!("{r}-dimensional subspace"),
                },
                self.margin()
            ),
        ))
    }

    /// The distance of the inputs off the subspace all training inputs lie in, when they lie in
    /// one of lower dimension than the inputs that vary (a sweep moving inputs together, a grid of
    /// fewer inputs) and the distance exceeds the margin: `(distance, its dimension)`.
    fn off_span(&self, value: impl Fn(usize) -> f64) -> Option<(f64, usize)> {
        if self.flat.is_empty() {
            return None;
        }
        let d = self.dims.len();
        let off = (self.flat.chunks_exact(d))
            .map(|v| {
                (self.dims.iter().enumerate())
                    .map(|(j, &c)| {
                        v[j] * ((value(c) - self.lo[j]) / self.width[j] - self.centre[j])
                    })
                    .sum::<f64>()
                    .powi(2)
            })
            .sum::<f64>()
            .sqrt();
        (off > self.margin()).then_some((off, d - self.flat.len() / d))
    }
}

/// `s` of the scaled rows `x` (`n × d`): over [`PROBES`] evenly spaced rows, the largest distance
/// to the nearest other row — with `windowed`, leaving out the rows of the same trajectory within
/// [`WINDOW_FRACTION`] of it. `None` if no probe has a row to compare with.
fn spacing(x: &[f64], d: usize, segments: &[(usize, bool)], windowed: bool) -> Option<f64> {
    let n = x.len() / d;
    let probes = n.min(PROBES);
    let segment_of = |i: usize| {
        let mut start = 0;
        for &(len, trajectory) in segments {
            if i < start + len {
                return (start, len, trajectory);
            }
            start += len;
        }
        (0, n, true)
    };
    let mut largest: Option<f64> = None;
    for m in 0..probes {
        let i = m * n / probes;
        let (start, len, trajectory) = segment_of(i);
        let w = match windowed && trajectory {
            true => ((len as f64 * WINDOW_FRACTION) as usize).max(1),
            false => 0,
        };
        let (near_lo, near_hi) = (i.saturating_sub(w).max(start), (i + w).min(start + len - 1));
        let xi = &x[i * d..(i + 1) * d];
        let nearest = (0..n)
            .filter(|&j| j != i && !(near_lo..=near_hi).contains(&j))
            .map(|j| {
                (x[j * d..(j + 1) * d].iter().zip(xi))
                    .map(|(a, b)| (a - b) * (a - b))
                    .sum::<f64>()
            })
            .min_by(f64::total_cmp);
        if let Some(s) = nearest {
            largest = Some(largest.unwrap_or(0.0).max(s.sqrt()));
        }
    }
    largest
}

/// A model's training inputs bound to a scenario: the [`InputCloud`] of its anchors, with each
/// input's value in a run (a tension from the run, anything else from the scenario).
#[derive(Debug, Clone)]
pub struct Coverage {
    cloud: InputCloud,
    inputs: Vec<GuessInput>,
}

impl InputCloud {
    /// The cloud of `model`'s training inputs, its anchors' inputs named by
    /// [`ModelMeta::anchor_parameters`](crate::reduced_model::ModelMeta::anchor_parameters);
    /// `None` for a model without anchors or whose inputs do not vary.
    pub fn of_model(model: &ReducedModel) -> Option<InputCloud> {
        let anchors = model.anchors.as_ref()?;
        let meta = &model.meta;
        // a model from before `trajectory` was recorded: each dataset read as a trajectory
        let segments: Vec<(usize, bool)> = std::iter::once(&meta.dataset)
            .chain(&meta.more_datasets)
            .map(|d| (d.rows, d.trajectory.unwrap_or(true)))
            .collect();
        InputCloud::new(meta.anchor_parameters.clone(), &anchors.inputs, &segments)
    }

    /// The names of the inputs, in column order.
    pub fn names(&self) -> &[String] {
        &self.names
    }
}

impl Coverage {
    /// The coverage of `model`'s training inputs in the scenario of `built` (its TOML `table`, for
    /// inputs other than tensions); `None` for a model without anchors (the range check alone
    /// applies), with inputs that do not vary, or whose inputs the scenario does not define.
    pub fn of(
        built: &Built,
        table: Option<&toml::Table>,
        model: &ReducedModel,
    ) -> Option<Coverage> {
        let inputs = GuessInput::of_model(built, table, model)?;
        let cloud = InputCloud::of_model(model)?;
        Some(Coverage { cloud, inputs })
    }
}

impl JointInputs for Coverage {
    /// Allocates nothing for inputs near the training inputs (Python's `statics(u)` checks every
    /// call's).
    fn outside(&self, u: &[f64]) -> Option<(f64, String)> {
        let value = |c: usize| match self.inputs[c] {
            GuessInput::Tension(k) => u.get(k).copied().unwrap_or(f64::NAN),
            GuessInput::Value(v) => v,
        };
        self.cloud.outside_by(value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(k: usize) -> Vec<String> {
        (0..k).map(|i| format!("tendons.{i}.tension")).collect()
    }

    /// A deterministic stand-in for uniform draws in `[0, 1)` (a Weyl sequence per column).
    fn draws(n: usize, k: usize) -> Vec<f64> {
        let alpha = [0.754877, 0.569840, 0.438459, 0.347987, 0.281918, 0.232549];
        (0..n)
            .flat_map(|i| (0..k).map(move |c| ((i as f64 + 0.5) * alpha[c] * 7.31).fract()))
            .collect()
    }

    /// `n` samples of six tensions moved together from -10 to 0 N.
    fn line(n: usize) -> InputCloud {
        let rows: Vec<f64> = (0..n)
            .flat_map(|i| std::iter::repeat_n(-10.0 + 10.0 * i as f64 / (n - 1) as f64, 6))
            .collect();
        InputCloud::new(names(6), &rows, &[(n, false)]).unwrap()
    }

    #[test]
    fn a_sweep_of_all_inputs_together_covers_its_line_and_not_the_corners_of_its_box() {
        for n in [3, 6, 11, 101, 1001] {
            let cloud = line(n);
            // on the line between two samples, and beyond its ends within the per-input margin
            // (1.5 % of the range on every input)
            for x in [-4.95, -10.15, 0.15] {
                assert!(cloud.outside(&[x; 6]).is_none(), "n = {n}: {x}");
            }
            // a corner of the box: each tension alone in its range, however coarse the sweep
            let (_, why) = cloud
                .outside(&[-10.0, 0.0, 0.0, 0.0, 0.0, 0.0])
                .unwrap_or_else(|| panic!("n = {n}: the corner was accepted"));
            assert!(why.contains("tendons.0.tension = -10"), "{why}");
            assert!(why.contains("never"), "{why}");
            // half-way to that corner, and a tenth of the range off the line
            for x in [
                [-5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                [-6.0, -4.0, -5.0, -5.0, -5.0, -5.0],
            ] {
                assert!(cloud.outside(&x).is_some(), "n = {n}: {x:?}");
            }
        }
        // 101 samples: the corner is sqrt(30/36) ≈ 0.913 of the range off the line, farther than
        // 3 spacings (sqrt(6) × 0.01 each) from every sample
        let (d, why) = line(101)
            .outside(&[-10.0, 0.0, 0.0, 0.0, 0.0, 0.0])
            .unwrap();
        assert!((d - (30.0f64 / 36.0).sqrt()).abs() < 0.01, "{d}");
        assert!(why.contains("never came near this combination"), "{why}");
        // 6 samples lie 0.49 apart: the corner is within 3 spacings of one, but 0.913 off the
        // line they all lie on, where only the margin sqrt(6) × 0.02 ≈ 0.049 is accepted
        let (d, why) = line(6).outside(&[-10.0, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
        assert!((d - (30.0f64 / 36.0).sqrt()).abs() < 1e-9, "{d}");
        assert!(
            why.contains("lie 0.913 off the line that all training inputs lie on, where at most 0.049 is accepted"),
            "{why}"
        );
    }

    #[test]
    fn a_straight_line_between_two_arms_of_an_l_is_off_the_data() {
        // a trajectory along an L: (-10, 0) to (0, 0) to (0, -10), sampled finely
        let mut rows = vec![];
        for i in 0..=200 {
            rows.extend([-10.0 + 10.0 * i as f64 / 200.0, 0.0]);
        }
        for i in 1..=200 {
            rows.extend([0.0, -10.0 * i as f64 / 200.0]);
        }
        let n = rows.len() / 2;
        let cloud = InputCloud::new(names(2), &rows, &[(n, true)]).unwrap();
        for x in [[-10.0, 0.0], [0.0, -7.5], [-5.0, 0.1]] {
            assert!(cloud.outside(&x).is_none(), "{x:?}");
        }
        // the corner of the box and the midpoint of the chord are off the L
        assert!(cloud.outside(&[-10.0, -10.0]).is_some());
        assert!(cloud.outside(&[-5.0, -5.0]).is_some());
    }

    #[test]
    fn new_draws_from_a_filled_box_are_inside_its_corners_included() {
        // 20 000 independent draws of six inputs, as a random static dataset; then 2000 more
        let (n, k) = (20_000, 6);
        let rows = draws(n + 2000, k);
        let cloud = InputCloud::new(names(k), &rows[..n * k], &[(n, false)]).unwrap();
        assert!(
            cloud.spacing() > 0.05 && cloud.spacing() < 0.5,
            "{}",
            cloud.spacing()
        );
        for x in rows[n * k..].chunks_exact(k) {
            assert!(cloud.outside(x).is_none(), "{x:?} {:?}", cloud.outside(x));
        }
        // every corner of the box, and 2 % beyond it (the range check's margin)
        for corner in 0..(1 << k) {
            let x: Vec<f64> = (0..k)
                .map(|c| if corner >> c & 1 == 1 { 1.02 } else { -0.02 })
                .collect();
            assert!(cloud.outside(&x).is_none(), "corner {x:?}");
        }
    }

    #[test]
    fn a_finely_sampled_trajectory_is_judged_by_how_it_covers_its_inputs_not_by_its_sample_rate() {
        // a held signal of 400 random six-tension holds with 0.2 s ramps between them, sampled at
        // 100 Hz (0.5 s holds): consecutive samples nearly equal
        let (holds, k) = (400, 6);
        let levels = draws(holds + 1, k);
        let mut rows = vec![];
        for h in 0..holds {
            let (a, b) = (
                &levels[h * k..(h + 1) * k],
                &levels[(h + 1) * k..(h + 2) * k],
            );
            for step in 0..50 {
                let w = (step as f64 / 20.0).min(1.0);
                rows.extend(a.iter().zip(b).map(|(a, b)| a + (b - a) * w));
            }
        }
        let n = rows.len() / k;
        let cloud = InputCloud::new(names(k), &rows, &[(n, true)]).unwrap();
        // another draw of the same babbling (a test signal) is accepted
        let other = draws(3000, k);
        let far = other[2000 * k..]
            .chunks_exact(k)
            .filter(|x| cloud.outside(x).is_some())
            .count();
        assert_eq!(far, 0, "spacing {}", cloud.spacing());
        // without the window, the spacing is the ramp's sample spacing and most draws would be
        // refused
        let fine = spacing(&cloud.points_for_test(&rows), k, &[(n, true)], false).unwrap();
        assert!(fine < cloud.spacing() / 3.0, "{fine} {}", cloud.spacing());
    }

    #[test]
    fn inputs_that_do_not_vary_or_too_few_rows_give_no_cloud() {
        assert!(InputCloud::new(names(2), &[1.0, 2.0], &[(1, false)]).is_none());
        assert!(InputCloud::new(names(1), &[3.0; 10], &[(10, false)]).is_none());
        assert!(InputCloud::new(names(1), &[0.0, f64::NAN, 1.0], &[(3, false)]).is_none());
        // a held input is left to the range check: the other is judged alone
        let rows: Vec<f64> = (0..11).flat_map(|i| [i as f64, 5.0]).collect();
        let cloud = InputCloud::new(names(2), &rows, &[(11, false)]).unwrap();
        assert!(cloud.outside(&[4.5, 5.0]).is_none());
    }

    impl InputCloud {
        /// `rows` scaled as the cloud scales its inputs (all columns vary in these tests).
        fn points_for_test(&self, rows: &[f64]) -> Vec<f64> {
            let k = self.names.len();
            rows.chunks_exact(k)
                .flat_map(|r| (0..k).map(move |c| (r[c] - self.lo[c]) / self.width[c]))
                .collect()
        }
    }
}
