//! A reduced model as a map between strain snapshots and reduced coordinates, for inspecting what
//! a model learned outside any simulation: `q = E(x)`, `x̂ = D(q)` and `x̂ = D(E(x))` on rows of
//! snapshots in a dataset's layout (`ξ − ξ*` of the active components, point-major, the
//! [`ModelLayout`](super::ModelLayout)).
//!
//! - POD: `E(x) = Vᵀ x`, `D(q) = V q` (orthonormal modes `V`, L × r).
//! - Autoencoder: its encoder and decoder, with the data scaling (`D(z) = s ⊙ dec(z) + μ`, times
//!   `z₁` for the scaled decoder form).
//!
//! A code far outside the training encodings (by more than half the range's width in some
//! coordinate, as a reduced solve is refused) is refused unless `extrapolate` is set: there a
//! decoder's tanh layers saturate and its answer is not to be trusted, and an encoding that lands
//! there says the snapshot is unlike the training data.

use super::{ModelWeights, ReducedModel};
use thiserror::Error;

/// Why an encoding or a decoding was refused. Each message names the argument, the offending
/// value and what is accepted.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CodecError {
    #[error("`{name}` is empty: give at least one row ({what})")]
    Empty {
        name: &'static str,
        what: &'static str,
    },
    #[error("`{name}` holds {len} values, not a whole number of rows of {row} ({what})")]
    Shape {
        name: &'static str,
        len: usize,
        row: usize,
        what: &'static str,
    },
    #[error("`{name}` row {row}, entry {index} is {value}: the values must be finite")]
    NotFinite {
        name: &'static str,
        row: usize,
        index: usize,
        value: f64,
    },
    #[error("{0}")]
    OutsideRange(String),
    #[error("the autoencoder refused the data: {0}")]
    Network(String),
}

/// How many times the largest training snapshot's norm an encoding accepts (unless `extrapolate`):
/// a tanh encoder saturates on a larger snapshot and returns a code inside its training range, so
/// the code alone cannot tell (an autoencoder of IV-A encoded 1000× a training snapshot, and a
/// snapshot of 1e300 everywhere, to ordinary codes).
pub const SNAPSHOT_NORM_MARGIN: f64 = 2.0;

/// The Euclidean norm of a snapshot, scaled by its largest entry first so that entries of 1e200
/// do not overflow it (NaN for a non-finite entry).
pub fn row_norm(x: &[f64]) -> f64 {
    if x.iter().any(|v| !v.is_finite()) {
        return f64::NAN;
    }
    let big = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    match big > 0.0 {
        true => big * x.iter().map(|v| (v / big) * (v / big)).sum::<f64>().sqrt(),
        false => 0.0,
    }
}

/// The first row of the row-major snapshots `x` whose norm exceeds [`SNAPSHOT_NORM_MARGIN`] ×
/// `largest` (or is not finite), with that norm; `None` without a recorded `largest`.
pub fn oversized_row(largest: Option<f64>, x: &[f64], features: usize) -> Option<(usize, f64)> {
    let largest = largest?;
    (x.chunks_exact(features).enumerate())
        .map(|(row, v)| (row, row_norm(v)))
        .find(|(_, n)| n.is_nan() || *n > SNAPSHOT_NORM_MARGIN * largest)
}

/// The first coordinate of `q` outside `range` widened by half its width on each side (or not
/// finite); `None` if every coordinate lies inside (always, for an empty range: a model written
/// before ranges were recorded).
pub fn outside_range(range: &[[f64; 2]], q: &[f64]) -> Option<usize> {
    q.iter().zip(range).position(|(v, [lo, hi])| {
        let margin = 0.5 * (hi - lo).max(1e-12);
        !(*v >= lo - margin && *v <= hi + margin)
    })
}

/// Checks that `data` is a whole, non-empty number of rows of `row` values, all finite.
fn check_rows(
    name: &'static str,
    data: &[f64],
    row: usize,
    what: &'static str,
) -> Result<(), CodecError> {
    if data.is_empty() {
        return Err(CodecError::Empty { name, what });
    }
    if row == 0 || !data.len().is_multiple_of(row) {
        return Err(CodecError::Shape {
            name,
            len: data.len(),
            row,
            what,
        });
    }
    if let Some(i) = data.iter().position(|v| !v.is_finite()) {
        return Err(CodecError::NotFinite {
            name,
            row: i / row,
            index: i % row,
            value: data[i],
        });
    }
    Ok(())
}

impl ReducedModel {
    /// Values of one snapshot: points × active components ([`super::ModelLayout::features`]).
    pub fn features(&self) -> usize {
        self.meta.layout.features()
    }

    /// `q = E(x)` for the row-major snapshots `x` (`rows × features` → `rows × r`). Unless
    /// `extrapolate`, refuses a snapshot whose code lies far outside the training encodings.
    pub fn encode(&self, x: &[f64], extrapolate: bool) -> Result<Vec<f64>, CodecError> {
        let n = self.features();
        check_rows("strain", x, n, "snapshots of the model's layout")?;
        if !extrapolate {
            if let Some((row, norm)) = oversized_row(self.meta.snapshot_norm_max, x, n) {
                let largest = self.meta.snapshot_norm_max.unwrap_or(0.0);
                return Err(CodecError::OutsideRange(format!(
                    "row {row}: the snapshot's norm ‖x‖ = {} is {}× the largest training snapshot's ({}): the snapshot is unlike the training data, and an encoder saturates on it; accepted: ‖x‖ ≤ {SNAPSHOT_NORM_MARGIN} × that, or --extrapolate",
                    gvs::error::fmt_value(norm),
                    gvs::error::fmt_value(norm / largest),
                    gvs::error::fmt_value(largest),
                )));
            }
        }
        let q = match &self.weights {
            ModelWeights::Pod {
                modes,
                norm_weights,
                ..
            } => rom::pod::project_rows(modes, norm_weights.as_deref(), x),
            ModelWeights::Autoencoder(ae) => ae
                .encode(x)
                .map_err(|e| CodecError::Network(e.to_string()))?,
        };
        if !extrapolate {
            self.check_codes(&q, "the snapshot is unlike the training data")?;
        }
        Ok(q)
    }

    /// `x̂ = D(q)` for the row-major codes `q` (`rows × r` → `rows × features`). Unless
    /// `extrapolate`, refuses a code far outside the training encodings.
    pub fn decode(&self, q: &[f64], extrapolate: bool) -> Result<Vec<f64>, CodecError> {
        let (n, r) = (self.features(), self.meta.latent);
        check_rows("q", q, r, "reduced coordinates of the model")?;
        if !extrapolate {
            self.check_codes(q, "the decoder has no data there")?;
        }
        match &self.weights {
            ModelWeights::Pod { modes, .. } => Ok(q
                .chunks_exact(r)
                .flat_map(|z| {
                    (0..n).map(move |i| (0..r).map(|k| modes[(i, k)] * z[k]).sum::<f64>())
                })
                .collect()),
            ModelWeights::Autoencoder(ae) => {
                ae.decode(q).map_err(|e| CodecError::Network(e.to_string()))
            }
        }
    }

    /// `x̂ = D(E(x))`: the model's reconstruction of each snapshot (Table I's `x̂`).
    pub fn reconstruct(&self, x: &[f64], extrapolate: bool) -> Result<Vec<f64>, CodecError> {
        self.decode(&self.encode(x, extrapolate)?, extrapolate)
    }

    /// Refuses the first row of codes `q` far outside the training encodings, saying `why`.
    fn check_codes(&self, q: &[f64], why: &str) -> Result<(), CodecError> {
        let (r, range) = (self.meta.latent, &self.meta.latent_range);
        for (row, z) in q.chunks_exact(r).enumerate() {
            if let Some(d) = outside_range(range, z) {
                let [lo, hi] = range[d];
                return Err(CodecError::OutsideRange(format!(
                    "row {row}: q_r[{d}] = {} lies far outside the range of the training encodings [{lo:.6}, {hi:.6}] ({why}); accepted: within half the range's width of it, or --extrapolate",
                    gvs::error::fmt_value(z[d])
                )));
            }
        }
        Ok(())
    }
}
