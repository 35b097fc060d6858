//! Training time per epoch of the autoencoder on 1000 × 306 synthetic snapshots, 7 hidden layers,
//! r = 1, batch 64. Run: `cargo run --release -p rom --example ae_epoch_time [-- EPOCHS [adam]]`
//! (`EPOCHS` Adam epochs, default 20; `adam`: only the Adam run with 10 % validation). Training uses
//! rayon's global pool, all cores by default; `RAYON_NUM_THREADS=1` (or `taskset -c 0`) times one.
//! The mean leaves out the first epoch (warm-up); "fastest" is the quickest epoch, the least
//! disturbed by other jobs on a shared machine.
//!
//! The JAX reference on the same data, architecture, batch size, float64, 900/100 split and
//! per-epoch validation pass (compare with the "Adam, 10 % validation" line):
//! `python scripts/ae_reference.py --synthetic --epochs 20`.

use gvs::inputs::SplitMix64;
use rom::nn::{Autoencoder, FineTune, TrainOptions};
use std::ops::ControlFlow;
use std::time::Instant;

/// 1000 rows of `x_j = sin(a X_j) + b X_j² + c cos(3 X_j)`, `X_j = j/305`, `(a, b, c)` uniform in [−1, 1].
fn snapshots(rows: usize, n: usize) -> Vec<f64> {
    let mut rng = SplitMix64::new(3);
    let mut data = Vec::with_capacity(rows * n);
    for _ in 0..rows {
        let (a, b, c) = (
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        data.extend((0..n).map(|j| {
            let x = j as f64 / (n - 1) as f64;
            (a * x).sin() + b * x * x + c * (3.0 * x).cos()
        }));
    }
    data
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let epochs: usize = args
        .first()
        .map_or(20, |a| a.parse().expect("EPOCHS: a number"));
    let adam_only = args.get(1).is_some_and(|a| a == "adam");
    let (rows, n) = (1000, 306);
    let data = snapshots(rows, n);
    for (label, validation_fraction, fine_tune) in [
        ("Adam, no validation", 0.0, FineTune::None),
        ("Adam, 10 % validation", 0.1, FineTune::None),
        (
            "L-BFGS iterations, 10 % validation",
            0.1,
            FineTune::Lbfgs {
                iterations: 20,
                memory: 10,
            },
        ),
    ] {
        if adam_only && (validation_fraction == 0.0 || fine_tune != FineTune::None) {
            continue;
        }
        let is_lbfgs = matches!(fine_tune, FineTune::Lbfgs { .. });
        let opts = TrainOptions {
            latent: 1,
            hidden_layers: 7,
            batch_size: 64,
            epochs: if is_lbfgs { 1 } else { epochs },
            patience: None,
            validation_fraction,
            fine_tune,
            ..TrainOptions::default()
        };
        let mut stamps = Vec::new();
        let mut progress = |_: usize, _: f64, _: Option<f64>| {
            stamps.push(Instant::now());
            ControlFlow::Continue(())
        };
        match Autoencoder::train(&data, n, &opts, &mut progress) {
            Ok((_, report)) => {
                // Skip the first interval (the first epoch includes warm-up); L-BFGS counts from epoch 2.
                let times: Vec<f64> = stamps
                    .windows(2)
                    .map(|w| (w[1] - w[0]).as_secs_f64())
                    .collect();
                let mean = times.iter().sum::<f64>() / times.len().max(1) as f64;
                let min = times.iter().copied().fold(f64::INFINITY, f64::min);
                println!(
                    "{label}: {:.1} ms per epoch (fastest {:.1}) over {} epochs (total {:.2} s, final train RMSE {:.3e})",
                    1e3 * mean,
                    1e3 * min,
                    times.len(),
                    report.wall_time.as_secs_f64(),
                    report.final_train_rmse
                );
            }
            Err(e) => eprintln!("{label}: {e}"),
        }
    }
}
