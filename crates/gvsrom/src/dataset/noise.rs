//! A dataset with Gaussian noise on its strain snapshots (paper Section IV-B, last paragraph: the
//! autoencoders "trained on noisy strain data"): `x̃ = x + σ_c n`, `n ~ N(0, 1)` independently per
//! entry, `σ_c = level · RMS(x_c)` for each strain component `c` over its values at every point of
//! every solved sample. Per component, because the components differ by orders of magnitude
//! (bending ~10 1/m, shear and elongation ~1e-4): one σ for all would bury the small ones in noise.
//! Failed and missing rows stay as they are; every other array is copied unchanged, and `meta.json`
//! records the source, its strain hash, the level, the σ_c and the seed.

use super::generate::{Layout, SampleResult};
use super::{Dataset, DatasetError, Meta};
use crate::output::OutputDir;
use gvs::inputs::SplitMix64;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// How a noisy dataset was made (in its `meta.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoiseInfo {
    /// The clean dataset's path and the SHA-256 of the `strain.npy` bytes the noise was added to
    /// (as its manifest records it; 16 hex digits of FNV-1a 64 in datasets made by earlier versions).
    pub source: String,
    pub source_strain_hash: String,
    /// σ relative to the RMS of each component of the clean snapshots.
    pub level: f64,
    /// The absolute standard deviation added to each component (in `components` order), in strain
    /// units.
    pub sigma: Vec<f64>,
    pub seed: u64,
}

/// Standard normal numbers by the Box–Muller transform of a SplitMix64 stream.
struct Normal {
    rng: SplitMix64,
    spare: Option<f64>,
}

impl Normal {
    fn next(&mut self) -> f64 {
        if let Some(v) = self.spare.take() {
            return v;
        }
        // u1 in (0, 1]: ln(u1) is finite
        let u1 = 1.0 - self.rng.uniform();
        let u2 = self.rng.uniform();
        let r = (-2.0 * u1.ln()).sqrt();
        let a = std::f64::consts::TAU * u2;
        self.spare = Some(r * a.sin());
        r * a.cos()
    }
}

/// Writes a copy of the dataset at `src` with noise of relative `level` (≥ 0, finite) on its
/// snapshots, drawn from `seed`, to the new directory `out` (`force`: replace an earlier gvsrom
/// output there).
pub fn with_noise(
    src: &Path,
    level: f64,
    seed: u64,
    out: &Path,
    force: bool,
) -> Result<(PathBuf, NoiseInfo), DatasetError> {
    if !(level.is_finite() && level >= 0.0) {
        return Err(DatasetError::Plan(format!(
            "noise level {level}: expected a finite number ≥ 0 (σ relative to the snapshots' RMS)"
        )));
    }
    let ds = Dataset::load(src)?;
    let ok = ds.ok_rows();
    let width = ds.row_len();
    let a = ds.meta.components.len().max(1);
    let mut sum = vec![0.0; a];
    for &k in &ok {
        for (j, v) in ds.strain_row(k).iter().enumerate() {
            sum[j % a] += v * v;
        }
    }
    let count = (ok.len() * width / a).max(1) as f64;
    let sigma: Vec<f64> = sum.iter().map(|s| level * (s / count).sqrt()).collect();
    let info = NoiseInfo {
        source: src.display().to_string(),
        source_strain_hash: ds.strain_sha256.clone(),
        level,
        sigma: sigma.clone(),
        seed,
    };
    let mut normal = Normal {
        rng: SplitMix64::new(seed),
        spare: None,
    };
    let n_dof = ds.meta.n_dof;
    let rows: Vec<SampleResult> = (0..ds.samples())
        .map(|k| {
            let mut strain = ds.strain_row(k).to_vec();
            if ds.status[k] == super::generate::STATUS_OK {
                for (j, v) in strain.iter_mut().enumerate() {
                    *v += sigma[j % a] * normal.next();
                }
            }
            let mut tip_rotation = [0.0; 9];
            tip_rotation.copy_from_slice(&ds.tip_rotation[9 * k..9 * k + 9]);
            SampleResult {
                status: ds.status[k],
                strain,
                q: ds.q[k * n_dof..(k + 1) * n_dof].to_vec(),
                tip_position: [
                    ds.tip_position[3 * k],
                    ds.tip_position[3 * k + 1],
                    ds.tip_position[3 * k + 2],
                ],
                tip_rotation,
                tendon_lengths: ds
                    .tendon_lengths_row(k)
                    .map_or_else(Vec::new, <[f64]>::to_vec),
                iterations: ds.iterations[k],
                residual: ds.residual[k],
                warm_started: false,
                reason: ds
                    .meta
                    .failures
                    .iter()
                    .find(|f| f.index == k)
                    .map(|f| f.reason.clone()),
            }
        })
        .collect();
    let layout = Layout {
        n_dof,
        strain_x: ds.strain_x.clone(),
        active: ds
            .meta
            .components
            .iter()
            .map(|c| {
                crate::scenario::StrainMode::ALL
                    .iter()
                    .position(|m| m.name() == c)
                    .unwrap_or(0)
            })
            .collect(),
        n_tendons: ds.meta.n_tendons.unwrap_or(0),
    };
    let mut meta: Meta = ds.meta.clone();
    meta.noise = Some(info.clone());
    meta.counts.warm_started = 0;
    let mut dir = OutputDir::create("--out", out, "dataset", force)?;
    super::write::write_arrays(
        &mut dir,
        &mut meta,
        &layout,
        &ds.inputs,
        &rows,
        ds.t.as_deref(),
    )?;
    let path = dir.commit(&meta)?;
    Ok((path, info))
}
