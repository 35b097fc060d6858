//! Latent spaces of trained autoencoders: the encodings of a dataset's samples, their projection on
//! principal components and how evenly they fill their bounding box (Figs. 3, 5 and 8).

use crate::dataset::Dataset;
use crate::reduced_model::{ModelWeights, ReducedModel};
use std::path::Path;

/// The encodings `E(x)` of every solved sample of the dataset at `data` by the autoencoder at
/// `model`.
pub fn encodings(data: &Path, model: &Path) -> anyhow::Result<Vec<Vec<f64>>> {
    let ds = Dataset::load(data)?;
    let m = ReducedModel::load(model)?;
    let ModelWeights::Autoencoder(ae) = &m.weights else {
        anyhow::bail!("`{}` is not an autoencoder", model.display());
    };
    ds.ok_rows()
        .into_iter()
        .map(|i| Ok(ae.encode(ds.strain_row(i))?))
        .collect()
}

/// The codes `z_i` on their first three principal components, `p_i = Vₖᵀ (z_i − z̄)`, k = 1 … 3,
/// from the SVD `Z − 1 z̄ᵀ = U Σ Vᵀ` (singular values sorted here, descending), and the share of
/// the variance they carry, `(σ₁² + σ₂² + σ₃²) / Σ σ²`.
pub fn principal_components(z: &[Vec<f64>]) -> anyhow::Result<(Vec<[f64; 3]>, f64)> {
    let n = z.len();
    let d = z.first().map_or(0, Vec::len);
    anyhow::ensure!(
        n >= 3 && d >= 3,
        "{n} codes of size {d}: too few for three principal components"
    );
    let mean: Vec<f64> = (0..d)
        .map(|j| z.iter().map(|r| r[j]).sum::<f64>() / n as f64)
        .collect();
    let c = nalgebra::DMatrix::from_fn(n, d, |i, j| z[i][j] - mean[j]);
    let svd = c.clone().svd(false, true);
    let v_t = svd
        .v_t
        .ok_or_else(|| anyhow::anyhow!("the SVD of the codes gave no right singular vectors"))?;
    let sv = &svd.singular_values;
    let mut order: Vec<usize> = (0..sv.len()).collect();
    order.sort_by(|&a, &b| sv[b].total_cmp(&sv[a]));
    let total: f64 = sv.iter().map(|s| s * s).sum();
    let explained = order[..3].iter().map(|&k| sv[k] * sv[k]).sum::<f64>() / total;
    let pcs = (0..n)
        .map(|i| {
            std::array::from_fn(|a| {
                let k = order[a];
                (0..d).map(|j| c[(i, j)] * v_t[(k, j)]).sum()
            })
        })
        .collect();
    Ok((pcs, explained))
}

/// The share of the `bins³` cells of the points' bounding box that hold at least one point.
pub fn occupied_fraction(p: &[[f64; 3]], bins: usize) -> f64 {
    let lo: [f64; 3] = std::array::from_fn(|a| p.iter().map(|x| x[a]).fold(f64::MAX, f64::min));
    let hi: [f64; 3] = std::array::from_fn(|a| p.iter().map(|x| x[a]).fold(f64::MIN, f64::max));
    let mut occupied = vec![false; bins.pow(3)];
    for x in p {
        let cell: [usize; 3] = std::array::from_fn(|a| {
            let w = hi[a] - lo[a];
            let f = if w > 0.0 { (x[a] - lo[a]) / w } else { 0.0 };
            ((f * bins as f64) as usize).min(bins - 1)
        });
        occupied[(cell[0] * bins + cell[1]) * bins + cell[2]] = true;
    }
    occupied.iter().filter(|&&o| o).count() as f64 / occupied.len() as f64
}
