//! Sampling plans of a static dataset: which scenario values vary, over which ranges, and the value of
//! every parameter at every sample.
//!
//! A plan is one kind of `--sweep`, `--grid` or `--random` (kinds are not mixed), each given as
//! `PATH=LO:HI` by the same key paths as `--set`. A `*` segment stands for every entry of a list
//! (`tendons.*.tension` is one parameter per tendon). With `d` parameters and `N = --samples`:
//!
//! - **sweep**: all parameters move together along one even 1-D grid including both ends,
//!   `v_i(k) = lo_i + (hi_i − lo_i) k/(N − 1)`;
//! - **grid**: the product of `m` even values per parameter, `m = round(N^(1/d))`, which must give
//!   `m^d = N` exactly; samples in lexicographic order (the last parameter varies fastest);
//! - **random**: independent uniform values in `[lo_i, hi_i)`, drawn sample after sample, parameter
//!   after parameter, from one SplitMix64 stream seeded by `--seed`, so the values never depend on
//!   the thread count.

use crate::scenario::{every_entry, parse_path, Seg};
use gvs::inputs::SplitMix64;
use serde::{Deserialize, Serialize};
use toml::{Table, Value};

/// Most samples of one dataset.
pub const MAX_SAMPLES: usize = 10_000_000;
/// Most parameters of one plan (after `*` expansion).
pub const MAX_PARAMETERS: usize = 64;

/// How the plan spreads its samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PlanKind {
    Sweep,
    Grid,
    Random,
}

impl PlanKind {
    pub fn option(self) -> &'static str {
        match self {
            PlanKind::Sweep => "--sweep",
            PlanKind::Grid => "--grid",
            PlanKind::Random => "--random",
        }
    }
}

/// One varied scenario value after `*` expansion.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Parameter {
    /// Canonical dotted path (`tendons.3.tension`).
    pub path: String,
    pub lo: f64,
    pub hi: f64,
    /// The `--sweep/--grid/--random` argument it came from.
    pub spec: String,
    /// The tendon whose tension this is, when the path is `tendons.K.tension` (applied without
    /// rebuilding the model).
    #[serde(skip)]
    pub tendon: Option<usize>,
}

/// A checked plan: its parameters, sample count and seed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    pub kind: PlanKind,
    /// The arguments as given.
    pub specs: Vec<String>,
    pub samples: usize,
    pub seed: u64,
    /// Values per parameter of a grid.
    pub per_axis: Option<usize>,
    pub parameters: Vec<Parameter>,
}

/// A plan error: the option, its value and what is accepted.
fn bad(kind: PlanKind, spec: &str, msg: impl std::fmt::Display) -> String {
    format!("{} {spec}: {msg}", kind.option())
}

/// `PATH=LO:HI` → (path, lo, hi).
fn parse_spec(kind: PlanKind, spec: &str) -> Result<(String, f64, f64), String> {
    let usage = "expected PATH=LO:HI with finite numbers LO <= HI, e.g. tendons.0.tension=-6:3";
    let (path, range) = spec.split_once('=').ok_or_else(|| bad(kind, spec, usage))?;
    let (lo, hi) = range
        .split_once(':')
        .ok_or_else(|| bad(kind, spec, usage))?;
    let num = |s: &str| s.trim().parse::<f64>().ok().filter(|v| v.is_finite());
    match (num(lo), num(hi)) {
        (Some(lo), Some(hi)) if lo <= hi && !path.trim().is_empty() => {
            Ok((path.trim().to_string(), lo, hi))
        }
        _ => Err(bad(kind, spec, usage)),
    }
}

fn canonical(segs: &[Seg]) -> String {
    segs.iter()
        .map(|s| match s {
            Seg::Key(k) => k.clone(),
            Seg::Index(i) => i.to_string(),
        })
        .collect::<Vec<_>>()
        .join(".")
}

/// Expands `path` (with at most one `*` segment) against the scenario `table`
/// ([`every_entry`], as `--set` expands it).
fn expand(kind: PlanKind, spec: &str, path: &str, table: &Table) -> Result<Vec<Vec<Seg>>, String> {
    let parse = |p: &str| parse_path(p).map_err(|e| bad(kind, spec, e));
    let stars = path
        .replace("[*]", ".*")
        .split('.')
        .filter(|p| *p == "*")
        .count();
    if stars > 1 {
        return Err(bad(kind, spec, "at most one `*` per path"));
    }
    match every_entry(table, path).map_err(|e| bad(kind, spec, e))? {
        None => Ok(vec![parse(path)?]),
        Some(paths) => paths.iter().map(|p| parse(p)).collect(),
    }
}

impl Plan {
    /// Checks the plan arguments against the scenario table (after `--set`): exactly one kind,
    /// `samples` in [1, [`MAX_SAMPLES`]], ranges `LO <= HI`, `*` over an existing non-empty list,
    /// and at least two values per axis of a sweep or grid over `LO < HI` (one would be LO alone).
    pub fn new(
        sweep: &[String],
        grid: &[String],
        random: &[String],
        samples: Option<usize>,
        seed: u64,
        table: &Table,
    ) -> Result<Plan, String> {
        let given: Vec<(PlanKind, &[String])> = [
            (PlanKind::Sweep, sweep),
            (PlanKind::Grid, grid),
            (PlanKind::Random, random),
        ]
        .into_iter()
        .filter(|(_, v)| !v.is_empty())
        .collect();
        let (kind, specs) = match given.as_slice() {
            [one] => *one,
            [] => return Err("a dataset needs a plan: --sweep, --grid or --random PATH=LO:HI (or --duration for a dynamic dataset)".into()),
            _ => return Err(format!(
                "{} cannot be combined: a dataset uses one kind of plan (repeat the option for several parameters)",
                given.iter().map(|(k, _)| k.option()).collect::<Vec<_>>().join(" and ")
            )),
        };
        let samples = samples.ok_or_else(|| {
            format!(
                "{} needs --samples N (an integer in [1, {MAX_SAMPLES}])",
                kind.option()
            )
        })?;
        if !(1..=MAX_SAMPLES).contains(&samples) {
            return Err(format!(
                "--samples {samples}: expected an integer in [1, {MAX_SAMPLES}]"
            ));
        }
        let n_tendons = match table.get("tendons") {
            Some(Value::Array(a)) => a.len(),
            _ => 0,
        };
        let mut parameters: Vec<Parameter> = vec![];
        for spec in specs {
            let (path, lo, hi) = parse_spec(kind, spec)?;
            for segs in expand(kind, spec, &path, table)? {
                let path = canonical(&segs);
                if parameters.iter().any(|p| p.path == path) {
                    return Err(bad(kind, spec, format!("`{path}` is varied twice")));
                }
                let tendon = match segs.as_slice() {
                    [Seg::Key(t), Seg::Index(k), Seg::Key(v)]
                        if t == "tendons" && v == "tension" && *k < n_tendons =>
                    {
                        Some(*k)
                    }
                    _ => None,
                };
                parameters.push(Parameter {
                    path,
                    lo,
                    hi,
                    spec: spec.clone(),
                    tendon,
                });
            }
        }
        if parameters.len() > MAX_PARAMETERS {
            return Err(format!(
                "{}: {} parameters after `*` expansion (accepted <= {MAX_PARAMETERS})",
                kind.option(),
                parameters.len()
            ));
        }
        let per_axis = match kind {
            PlanKind::Grid => Some(grid_per_axis(samples, parameters.len())?),
            _ => None,
        };
        let evenly = match kind {
            PlanKind::Sweep => Some((samples, 2)),
            PlanKind::Grid => per_axis.map(|m| (m, 1usize << parameters.len().min(20))),
            PlanKind::Random => None,
        };
        if let (Some((1, needed)), Some(p)) = (evenly, parameters.iter().find(|p| p.lo < p.hi)) {
            return Err(format!(
                "{} `{}`: --samples {samples} gives one value per parameter, its LO end {}: give at least {needed} samples to reach HI, or LO:LO for one value",
                kind.option(),
                p.spec,
                p.lo
            ));
        }
        Ok(Plan {
            kind,
            specs: specs.to_vec(),
            samples,
            seed,
            per_axis,
            parameters,
        })
    }

    /// Parameter names (canonical paths), one column of `inputs.npy` each.
    pub fn names(&self) -> Vec<String> {
        self.parameters.iter().map(|p| p.path.clone()).collect()
    }

    /// The `samples × d` parameter values, row-major.
    pub fn values(&self) -> Vec<f64> {
        let d = self.parameters.len();
        let n = self.samples;
        let even = |p: &Parameter, i: usize, m: usize| {
            if m <= 1 {
                p.lo
            } else if i + 1 == m {
                p.hi // exactly the end, whatever the rounding
            } else {
                p.lo + (p.hi - p.lo) * (i as f64 / (m - 1) as f64)
            }
        };
        let mut v = Vec::with_capacity(n * d);
        match self.kind {
            PlanKind::Sweep => {
                for k in 0..n {
                    v.extend(self.parameters.iter().map(|p| even(p, k, n)));
                }
            }
            PlanKind::Grid => {
                let m = self.per_axis.unwrap_or(1);
                for k in 0..n {
                    // digits of k in base m, the last parameter fastest
                    let mut rest = k;
                    let mut idx = vec![0; d];
                    for i in (0..d).rev() {
                        idx[i] = rest % m;
                        rest /= m;
                    }
                    v.extend(
                        self.parameters
                            .iter()
                            .zip(&idx)
                            .map(|(p, &i)| even(p, i, m)),
                    );
                }
            }
            PlanKind::Random => {
                let mut rng = SplitMix64::new(self.seed);
                for _ in 0..n {
                    v.extend(self.parameters.iter().map(|p| rng.range(p.lo, p.hi)));
                }
            }
        }
        v
    }
}

/// `m` with `m^d = samples`, or an error naming the nearest valid counts.
fn grid_per_axis(samples: usize, d: usize) -> Result<usize, String> {
    let m = (samples as f64).powf(1.0 / d as f64).round().max(1.0) as usize;
    let pow = |m: usize| (m as u128).checked_pow(d as u32).unwrap_or(u128::MAX);
    if pow(m) == samples as u128 {
        return Ok(m);
    }
    let below = (1..=m)
        .rev()
        .find(|&k| pow(k) < samples as u128)
        .unwrap_or(1);
    let above = (m.max(1)..)
        .find(|&k| pow(k) > samples as u128)
        .unwrap_or(m + 1);
    Err(format!(
        "--samples {samples}: a grid over {d} parameters needs the same number of values along each, a count n^{d}; nearest: {} ({below}^{d}) or {} ({above}^{d})",
        pow(below),
        pow(above)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> Table {
        text.parse().unwrap()
    }

    #[test]
    fn star_expands_to_one_parameter_per_list_entry() {
        let t =
            table("[[tendons]]\ntension = 1\n[[tendons]]\ntension = 2\n[[tendons]]\ntension = 3\n");
        let p = Plan::new(&[], &[], &["tendons.*.tension=-1:1".into()], Some(4), 0, &t).unwrap();
        assert_eq!(
            p.names(),
            [
                "tendons.0.tension",
                "tendons.1.tension",
                "tendons.2.tension"
            ]
        );
        assert!(p.parameters.iter().all(|p| p.tendon.is_some()));
    }

    #[test]
    fn sweep_includes_both_ends_and_moves_all_parameters_together() {
        let t = table("[[tendons]]\ntension = 1\n[[tendons]]\ntension = 2\n");
        let p = Plan::new(&["tendons.*.tension=-6:3".into()], &[], &[], Some(4), 0, &t).unwrap();
        assert_eq!(p.values(), [-6.0, -6.0, -3.0, -3.0, 0.0, 0.0, 3.0, 3.0]);
    }

    #[test]
    fn grid_needs_an_exact_power_and_names_the_nearest() {
        let t = table("[[tendons]]\ntension = 1\n[[tendons]]\ntension = 2\n");
        let e =
            Plan::new(&[], &["tendons.*.tension=0:1".into()], &[], Some(10), 0, &t).unwrap_err();
        assert!(e.contains("9 (3^2)") && e.contains("16 (4^2)"), "{e}");
        let p = Plan::new(&[], &["tendons.*.tension=0:2".into()], &[], Some(9), 0, &t).unwrap();
        let v = p.values();
        assert_eq!(&v[..6], [0.0, 0.0, 0.0, 1.0, 0.0, 2.0]);
        assert_eq!(&v[16..], [2.0, 2.0]);
    }

    #[test]
    fn one_value_per_axis_over_a_range_is_refused_not_taken_as_its_lo_end() {
        let t = table("[[tendons]]\ntension = 1\n[[tendons]]\ntension = 2\n");
        let sweep = |spec: &str, n| Plan::new(&[spec.into()], &[], &[], Some(n), 0, &t);
        let e = sweep("tendons.0.tension=-6:0", 1).unwrap_err();
        assert!(
            e.contains("--samples 1 gives one value per parameter, its LO end -6")
                && e.contains("at least 2 samples"),
            "{e}"
        );
        assert_eq!(
            sweep("tendons.0.tension=-6:-6", 1).unwrap().values(),
            [-6.0]
        );
        assert_eq!(
            sweep("tendons.0.tension=-6:0", 2).unwrap().values(),
            [-6.0, 0.0]
        );
        let e = Plan::new(&[], &["tendons.*.tension=0:1".into()], &[], Some(1), 0, &t).unwrap_err();
        assert!(e.contains("at least 4 samples"), "{e}");
        // a random plan of one sample draws one value in the range
        assert!(Plan::new(&[], &[], &["tendons.0.tension=0:1".into()], Some(1), 0, &t).is_ok());
    }

    #[test]
    fn random_values_depend_only_on_the_seed_and_stay_in_range() {
        let t = table("[[tendons]]\ntension = 1\n");
        let p = |seed| {
            Plan::new(
                &[],
                &[],
                &["tendons.0.tension=-2:5".into()],
                Some(50),
                seed,
                &t,
            )
            .unwrap()
            .values()
        };
        assert_eq!(p(3), p(3));
        assert_ne!(p(3), p(4));
        assert!(p(3).iter().all(|v| (-2.0..5.0).contains(v)));
    }

    #[test]
    fn mixed_kinds_and_bad_ranges_are_refused() {
        let t = table("[[tendons]]\ntension = 1\n");
        let e = Plan::new(
            &["tendons.0.tension=0:1".into()],
            &[],
            &["tendons.0.tension=0:1".into()],
            Some(4),
            0,
            &t,
        )
        .unwrap_err();
        assert!(e.contains("--sweep and --random"), "{e}");
        let e =
            Plan::new(&["tendons.0.tension=3:-1".into()], &[], &[], Some(4), 0, &t).unwrap_err();
        assert!(
            e.contains("--sweep tendons.0.tension=3:-1") && e.contains("LO <= HI"),
            "{e}"
        );
        let e = Plan::new(&["loads.*.x=0:1".into()], &[], &[], Some(4), 0, &t).unwrap_err();
        assert!(e.contains("no list `loads`"), "{e}");
    }
}
