//! Case IV-B: the soft beam under a triangular moment pulse (paper Section IV-B, Table I bottom,
//! Figs. 5–6, Table III).
//!
//! The paper's magnitudes are the pulse's total moment in N·m (`convention = "total"`): 5000
//! equilibria at random centres in [0, L] and magnitudes in [−5, 5] N·m. Models: autoencoders
//! r = 1, 2, 3 × 3, 5, 7 hidden layers and POD with 1 … 30 modes. Test: 4 N·m at X/L = 0.25 and
//! 2 N·m at X/L = 0.75 (Fig. 6).

use super::evaluation::{statics_eval, EvalModel, Evaluation};
use super::figures;
use super::iv_a::{accuracy_table, table_i};
use super::report::{figure, CaseReport, Cell, Finding, RenderedFigure, Table};
use super::statics_study::StaticsComparison;
use super::step::Step;
use super::tasks::{self, AeConfig, DatasetSpec, ScenarioSpec};
use super::{iv_b_built, iv_common, new_report, paper, Case, Options, Run};
use crate::dataset::Dataset;
use crate::plot::{palette, Figure, SeriesStyle};
use crate::reduced_model::{ModelWeights, ReducedModel};
use serde_json::json;
use std::path::Path;

struct Sizes {
    samples: usize,
    epochs: usize,
    /// Iterations of the final L-BFGS phase.
    lbfgs_iterations: usize,
    /// The POD models tried, ascending (the fewest below 1 % is searched among them).
    pod_modes: Vec<usize>,
    repeat: u32,
}

fn sizes(opts: &Options) -> Sizes {
    if opts.tiny {
        Sizes {
            samples: 60,
            epochs: 15,
            lbfgs_iterations: 10,
            pod_modes: vec![1, 2, 4],
            repeat: 1,
        }
    } else if opts.quick {
        Sizes {
            samples: 500,
            epochs: 100,
            lbfgs_iterations: 300,
            pod_modes: vec![1, 2, 3, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 28],
            repeat: 2,
        }
    } else {
        Sizes {
            samples: 5000,
            // with 2000 epochs and 300 L-BFGS iterations the r = 2, 7-layer model still improved at
            // its last epoch (RMSE 0.572); with these it stops on its own at ~3900 (0.481)
            epochs: 5000,
            lbfgs_iterations: 2000,
            pod_modes: (1..=30).collect(),
            repeat: 5,
        }
    }
}

/// The two loads of Fig. 6: (total moment [N·m], centre [m]) on the 0.8 m beam.
const TEST_LOADS: [(f64, f64); 2] = [(4.0, 0.2), (2.0, 0.6)];
/// Random test loads beyond the paper's two, and the seed that draws them (not the data's).
const RANDOM_LOADS: usize = 5;
const RANDOM_SEED: u64 = 7;

/// `RANDOM_LOADS` loads drawn like the data (centre uniform in [0, L], magnitude uniform in
/// [−5, 5] N·m) with another seed, as overrides.
fn random_inputs() -> Vec<Vec<String>> {
    let mut rng = gvs::inputs::SplitMix64::new(RANDOM_SEED);
    (0..RANDOM_LOADS)
        .map(|_| {
            let (c, m) = (rng.range(0.0, 0.8), rng.range(-5.0, 5.0));
            vec![
                format!("loads.distributed.0.magnitude={m:.4}"),
                format!("loads.distributed.0.center={c:.4}"),
            ]
        })
        .collect()
}

/// The position of the POD model with `k` modes among `modes`.
fn pod_index(modes: &[usize], k: usize) -> anyhow::Result<usize> {
    modes
        .iter()
        .position(|&m| m == k)
        .ok_or_else(|| anyhow::anyhow!("no POD-{k} among the POD models {modes:?}"))
}

/// The label of the AE-2 with the scaled decoder in the evaluations.
const SCALED: &str = "AE-2 scaled";

/// Bins of the load magnitude |M| [N·m] of [`error_by_magnitude`]; the last is closed (the data's
/// largest magnitude, 5 N·m).
const MAGNITUDE_BINS: [f64; 6] = [0.0, 0.5, 1.0, 1.5, 2.5, 5.0];

/// The AE-2's and POD-2's reconstruction error over the dataset by load magnitude: where the
/// bottleneck at zero load (the paper's Fig. 5) leaves the autoencoder above 1 %.
fn error_by_magnitude(
    data: &Path,
    ae: &Step<tasks::ModelInfo>,
    scaled: &Step<tasks::ModelInfo>,
    pod: &Step<tasks::ModelInfo>,
) -> anyhow::Result<Table> {
    let (ae, scaled, pod) = (
        ReducedModel::load(&ae.path)?,
        ReducedModel::load(&scaled.path)?,
        ReducedModel::load(&pod.path)?,
    );
    let errors = tasks::relative_errors(
        &Dataset::load(data)?,
        &[&ae, &scaled, &pod],
        "loads.distributed.0.magnitude",
    )?;
    let top = MAGNITUDE_BINS[MAGNITUDE_BINS.len() - 1];
    let rows = MAGNITUDE_BINS
        .windows(2)
        .map(|b| {
            let last = b[1] == top;
            let inside: Vec<&Vec<f64>> = errors
                .iter()
                .filter(|(m, _)| (b[0]..b[1]).contains(&m.abs()) || (last && m.abs() == top))
                .map(|(_, e)| e)
                .collect();
            let n = inside.len().max(1) as f64;
            let mean = |i: usize| inside.iter().map(|e| e[i]).sum::<f64>() / n;
            let above = |i: usize| inside.iter().filter(|e| e[i] >= 1.0).count();
            let max = |i: usize| inside.iter().fold(0.0f64, |m, e| m.max(e[i]));
            vec![
                Cell::text(match last {
                    true => format!("[{}, {}]", b[0], b[1]),
                    false => format!("[{}, {})", b[0], b[1]),
                }),
                Cell::int(inside.len()),
                Cell::sig(mean(0), 3),
                Cell::sig(max(0), 3),
                Cell::sig(100.0 * above(0) as f64 / n, 3),
                Cell::sig(mean(1), 3),
                Cell::sig(max(1), 3),
                Cell::sig(100.0 * above(1) as f64 / n, 3),
                Cell::sig(mean(2), 3),
            ]
        })
        .collect();
    Ok(Table {
        id: "error-by-magnitude".into(),
        title: "AE-2 (plain and scaled decoder) and POD-2 reconstruction error over the dataset, by load magnitude".into(),
        columns: [
            "magnitude [N·m] (absolute)",
            "samples",
            "AE-2 mean [%]",
            "AE-2 max [%]",
            "AE-2 samples ≥ 1 % [%]",
            "AE-2 scaled mean [%]",
            "AE-2 scaled max [%]",
            "AE-2 scaled samples ≥ 1 % [%]",
            "POD-2 mean [%]",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        note: "Error: mean |x̂ − x| over the snapshot in % of its largest |x| (the accuracy tables' strain error), x̂ the model's reconstruction (AE: decoder of the encoding, which a ROM equilibrium matches to a few hundredths of a percent; POD: projection). At small |M| every centre's snapshot shrinks to the straight rod, the cone's apex that a smooth 2-D decoder cannot follow: its relative error grows as 1/|M| there. The scaled decoder x̂ = z₁ D(z) (beyond the paper) decodes every z₁ = 0 to the straight rod and follows the apex; its encoder cannot tell the centre of a vanishing snapshot, so its reconstruction's relative error still grows below 0.5 N·m, while a ROM equilibrium solves for both coordinates.".into(),
    })
}

/// The IV-B scenario: the preset in the paper's convention (total moment in N·m).
pub fn scenario() -> ScenarioSpec {
    ScenarioSpec::new("soft-beam", &[])
}

fn plan(opts: &Options) -> DatasetSpec {
    DatasetSpec {
        random: vec![
            "loads.distributed.0.center=0:0.8".into(),
            "loads.distributed.0.magnitude=-5:5".into(),
        ],
        samples: Some(sizes(opts).samples),
        seed: 1,
        ..DatasetSpec::default()
    }
}

/// The IV-B dataset (step `iv-b/dataset`).
pub fn dataset(run: &Run, opts: &Options) -> anyhow::Result<Step<tasks::DatasetInfo>> {
    tasks::dataset(run, "iv-b/dataset", &scenario(), &plan(opts), opts.jobs)
}

/// Plateau patience [epochs] of the r = 1 autoencoders (the others keep `gvsrom train`'s 50). A
/// 1-D code of the 2-D family improves through long, noisy plateaus, and a rate cut at each short
/// one freezes it early. Measured on the 5000 samples, 7 hidden layers, seed 0 (validation RMSE):
/// 10.5 at patience 50 (Adam stops at ~700 epochs), 9.9 at 150, 8.8 at 300 (all 5000 Adam epochs
/// and 2000 L-BFGS iterations, 250 s), 10.2 with no early stopping (the rate never drops), 9.6 at
/// 300 with the rate 3e-3; seeds 1 and 2 at 300: 10.2 and 8.6.
const R1_PATIENCE: usize = 300;

/// The settings of the IV-B autoencoder with `r` latent coordinates and `h` hidden layers.
pub fn ae_config(opts: &Options, r: usize, h: usize) -> AeConfig {
    let s = sizes(opts);
    let c = AeConfig::new(r, h, s.epochs);
    AeConfig {
        lbfgs_iterations: s.lbfgs_iterations,
        patience: if r == 1 { R1_PATIENCE } else { c.patience },
        ..c
    }
}

/// Seeds of the AE-2 with the scaled decoder (beyond the paper); the one with the lowest
/// validation RMSE is kept. Its first coordinate must learn the signed magnitude (the scaling
/// `z₁`); a seed whose `z₁` settles away from 0 over the whole data (measured: 1 of 3) is a plain
/// decoder in effect, at 2.6× the RMSE.
const SCALED_SEEDS: [u64; 3] = [0, 1, 2];

/// The IV-B AE-2 (7 hidden layers) with the scaled decoder `x̂ = z₁ D(z)` and `seed`.
pub fn scaled_config(opts: &Options, seed: u64) -> AeConfig {
    AeConfig {
        seed,
        decoder: Some(rom::nn::DecoderForm::Scaled.name().into()),
        ..ae_config(opts, 2, 7)
    }
}

/// Trains the IV-B autoencoder `c` on `data` (step `iv-b/ae-r<r>-h<h>`, with `-scaled-seed<s>`
/// for the scaled decoder).
pub fn ae_step(
    run: &Run,
    data: &Step<tasks::DatasetInfo>,
    c: &AeConfig,
) -> anyhow::Result<Step<tasks::ModelInfo>> {
    let name = match c.decoder.as_deref() {
        Some("scaled") => format!(
            "iv-b/ae-r{}-h{}-scaled-seed{}",
            c.latent, c.hidden_layers, c.seed
        ),
        _ => format!("iv-b/ae-r{}-h{}", c.latent, c.hidden_layers),
    };
    tasks::train(run, &name, data, c)
}

/// The two test inputs of Fig. 6 as overrides.
pub fn test_inputs() -> Vec<Vec<String>> {
    TEST_LOADS
        .iter()
        .map(|(m, c)| {
            vec![
                format!("loads.distributed.0.magnitude={m}"),
                format!("loads.distributed.0.center={c}"),
            ]
        })
        .collect()
}

/// Runs case IV-B.
pub fn run(run: &Run, opts: &Options) -> anyhow::Result<(CaseReport, Vec<RenderedFigure>)> {
    let s = sizes(opts);
    let scenario = scenario();
    let plan = plan(opts);
    let data = dataset(run, opts)?;
    let configs: Vec<AeConfig> = paper::TABLE_I_LAYERS
        .iter()
        .flat_map(|&h| (1..=3).map(move |r| (h, r)))
        .map(|(h, r)| ae_config(opts, r, h))
        .collect();
    let trained = tasks::parallel(&configs, |c| ae_step(run, &data, c))?;
    let aes: Vec<Vec<_>> = trained.chunks(3).map(<[_]>::to_vec).collect();
    let scaled_configs: Vec<AeConfig> = SCALED_SEEDS
        .iter()
        .map(|&s| scaled_config(opts, s))
        .collect();
    let scaled_all = tasks::parallel(&scaled_configs, |c| ae_step(run, &data, c))?;
    let scaled = scaled_all
        .iter()
        .min_by(|a, b| {
            let v = |m: &Step<tasks::ModelInfo>| m.value.val_rmse.unwrap_or(f64::INFINITY);
            v(a).total_cmp(&v(b))
        })
        .expect("at least one seed");
    let modes = s.pod_modes.clone();
    let pods = tasks::parallel(&modes, |&k| {
        tasks::pod(run, &format!("iv-b/pod-{k}"), &data, k)
    })?;

    let mut report = new_report(
        Case::IvB,
        "soft beam under an external moment (paper Section IV-B)",
    );
    report.setup = vec![
        "scenario: preset `soft-beam` (`convention = \"total\"`: the magnitude is the pulse's total moment in N·m, as the paper gives it; 0.8 m beam, radius 1.5 cm, E = 1 MPa, follower moment about local y as a triangular pulse of base 0.1 L, no gravity, 50-DOF linear FEM-like bend-y basis, 148 points)".into(),
        format!("data: {} equilibria at random centres in [0, 0.8] m and magnitudes in [−5, 5] N·m, seed 1 (`gvsrom dataset soft-beam --random loads.distributed.0.center=0:0.8 --random loads.distributed.0.magnitude=-5:5 --samples {} --seed 1`); {} solved, {} failed", data.value.samples, data.value.samples, data.value.ok, data.value.failed),
        format!("autoencoders: r = 1, 2, 3 × 3, 5, 7 hidden layers, tanh, λ = 1e-4 against a whole snapshot's squared error (eq. 15), loss in the strain-energy norm, Adam ≤ {} epochs with learning-rate reductions at plateaus of {} epochs ({R1_PATIENCE} at r = 1, whose code improves through long plateaus) and early stopping, then ≤ {} L-BFGS iterations", s.epochs, ae_config(opts, 2, 7).patience, s.lbfgs_iterations),
        format!("POD: {:?} modes", s.pod_modes),
        format!("test: 4 N·m at X/L = 0.25 and 2 N·m at X/L = 0.75 (Fig. 6); each equilibrium solved {} times, mean time", s.repeat),
    ];
    report.tables.push(table_i(
        "table-i",
        "Table I (bottom): RMS reconstruction error over the full dataset",
        &aes,
        &paper::TABLE_I_IV_B,
        "RMS of x̂ − x over every entry of every snapshot, x = bend-y curvature deviation at the 148 points [1/m]. Columns: ours, the paper's, ours / paper.",
    ));
    let unseen = tasks::dataset(
        run,
        "iv-b/dataset-unseen",
        &scenario,
        &DatasetSpec {
            seed: 2,
            ..plan.clone()
        },
        opts.jobs,
    )?;
    let trained = ReducedModel::load(&aes[2][0].path)?;
    let ModelWeights::Autoencoder(trained_ae) = &trained.weights else {
        anyhow::bail!("{}: not an autoencoder", aes[2][0].path.display());
    };
    report.tables.push(iv_b_built::table(
        &data.path,
        &unseen.path,
        trained_ae,
        aes[2][0].value.rmse_full,
        paper::TABLE_I_IV_B[2][0],
    )?);
    let mut models = vec![
        EvalModel::hom(),
        EvalModel::of("AE-2", &aes[2][1]),
        EvalModel::of(SCALED, scaled),
    ];
    for (k, p) in modes.iter().zip(&pods) {
        models.push(EvalModel::of(&format!("POD-{k}"), p));
    }
    let inputs: Vec<Vec<String>> = TEST_LOADS
        .iter()
        .map(|(m, c)| {
            vec![
                format!("loads.distributed.0.magnitude={m}"),
                format!("loads.distributed.0.center={c}"),
            ]
        })
        .collect();
    let ev = statics_eval(run, "iv-b/eval", &scenario, &inputs, &models, s.repeat)?;
    let ev = &ev.value;
    let c = StaticsComparison::of(ev, 2, &modes);
    let (k, pod_k) = (c.pod_k, c.pod_k_label());
    report.tables.push(accuracy_table(ev, &models));
    report.tables.push(c.table_iii(&paper::TABLE_III_IV_B));
    // beyond the paper: five random loads, the AE-2 against POD-2 and POD-k
    let random_models: Vec<EvalModel> = models
        .iter()
        .filter(|m| {
            ["HOM", "AE-2", SCALED, "POD-2"].contains(&m.label.as_str())
                || Some(&m.label) == pod_k.as_ref()
        })
        .cloned()
        .collect();
    let ev_random = statics_eval(
        run,
        "iv-b/eval-random",
        &scenario,
        &random_inputs(),
        &random_models,
        1,
    )?;
    let ev_random = &ev_random.value;
    let mut random_table = accuracy_table(ev_random, &random_models);
    random_table.id = "accuracy-random".into();
    random_table.title = format!("Accuracy at {RANDOM_LOADS} random loads (centre in [0, L], magnitude in [−5, 5] N·m, seed {RANDOM_SEED}; not in the paper)");
    random_table.columns[6] = "time per equilibrium [ms] (one solve)".into();
    report.tables.push(random_table);
    report.tables.push(error_by_magnitude(
        &data.path,
        &aes[2][1],
        scaled,
        &pods[pod_index(&modes, 2)?],
    )?);
    let (ae_rand, ae_rand_max) = ev_random.stats("AE-2", |s| s.strain_error_percent);
    let (pod2_rand, _) = ev_random.stats("POD-2", |s| s.strain_error_percent);
    let (_, scaled_max) = ev.stats(SCALED, |s| s.strain_error_percent);
    let (scaled_rand, scaled_rand_max) = ev_random.stats(SCALED, |s| s.strain_error_percent);
    report.findings = c.findings("the two test loads");
    report.findings.extend([
        Finding {
            claim: format!("the AE-2 ROM stays below 1 % strain error, and below POD-2, at {RANDOM_LOADS} random loads (beyond the paper)"),
            holds: ae_rand_max < 1.0 && ae_rand < pod2_rand,
            evidence: format!(
                "AE-2 mean {} %, largest {} %; POD-2 mean {} %",
                Cell::sig(ae_rand, 3).render(),
                Cell::sig(ae_rand_max, 3).render(),
                Cell::sig(pod2_rand, 3).render()
            ),
        },
        Finding {
            claim: format!("with the scaled decoder x̂ = z₁ D(z) (beyond the paper) the AE-2 ROM stays below 1 % strain error at the two test loads and at {RANDOM_LOADS} random loads, and below POD-2"),
            holds: scaled_max < 1.0 && scaled_rand_max < 1.0 && scaled_rand < pod2_rand,
            evidence: format!(
                "largest strain error {} % at the test loads, {} % at the random loads (mean {} %; POD-2 mean {} %); the seed of lowest validation RMSE of {} (validation RMSE {})",
                Cell::sig(scaled_max, 3).render(),
                Cell::sig(scaled_rand_max, 3).render(),
                Cell::sig(scaled_rand, 3).render(),
                Cell::sig(pod2_rand, 3).render(),
                SCALED_SEEDS.len(),
                SCALED_SEEDS
                    .iter()
                    .zip(&scaled_all)
                    .map(|(s, m)| format!(
                        "seed {s}: {}",
                        Cell::sig(m.value.val_rmse.unwrap_or(f64::NAN), 3).render()
                    ))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        },
    ]);
    let latent = iv_common::latent_and_dimension(
        &data.path,
        &[&aes[0][1], &aes[0][2]],
        &aes[2],
        1,
        "magnitude [N·m]",
    )?;
    report.tables.push(latent.table.clone());
    report.notes = vec![
        "Table I's bottom half is measured in the paper's convention (total moment in N·m); the variant `soft-beam-peak` (`convention = \"peak\"`, the magnitude read as the peak line density) gives 25× smaller strains.".into(),
        format!(
            "Table I at 7 hidden layers, ours / the paper's: r = 1 {}, r = 2 {}, r = 3 {}. The weight penalty weighs against a whole snapshot's squared error, as eq. (15) writes it; against the per-entry mean it is 148× stronger here and held the r = 2 error at 3.9 (docs/assumptions.md). A 1-D code of this 2-D family is a hard, non-convex fit that improves through long plateaus: gvsrom's r = 1 models train with a plateau patience of {R1_PATIENCE} epochs (at 50, 10.4 at 7 hidden layers), and an independent JAX + optax trainer of the same architecture (scripts/ae_reference.py) lands at 10.3 and 11.4 at r = 1 for two seeds, 0.547 at r = 2 and 0.396 at r = 3 (docs/assumptions.md). What limits r = 1 is the encoder: handed a 16-pass fan-shaped code (bins of the angle in the plane of the first two POD coefficients, each pass along the moment), the paper's decoder fits in under a minute to a curve whose nearest point lies 4.74 from the snapshots (4.00 with 24 passes), below the paper's 4.81, but no encoder trained on it resolves the code's steps: 14.6 for the whole autoencoder (scripts/ae_fan_code.py). The architecture can hold the cell: a network of it built by hand, its encoder tearing the family where the strain at a point turns non-zero, reaches 3.05 over the dataset and 3.17 on 5000 unseen snapshots (scripts/ae_constructed_encoder.py), but at weights for which eq. (15)'s penalty is 1e11 times its reconstruction term (that penalty on its output layer alone brings it to 34). No trained r = 1 model reaches the paper's cell.",
            ratio_at_7(&aes, 0),
            ratio_at_7(&aes, 1),
            ratio_at_7(&aes, 2)
        ),
        format!(
            "The AE-2 (7 hidden layers) with the scaled decoder x̂ = z₁ D(z) (beyond the paper; `gvsrom train --decoder scaled`, seeds {}, the lowest validation RMSE kept): RMSE over the full dataset {} against {} for the paper's decoder and the paper's {}. A seed whose z₁ never crosses 0 over the data learns a plain decoder in effect and fits worse; the validation RMSE tells it.",
            SCALED_SEEDS.map(|s| s.to_string()).join(", "),
            Cell::sig(scaled.value.rmse_full, 3).render(),
            Cell::sig(aes[2][1].value.rmse_full, 3).render(),
            paper::TABLE_I_IV_B[2][1]
        ),
        "Times: gvsrom on this machine against the paper's MATLAB: compare the ratios.".into(),
    ];
    report.settings = json!({ "scenario": scenario, "plan": plan, "autoencoders": configs, "scaled_autoencoders": scaled_configs, "pod_modes": modes });
    report.values = json!({
        "table_i": aes.iter().map(|row| row.iter().map(|a| &a.value).collect::<Vec<_>>()).collect::<Vec<_>>(),
        "scaled_ae2": scaled_all.iter().map(|a| &a.value).collect::<Vec<_>>(),
        "pod_k_below_1_percent": k,
        "evaluation": ev,
        "evaluation_random": ev_random,
        "intrinsic_dimension": latent.values,
    });
    let figures = vec![
        fig6(ev, pod_k.as_deref())?,
        figure("fig5-latent", "Fig. 5: latent coordinates of the training samples, AE with r = 2 (left) and r = 3 (right), 3 hidden layers, coloured by the moment's magnitude", &latent.figure, 1400, 620)?,
        figure(
            "scaled-latent",
            "Beyond the paper: the latent coordinates of the training samples under the scaled AE-2 (x̂ = z₁ D(z), 7 hidden layers), coloured by the moment's magnitude (left) and centre (right): z₁ follows the signed magnitude (its sign is the training's choice), z₂ the centre, and the whole line z₁ = 0 decodes to the straight rod",
            &iv_common::latent_plane(
                &data.path,
                scaled,
                "scaled AE-2: latent coordinates of the training samples",
                &[(1, "magnitude [N·m]"), (0, "centre [m]")],
            )?,
            1400,
            620,
        )?,
    ];
    Ok((report, figures))
}

/// Fig. 6: bend-y strain along the beam at the two test loads (HOM, AE-2, POD-2, POD-k) and the
/// configurations of the HOM and the AE-ROM.
fn fig6(ev: &Evaluation, pod_k: Option<&str>) -> anyhow::Result<RenderedFigure> {
    let mut looks = vec![
        ("HOM", palette::HOM, SeriesStyle::Line),
        ("AE-2", palette::AE, SeriesStyle::Dashed),
        ("POD-2", palette::POD, SeriesStyle::Dashed),
    ];
    if let Some(l) = pod_k {
        looks.push((l, palette::POD_ALT, SeriesStyle::Dashed));
    }
    let mut panels: Vec<Figure> = TEST_LOADS
        .iter()
        .enumerate()
        .map(|(i, (m, c))| {
            let title = format!("{m} N·m at X/L = {:.2}", c / 0.8);
            figures::strain_panel(ev, i, "bend_y", "bend-y strain ξ₂ [1/m]", title, &looks)
        })
        .collect();
    panels.push(Figure::Line(figures::configurations(
        ev,
        &[0, 1],
        &looks[..2],
        "configurations at both loads",
    )));
    figure(
        "fig6-strain",
        "Fig. 6: bend-y strain of the HOM, the AE-ROM (r = 2) and POD-ROMs with 2 and k modes (k: the fewest reaching < 1 %) at 4 N·m @ X/L = 0.25 and 2 N·m @ X/L = 0.75, and the configurations (x–z)",
        &Figure::Grid { title: "IV-B: strain profiles and configurations".into(), cols: 3, panels },
        1800,
        600,
    )
}

/// "x.xx×": the RMSE of the 7-hidden-layer AE with latent index `r` (0-based) over the paper's.
fn ratio_at_7(aes: &[Vec<Step<tasks::ModelInfo>>], r: usize) -> String {
    let ours = aes
        .last()
        .and_then(|row| row.get(r))
        .map_or(f64::NAN, |a| a.value.rmse_full);
    let paper = paper::TABLE_I_IV_B.last().map_or(f64::NAN, |row| row[r]);
    format!("{}×", Cell::sig(ours / paper, 3).render())
}
