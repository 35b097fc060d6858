//! One AE-ROM equilibrium as the Python package makes it (`robot.with_model(m).statics(u=[-2.7])`),
//! called from Rust: the library calls the binding makes — `Built::tensions` (count, finite,
//! plausible), `Reduced::covers_tensions`, `statics::solve_under` (the anchors' guess at u, the
//! dogleg, the report's kinematics) and `Reduced::check_range` — on the preset `single-tendon` with
//! the model attached by `reduce::attach_source`. Single thread. Python's time per
//! call minus this one is the binding's overhead (argument conversion, the GIL, the NumPy arrays):
//! `crates/gvsrom-py/bench/speed.py` runs this bench and the Python call in one run.
//!
//! The model: `GVSROM_BENCH_MODEL` (a model directory made for `single-tendon`), else
//! `<target>/bench-data/iv-a-ae`, made on the first run if missing — 200 IV-A equilibria (tensions
//! evenly in [−6, 3] N, `gvsrom dataset`) and an autoencoder with r = 1 and 7 hidden layers
//! (`gvsrom train`, 300 epochs, about a minute on two cores).
//!
//! Run with `cargo bench -p gvsrom --bench rom_statics`.

use criterion::{criterion_group, criterion_main, Criterion};
use gvsrom::reduce::{self, AttachOptions};
use std::hint::black_box;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicUsize;
use std::time::Duration;

/// The test tension [N]: between training tensions, as in the `reduction` bench.
const TENSION: f64 = -2.7;

fn rom_statics(c: &mut Criterion) {
    let dir = model_dir();
    let src = gvsrom::presets::source("single-tendon").expect("preset");
    let scenario = gvsrom::presets::load_from(&src, &[]).expect("preset");
    let mut built = gvsrom::build(&scenario).expect("build");
    reduce::attach_source(&mut built, &src, &[], &dir, AttachOptions::default()).expect("attach");
    let u = built.tensions(&[TENSION]).expect("tension");
    let r = built.reduced.as_ref().expect("attached");
    assert!(r.covers_tensions(&built.u, &u), "u inside the training");
    let report = gvsrom::statics::solve_under(&built, &u).expect("solve");
    eprintln!(
        "AE-ROM at u = {TENSION} N ({}): {} iteration(s), {} residuals, tip {:?}",
        dir.display(),
        report.iterations,
        report.residual_evaluations,
        report.tip_position
    );
    // what the binding calls: the tensions checked, then the solve and the range check
    let call = || {
        let u = built.tensions(black_box(&[TENSION])).expect("tension");
        assert!(r.covers_tensions(&built.u, &u));
        let report = gvsrom::statics::solve_under(&built, &u).expect("solve");
        r.check_range(&report.q).expect("in range");
        black_box(report)
    };
    c.bench_function("rom_statics/ae_r1_solve_under", |b| b.iter(call));
    // the same in the process's CPU time, which time spent waiting for a busy machine's cores
    // does not count (Python's `time.process_time`)
    c.bench_function("rom_statics/ae_r1_solve_under_cpu", |b| {
        b.iter_custom(|iters| {
            let t0 = process_cpu_time();
            for _ in 0..iters {
                call();
            }
            process_cpu_time() - t0
        })
    });
    c.bench_function("rom_statics/tensions_checked", |b| {
        b.iter(|| built.tensions(black_box(&[TENSION])).expect("tension"))
    });
}

/// CPU time of this process (`CLOCK_PROCESS_CPUTIME_ID`).
fn process_cpu_time() -> Duration {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec for clock_gettime to write.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) };
    assert_eq!(rc, 0, "clock_gettime");
    Duration::new(t.tv_sec as u64, t.tv_nsec as u32)
}

/// The model to time: `GVSROM_BENCH_MODEL`, or the one kept under the target directory (made if
/// missing).
fn model_dir() -> PathBuf {
    if let Ok(dir) = std::env::var("GVSROM_BENCH_MODEL") {
        return PathBuf::from(dir);
    }
    let target = std::env::var("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|_| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target"));
    let data = target.join("bench-data");
    let model = data.join("iv-a-ae");
    if gvsrom::reduced_model::ReducedModel::load(&model).is_ok() {
        return model;
    }
    std::fs::create_dir_all(&data).expect("bench-data directory");
    let dataset = data.join("iv-a-200");
    let args = gvsrom::dataset::DatasetRequest {
        scenario: "single-tendon".into(),
        set: vec![],
        sweep: vec!["tendons.0.tension=-6:3".into()],
        grid: vec![],
        random: vec![],
        samples: Some(200),
        seed: None,
        chunk_size: gvsrom::dataset::DEFAULT_CHUNK_SIZE,
        threads: None,
        out: dataset.clone(),
        force: true,
        resume: false,
        duration: None,
        sample_rate: None,
        input: None,
        interpolate: false,
        steps: None,
        babble: None,
        from_equilibrium: false,
        rtol: None,
        atol: 1e-6,
        stop_after_chunks: None,
    };
    gvsrom::dataset::run(&args, &AtomicUsize::new(0)).expect("dataset");
    let options = rom::nn::TrainOptions {
        latent: 1,
        hidden_layers: 7,
        epochs: 300,
        ..rom::nn::TrainOptions::default()
    };
    let mut progress = |_: usize, _: f64, _: Option<f64>| ControlFlow::Continue(());
    reduce::train(
        &[&dataset],
        None,
        &options,
        reduce::Loss::default(),
        0.0,
        &model,
        true,
        &mut progress,
    )
    .expect("train");
    model
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(50);
    targets = rom_statics
}
criterion_main!(benches);
