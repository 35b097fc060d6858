//! The snapshots a model is made from: the solved rows of one dataset, or of several datasets of
//! one scenario, taken in the order given (`gvsrom pod A B …`, `gvsrom train A B …`). Several
//! datasets let a model learn from data made by separate commands — a babbling trajectory with
//! static equilibria of the same input range mixed in (the paper's IV-C2 question of more
//! informative data at one budget), or runs of other seeds — without an ad-hoc merge that would
//! lose where each row came from.
//!
//! Datasets are combined only when the model they make means the same thing for every row: the
//! same points and active components, the same sampled inputs (names and order), and the same
//! physics (the scenario's TOML, everything but the inputs and the keys that are not physics,
//! compared as `--model` compares a scenario with a model's: `validity::first_physics_difference`).

use super::validity::{first_physics_difference, input_ranges};
use super::{dataset_scenario, invalid, snapshot_rows};
use crate::build::reduced::INPUT_MARGIN;
use crate::build::Built;
use crate::dataset::Dataset;
use crate::error::ScenarioError;
use crate::provenance::Provenance;
use crate::reduced_model::{same_abscissae, DatasetRef, InputRange};
use crate::scenario::Scenario;
use std::path::{Path, PathBuf};

/// The usable snapshots of one or more datasets of one scenario.
pub(super) struct Sources {
    /// Each dataset, as given, with its directory.
    pub sets: Vec<(PathBuf, Dataset)>,
    /// The HOM of the (first) dataset's scenario.
    pub built: Built,
    /// The usable rows of every dataset in order, row-major.
    pub x: Vec<f64>,
    /// Usable rows of each dataset, in order.
    pub rows_of: Vec<usize>,
    /// Values per snapshot.
    pub features: usize,
}

/// The option that names the datasets on every front-end.
const FIELD: &str = "DATASET";

impl Sources {
    /// Loads `paths` (at least one) and checks that they can make one model.
    pub fn load<P: AsRef<Path>>(paths: &[P]) -> Result<Sources, anyhow::Error> {
        let Some(first) = paths.first() else {
            return Err(invalid(FIELD, "no dataset given: at least one is needed").into());
        };
        let first = first.as_ref();
        // with several datasets, a dataset's own error names it
        let several = paths.len() > 1;
        let named = |p: &Path, e: ScenarioError| if several { e.naming(p) } else { e };
        let ds = Dataset::load(first)?;
        let built = dataset_scenario(&ds).map_err(|e| named(first, e))?;
        let length = built.model.rod.length();
        let (x, rows) = snapshot_rows(&ds, FIELD, length).map_err(|e| named(first, e))?;
        let features = ds.row_len();
        let mut sources = Sources {
            sets: vec![(first.to_path_buf(), ds)],
            built,
            x,
            rows_of: vec![rows],
            features,
        };
        for p in &paths[1..] {
            let p = p.as_ref();
            let ds = Dataset::load(p)?;
            dataset_scenario(&ds).map_err(|e| named(p, e))?;
            sources.check_joins(p, &ds)?;
            let (more, rows) = snapshot_rows(&ds, FIELD, length).map_err(|e| named(p, e))?;
            sources.x.extend_from_slice(&more);
            sources.rows_of.push(rows);
            sources.sets.push((p.to_path_buf(), ds));
        }
        sources.check_coverage()?;
        Ok(sources)
    }

    /// Whether `ds` (read from `path`) has the first dataset's layout, inputs and physics; an
    /// error naming both datasets and what differs otherwise.
    fn check_joins(&self, path: &Path, ds: &Dataset) -> Result<(), ScenarioError> {
        let (first_path, first) = &self.sets[0];
        let (a, b) = (&first.meta, &ds.meta);
        let refuse = |what: String| {
            invalid(
                FIELD,
                format!(
                    "`{}` cannot join `{}` in one model: {what}; datasets combined into one model must share the points, components, sampled inputs and physics of one scenario",
                    path.display(),
                    first_path.display()
                ),
            )
        };
        if let Some((twin, _)) = self
            .sets
            .iter()
            .find(|(_, d)| d.strain_sha256 == ds.strain_sha256)
        {
            return Err(invalid(
                FIELD,
                format!(
                    "`{}` holds the same snapshots as `{}` (the same strain.npy): give each dataset once",
                    path.display(),
                    twin.display()
                ),
            ));
        }
        if !same_abscissae(&a.strain_x, &b.strain_x) || a.components != b.components {
            return Err(refuse(format!(
                "its snapshots have {} points × [{}], the first's {} points × [{}]{}",
                b.strain_x.len(),
                b.components.join(", "),
                a.strain_x.len(),
                a.components.join(", "),
                if a.strain_x.len() == b.strain_x.len() && !same_abscissae(&a.strain_x, &b.strain_x)
                {
                    " (at other abscissae)"
                } else {
                    ""
                }
            )));
        }
        if a.parameters != b.parameters {
            return Err(refuse(format!(
                "its inputs are [{}], the first's [{}]",
                b.parameters.join(", "),
                a.parameters.join(", ")
            )));
        }
        let scenario =
            |m: &crate::dataset::Meta| Scenario::from_toml(&m.scenario, &m.scenario_toml, &[]);
        let inputs = a.parameters.iter().map(String::as_str);
        let difference =
            first_physics_difference(&scenario(a)?, &scenario(b)?, inputs, |at, first, value| {
                format!("its scenario's {at} is {value}, the first's {first}")
            })?;
        if let Some(what) = difference {
            return Err(refuse(what));
        }
        Ok(())
    }

    /// Each dataset's directory and usable rows, in order.
    pub fn listing(&self) -> Vec<(PathBuf, usize)> {
        self.sets
            .iter()
            .zip(&self.rows_of)
            .map(|((dir, _), &n)| (dir.clone(), n))
            .collect()
    }

    /// Refuses datasets whose ranges of an input leave a gap no dataset covers (wider than the
    /// margin `--model` allows, [`INPUT_MARGIN`] of the united range): the model records one range
    /// per input (their union, [`Sources::input_ranges`]) and would answer inside the gap, where it
    /// saw no data.
    fn check_coverage(&self) -> Result<(), ScenarioError> {
        if self.sets.len() < 2 {
            return Ok(());
        }
        let ranges: Vec<Vec<InputRange>> =
            self.sets.iter().map(|(_, ds)| input_ranges(ds)).collect();
        for (d, united) in self.input_ranges().iter().enumerate() {
            let mut spans: Vec<(f64, f64, &Path)> = ranges
                .iter()
                .zip(&self.sets)
                .map(|(r, (dir, _))| (r[d].min, r[d].max, dir.as_path()))
                .collect();
            spans.sort_by(|p, q| p.0.total_cmp(&q.0));
            let margin = INPUT_MARGIN * (united.max - united.min);
            let mut reach = spans[0].1;
            for w in spans.windows(2) {
                reach = reach.max(w[0].1);
                if w[1].0 - reach > margin {
                    return Err(invalid(
                        FIELD,
                        format!(
                            "the datasets leave {} between {reach} and {} without a sample (`{}` starts there), yet a model of them would accept all of [{}, {}]: add a dataset that covers the gap, or make one model per range",
                            united.parameter,
                            w[1].0,
                            w[1].2.display(),
                            united.min,
                            united.max
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Usable rows of all datasets.
    pub fn rows(&self) -> usize {
        self.rows_of.iter().sum()
    }

    /// The first dataset (whose scenario and layout the model records).
    pub fn first(&self) -> &Dataset {
        &self.sets[0].1
    }

    /// Usable rows of trajectory (dynamics) datasets.
    pub fn dynamic_rows(&self) -> usize {
        self.sets
            .iter()
            .zip(&self.rows_of)
            .filter(|((_, ds), _)| ds.meta.dynamic.is_some())
            .map(|(_, &n)| n)
            .sum()
    }

    /// The strain rate of every usable row, row-major as [`Sources::x`] (strain per second): along a
    /// trajectory the central difference `(ξ_{k+1} − ξ_{k−1}) / (t_{k+1} − t_{k−1})` of its usable
    /// samples (one-sided at its ends; 0 for a trajectory of one sample); 0 for static equilibria,
    /// which are at rest.
    pub fn strain_rates(&self) -> Vec<f64> {
        let n = self.features;
        let mut v = vec![0.0; self.x.len()];
        let mut first = 0;
        for ((_, ds), &rows) in self.sets.iter().zip(&self.rows_of) {
            let (x, out) = (
                &self.x[first * n..(first + rows) * n],
                &mut v[first * n..(first + rows) * n],
            );
            first += rows;
            let (Some(t), Some(_), true) = (&ds.t, &ds.meta.dynamic, rows > 1) else {
                continue;
            };
            let t: Vec<f64> = ds.ok_rows().iter().map(|&k| t[k]).collect();
            for k in 0..rows {
                let (a, b) = (k.saturating_sub(1), (k + 1).min(rows - 1));
                let dt = t[b] - t[a];
                let (xa, xb) = (&x[a * n..(a + 1) * n], &x[b * n..(b + 1) * n]);
                for ((o, xa), xb) in out[k * n..(k + 1) * n].iter_mut().zip(xa).zip(xb) {
                    *o = (xb - xa) / dt;
                }
            }
        }
        v
    }

    /// The first dataset when every dataset holds static equilibria (whose anchors may be
    /// replaced by the reduced model's own equilibria); `None` if any is a trajectory.
    pub fn all_static(&self) -> Option<&Dataset> {
        let any_dynamic = self.sets.iter().any(|(_, ds)| ds.meta.dynamic.is_some());
        (!any_dynamic).then(|| self.first())
    }

    /// `provenance` with every dataset recorded: the first as `dataset`, the others as
    /// `more_datasets`, in order.
    pub fn record(&self, provenance: Provenance) -> Provenance {
        let mut p = provenance.dataset(&self.sets[0].1.origin);
        for (_, ds) in &self.sets[1..] {
            p.more_datasets.push(ds.origin.clone());
        }
        p
    }

    /// What the model records of its datasets: the first, and the others in order.
    pub fn refs(&self) -> (DatasetRef, Vec<DatasetRef>) {
        let mut refs = self
            .sets
            .iter()
            .zip(&self.rows_of)
            .map(|((dir, ds), &rows)| super::dataset_ref(dir, ds, rows));
        let first = refs.next().expect("at least one dataset");
        (first, refs.collect())
    }

    /// Per input, its range over the usable samples of every dataset.
    pub fn input_ranges(&self) -> Vec<InputRange> {
        let mut ranges = input_ranges(self.first());
        for (_, ds) in &self.sets[1..] {
            for (r, more) in ranges.iter_mut().zip(input_ranges(ds)) {
                (r.min, r.max) = (r.min.min(more.min), r.max.max(more.max));
            }
        }
        ranges
    }

    /// The inputs of the usable samples of every dataset in order, row-major (`n × k`).
    pub fn sample_inputs(&self) -> Vec<f64> {
        self.sets
            .iter()
            .flat_map(|(_, ds)| super::sample_inputs(ds))
            .collect()
    }

    /// Where usable row `i` (over all datasets) comes from: the dataset's directory and the row's
    /// sample index in it.
    pub fn origin_of(&self, mut i: usize) -> (&Path, usize) {
        for ((dir, ds), &n) in self.sets.iter().zip(&self.rows_of) {
            if i < n {
                return (dir, ds.ok_rows()[i]);
            }
            i -= n;
        }
        let (dir, ds) = self.sets.last().expect("at least one dataset");
        (dir, ds.samples())
    }

    /// Warnings for the user (datasets written before content hashes).
    pub fn warnings(&self) -> Vec<String> {
        self.sets
            .iter()
            .flat_map(|(dir, ds)| super::dataset_warnings(ds, dir))
            .collect()
    }
}
