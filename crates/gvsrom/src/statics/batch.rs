//! Many statics solves at once: a batch of tensions in parallel ([`solve_batch`]), each chunk along
//! a warm-start chain of nearest neighbours ([`along_chain`]) with one solver, every solve warm
//! from its neighbour or, failing that, the scenario's load ramp from straight ([`warm_or_ramp`]).

use super::{failure, report, StaticsReport};
use crate::build::Built;
use crate::error::StaticsFailure;
use gvs::solve::statics::{StaticsError, StaticsOptions, StaticsSolution, StaticsSolver};
use gvs::solve::StopCheck;
use gvs::strain::StrainParam;
use nalgebra::DVector;
use std::time::Instant;

/// Iteration limit of a warm-started solve of a batch ([`warm_or_ramp`]) before it falls back to
/// the scenario's load ramp from straight.
pub const WARM_MAX_ITERATIONS: usize = 50;

/// Equilibria of the full model of `built` under many tensions (one row per equilibrium, one value
/// per tendon, checked with [`Built::tensions`]), solved as a static dataset of tensions solves its
/// samples (`gvsrom dataset`): chunks of `chunk_size` consecutive rows in parallel (rayon), each
/// along its warm-start chain ([`along_chain`], [`warm_or_ramp`]) with one solver. With the same
/// rows and chunk size the solutions are the dataset's, and they do not depend on the thread count;
/// each equals [`solve_under`](super::solve_under)'s to the solver's tolerance. A report's `solve_time_s` is its own
/// solve's; a row that fails has the failure of its solve from straight. `None` if `stop` asked
/// for it (it is checked between Newton iterations).
pub fn solve_batch(
    built: &Built,
    rows: &[Vec<f64>],
    chunk_size: usize,
    stop: &(dyn Fn() -> Option<String> + Sync),
) -> Option<Vec<Result<StaticsReport, StaticsFailure>>> {
    use rayon::prelude::*;
    let na = built.model.n_actuators();
    let ranges: Vec<[f64; 2]> = (0..na)
        .map(|t| {
            rows.iter()
                .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], u| {
                    [lo.min(u[t]), hi.max(u[t])]
                })
        })
        .collect();
    let chunks: Vec<Option<Vec<_>>> = rows
        .par_chunks(chunk_size.max(1))
        .map(|chunk| {
            let model = &built.model;
            let mut solver = StaticsSolver::new(model, built.options.clone());
            let mut ws = model.workspace();
            let values = chunk.concat();
            along_chain(&values, &ranges, chunk.len(), |i, warm| {
                let u = &chunk[i];
                let t0 = Instant::now();
                let r = warm_or_ramp(&mut solver, &built.options, u, &built.loads, warm, stop)?;
                let time = t0.elapsed().as_secs_f64();
                Some(match r {
                    Ok((sol, _)) => {
                        let report = report(built, model, u, &sol, time, &mut ws);
                        (Ok(report), Some(sol.q))
                    }
                    Err(error) => (Err(failure(built, u, error)), None),
                })
            })
        })
        .collect();
    chunks
        .into_iter()
        .collect::<Option<Vec<_>>>()
        .map(|c| c.into_iter().flatten().collect())
}

/// Solves the `m` problems of a chunk of a batch along a warm-start chain ([`solve_batch`], the
/// chunks of `gvsrom dataset`). Problem `i` has the parameter values `values[i·d..(i+1)·d]`,
/// parameter `p` the range `ranges[p] = [lo, hi]`. The problems are taken along a greedy
/// nearest-neighbour chain in the parameters normalised by their ranges, from the problem closest
/// to zero (each parameter in units of its range's largest magnitude; ties go to the lower index),
/// and `solve(i, warm)` solves problem `i` from the solution of the nearest problem solved so far
/// (`None` for the first, or if none was solved). It returns the problem's result with its
/// solution `q` if it has one, or `None` to stop: `along_chain` then returns `None`. Results are
/// in problem order.
pub fn along_chain<R>(
    values: &[f64],
    ranges: &[[f64; 2]],
    m: usize,
    mut solve: impl FnMut(usize, Option<&DVector<f64>>) -> Option<(R, Option<DVector<f64>>)>,
) -> Option<Vec<R>> {
    let d = ranges.len();
    let row = |i: usize| &values[i * d..(i + 1) * d];
    // normalised coordinates for distances, and the distance to zero for the chain's start
    let z: Vec<Vec<f64>> = (0..m)
        .map(|i| {
            ranges
                .iter()
                .zip(row(i))
                .map(|([lo, hi], v)| {
                    let w = hi - lo;
                    if w > 0.0 {
                        (v - lo) / w
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect();
    let zero: Vec<f64> = (0..m)
        .map(|i| {
            ranges
                .iter()
                .zip(row(i))
                .map(|([lo, hi], v)| {
                    let s = lo.abs().max(hi.abs());
                    if s > 0.0 {
                        (v / s) * (v / s)
                    } else {
                        0.0
                    }
                })
                .sum()
        })
        .collect();
    let mut out: Vec<Option<R>> = (0..m).map(|_| None).collect();
    let mut solved: Vec<(usize, DVector<f64>)> = vec![];
    for i in chain(&z, &zero) {
        let warm = solved
            .iter()
            .min_by(|a, b| dist(&z[i], &z[a.0]).total_cmp(&dist(&z[i], &z[b.0])))
            .map(|(_, q)| q);
        let (result, q) = solve(i, warm)?;
        if let Some(q) = q {
            solved.push((i, q));
        }
        out[i] = Some(result);
    }
    out.into_iter().collect()
}

/// The order of a chain: greedy nearest neighbours in `z`, from the point of least `zero` (ties go
/// to the lower index).
fn chain(z: &[Vec<f64>], zero: &[f64]) -> Vec<usize> {
    let n = z.len();
    let mut done = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut cur = (0..n)
        .min_by(|&a, &b| zero[a].total_cmp(&zero[b]).then(a.cmp(&b)))
        .unwrap_or(0);
    for _ in 0..n {
        done[cur] = true;
        order.push(cur);
        let next = (0..n)
            .filter(|&j| !done[j])
            .min_by(|&a, &b| dist(&z[cur], &z[a]).total_cmp(&dist(&z[cur], &z[b])));
        match next {
            Some(j) => cur = j,
            None => break,
        }
    }
    order
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// One solve of a batch: from `warm` (a neighbour's solution) at the full load in one stage, at most
/// [`WARM_MAX_ITERATIONS`] iterations; without `warm`, or if that fails, the scenario's solve
/// (`options`, with its load ramp) from straight. Returns the solution and whether the warm start
/// gave it, or the error of the solve from straight; `None` if `stop` asked to stop (polled before
/// every load stage).
pub fn warm_or_ramp<P: StrainParam>(
    solver: &mut StaticsSolver<'_, P>,
    options: &StaticsOptions,
    u: &[f64],
    loads: &gvs::loads::Loads,
    warm: Option<&DVector<f64>>,
    stop: &StopCheck<'_>,
) -> Option<Result<(StaticsSolution, bool), StaticsError>> {
    if let Some(q0) = warm {
        solver.options = StaticsOptions {
            ramp_steps: 1,
            min_increment: 1.0,
            max_iterations: options.max_iterations.min(WARM_MAX_ITERATIONS),
            ..options.clone()
        };
        match solver.solve_interruptible(u, loads, Some(q0), stop) {
            // a neighbour's solution can lead onto an equilibrium that diverges (the neighbour's
            // own branch past its end): then solve from straight, whose solver follows the
            // equilibria connected to the straight rod
            Ok(s) if s.divergence.is_none() => return Some(Ok((s, true))),
            Err(StaticsError::Stopped { .. }) => return None,
            Ok(_) | Err(_) => {}
        }
    }
    solver.options = options.clone();
    match solver.solve_interruptible(u, loads, None, stop) {
        Ok(s) => Some(Ok((s, false))),
        Err(StaticsError::Stopped { .. }) => None,
        Err(e) => Some(Err(e)),
    }
}
