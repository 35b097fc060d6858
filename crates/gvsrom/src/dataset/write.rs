//! The dataset's arrays, assembled from the samples' rows and written into the output directory.

use super::generate::{
    Generator, Layout, SampleResult, STATUS_FAILED, STATUS_NOT_COMPUTED, STATUS_OK,
};
use super::{Counts, DatasetError, Failure, Meta, FILES, TENDON_LENGTHS_FILE, T_FILE};
use crate::output::OutputDir;

/// Writes the arrays of all samples (missing chunks as not computed) and fills the counts.
pub(super) fn write(
    dir: &mut OutputDir,
    meta: &mut Meta,
    gen: &Generator<'_>,
    results: Vec<Option<Vec<SampleResult>>>,
) -> Result<(), DatasetError> {
    let mut rows = Vec::with_capacity(meta.samples);
    for (c, chunk) in results.into_iter().enumerate() {
        meta.chunk_done[c] = chunk.is_some();
        rows.extend(chunk.unwrap_or_else(|| {
            gen.chunk_range(c)
                .map(|_| SampleResult::missing(gen.layout, STATUS_NOT_COMPUTED, None))
                .collect()
        }));
    }
    write_arrays(dir, meta, gen.layout, gen.values, &rows, None)
}

/// Writes the arrays of `rows` (one per sample, inputs `samples × parameters`; `t` for a dynamic
/// dataset) and fills the counts and failures of `meta`.
pub(crate) fn write_arrays(
    dir: &mut OutputDir,
    meta: &mut Meta,
    layout: &Layout,
    inputs: &[f64],
    rows: &[SampleResult],
    t: Option<&[f64]>,
) -> Result<(), DatasetError> {
    let n = meta.samples;
    let mut strain = Vec::with_capacity(n * layout.row_len());
    let mut q = Vec::with_capacity(n * layout.n_dof);
    let mut tip_position = Vec::with_capacity(3 * n);
    let mut tip_rotation = Vec::with_capacity(9 * n);
    let mut status = Vec::with_capacity(n);
    let mut iterations = Vec::with_capacity(n);
    let mut residual = Vec::with_capacity(n);
    let mut tendon_lengths = Vec::with_capacity(n * layout.n_tendons);
    let mut counts = Counts::default();
    let mut failures = vec![];
    for (k, s) in rows.iter().enumerate() {
        match s.status {
            STATUS_OK => counts.ok += 1,
            STATUS_FAILED => {
                counts.failed += 1;
                failures.push(Failure {
                    index: k,
                    reason: s.reason.clone().unwrap_or_default(),
                });
            }
            _ => counts.not_computed += 1,
        }
        counts.warm_started += s.warm_started as usize;
        strain.extend_from_slice(&s.strain);
        q.extend_from_slice(&s.q);
        tip_position.extend_from_slice(&s.tip_position);
        tip_rotation.extend_from_slice(&s.tip_rotation);
        status.push(s.status);
        iterations.push(s.iterations);
        residual.push(s.residual);
        tendon_lengths.extend_from_slice(&s.tendon_lengths);
    }
    meta.counts = counts;
    // a dataset from one written before the lengths were recorded has none to write
    if rows
        .iter()
        .any(|s| s.tendon_lengths.len() != layout.n_tendons)
    {
        meta.n_tendons = None;
    }
    meta.failures = failures;
    let d = meta.parameters.len();
    let p = layout.strain_x.len();
    (|| -> std::io::Result<()> {
        use crate::npy::{write_array, write_array_of};
        write_array(dir, FILES[0], &[n, d], inputs)?;
        write_array(dir, FILES[1], &[n, layout.row_len()], &strain)?;
        write_array(dir, FILES[2], &[n, layout.n_dof], &q)?;
        write_array(dir, FILES[3], &[n, 3], &tip_position)?;
        write_array(dir, FILES[4], &[n, 3, 3], &tip_rotation)?;
        write_array_of(dir, FILES[5], &[n], &status)?;
        write_array_of(dir, FILES[6], &[n], &iterations)?;
        write_array(dir, FILES[7], &[n], &residual)?;
        write_array(dir, FILES[8], &[p], &layout.strain_x)?;
        if let Some(t) = t {
            write_array(dir, T_FILE, &[n], t)?;
        }
        if meta.n_tendons.is_some() {
            write_array(
                dir,
                TENDON_LENGTHS_FILE,
                &[n, layout.n_tendons],
                &tendon_lengths,
            )?;
        }
        Ok(())
    })()
    .map_err(|e| DatasetError::Output(dir.io_error("write the dataset arrays", e)))
}
