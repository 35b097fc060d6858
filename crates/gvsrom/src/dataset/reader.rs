//! Reading a dataset back: its files are first checked against the hashes recorded when it was
//! written ([`crate::output::verify_dir`]), then every array against `meta.json` (dtype, shape, exact
//! byte length), so an edited, truncated, corrupted or missing file is an error naming the file,
//! never a wrong dataset. Only regular files are opened ([`crate::output::read`]): a FIFO, device or
//! directory in place of a file is refused by name, never waited on.

use super::generate::{STATUS_FAILED, STATUS_NOT_COMPUTED, STATUS_OK};
use super::{DatasetError, Meta, FILES, TENDON_LENGTHS_FILE, T_FILE};
use crate::output::integrity::{recorded_hashes, sha256_hex, Integrity, IntegrityError, Problem};
use std::collections::BTreeMap;
use std::path::Path;

/// The manifest format of a dataset directory.
pub const DATASET_FORMAT: &str = "dataset";

/// A dataset loaded from its directory. Arrays are row-major; see the module documentation of
/// [`crate::dataset`] for the files.
#[derive(Debug, Clone, PartialEq)]
pub struct Dataset {
    pub meta: Meta,
    /// `samples × parameters`.
    pub inputs: Vec<f64>,
    /// `samples × (points · active components)`, point-major; NaN rows for failed samples.
    pub strain: Vec<f64>,
    /// `samples × n_dof`.
    pub q: Vec<f64>,
    /// `samples × 3`.
    pub tip_position: Vec<f64>,
    /// `samples × 3 × 3`.
    pub tip_rotation: Vec<f64>,
    /// 0 ok, 1 failed, 2 not computed (an incomplete dataset).
    pub status: Vec<u8>,
    pub iterations: Vec<u32>,
    pub residual: Vec<f64>,
    pub strain_x: Vec<f64>,
    /// Sample times of a dynamic dataset.
    pub t: Option<Vec<f64>>,
    /// `samples × n_tendons`: the tendons' lengths \[m\] (`None` for a dataset written before they
    /// were recorded).
    pub tendon_lengths: Option<Vec<f64>>,
    /// Whether the files were checked against recorded hashes ([`Integrity::Unhashed`]: a dataset
    /// written before gvsrom recorded them; a front-end may warn).
    pub integrity: Integrity,
    /// The SHA-256 (hex) of the `strain.npy` bytes `strain` was read from: for a checked dataset,
    /// the hash its manifest records. What a model or a noisy copy records of its source.
    pub strain_sha256: String,
    /// Its directory by its manifest's hashes as read (what a model records of its dataset).
    pub origin: crate::provenance::DirOrigin,
    /// meta.json as it was verified: the value `meta` was parsed from (a front-end shows it whole
    /// rather than reading the file a second time).
    pub meta_json: serde_json::Value,
}

fn file_error(file: &str, message: impl Into<String>) -> DatasetError {
    DatasetError::File {
        file: file.into(),
        message: message.into(),
    }
}

/// Reads the arrays of a dataset directory, each file once: the bytes parsed are the bytes hashed.
struct Arrays<'a> {
    dir: &'a Path,
    /// For a checked dataset, the hashes its manifest records: each file read must still have its
    /// own, so a file replaced after [`crate::output::verify_dir`] checked it is refused, not used.
    recorded: Option<BTreeMap<String, String>>,
}

impl Arrays<'_> {
    /// The array `name` ([`crate::npy::parse_checked`]) and the SHA-256 of the bytes it was read
    /// from.
    fn read_hashed<T: npyz::Deserialize>(
        &self,
        name: &str,
        descr: &str,
        shape: &[usize],
    ) -> Result<(Vec<T>, String), DatasetError> {
        let npy = |e: crate::npy::NpyError| file_error(&e.file, e.message);
        let (bytes, shown) = crate::npy::read_file(self.dir, name).map_err(npy)?;
        let sha256 = sha256_hex(&bytes);
        match self.recorded.as_ref().map(|r| r.get(name)) {
            None => {}
            Some(Some(recorded)) if *recorded == sha256 => {}
            Some(Some(_)) => {
                return Err(file_error(
                    &shown,
                    format!(
                        "{}; it changed while the dataset was being read (is another process writing it?)",
                        Problem::Changed
                    ),
                ))
            }
            Some(None) => {
                return Err(file_error(
                    &shown,
                    "meta.json records no hash for it (gvsrom lists and hashes every file of a dataset)",
                ))
            }
        }
        let v = crate::npy::parse_checked(&bytes, &shown, descr, shape).map_err(npy)?;
        Ok((v, sha256))
    }

    /// The array `name`, read as [`Arrays::read_hashed`].
    fn read<T: npyz::Deserialize>(
        &self,
        name: &str,
        descr: &str,
        shape: &[usize],
    ) -> Result<Vec<T>, DatasetError> {
        Ok(self.read_hashed(name, descr, shape)?.0)
    }
}

/// An integrity error as a dataset error. For a file changed since it was written, what reading it
/// finds is added when that fails too (e.g. "truncated"): the hash says *that* it changed, the
/// reader *how*.
fn integrity_error(dir: &Path, e: IntegrityError) -> DatasetError {
    let mut message = e.problem.to_string();
    if matches!(e.problem, Problem::Changed | Problem::MetaEdited) {
        if let Err(found) = Dataset::read_unchecked(dir) {
            message = format!("{message}; as read now: {found}");
        }
    }
    file_error(&e.path.display().to_string(), message)
}

/// Largest ‖RᵀR − I‖_F of a stored tip rotation. A solved tip rotation is a product of exponential
/// maps, each orthogonal to rounding (~1e-16), so its error stays many orders below this; a matrix
/// with an entry changed by more than about 1e-6 is refused.
pub const ROTATION_TOL: f64 = 1e-6;

/// `Ok` if the row-major 3×3 `r` is a rotation: ‖RᵀR − I‖_F ≤ [`ROTATION_TOL`] and det R > 0;
/// otherwise `Err((‖RᵀR − I‖_F, det R))`.
pub fn is_rotation(r: &[f64]) -> Result<(), (f64, f64)> {
    let m = nalgebra::Matrix3::from_row_slice(r);
    let orthogonality = (m.transpose() * m - nalgebra::Matrix3::identity()).norm();
    let det = m.determinant();
    if orthogonality <= ROTATION_TOL && det > 0.0 {
        Ok(())
    } else {
        Err((orthogonality, det))
    }
}

impl Dataset {
    /// Loads and validates the dataset in `dir`: its files against the hashes in its manifest, then
    /// its arrays against `meta.json`.
    pub fn load(dir: &Path) -> Result<Dataset, DatasetError> {
        let verified = crate::output::verify_dir_meta(dir, DATASET_FORMAT)
            .map_err(|e| integrity_error(dir, e))?;
        Dataset::read(dir, verified.integrity, verified.meta)
    }

    /// The dataset in `dir` read as it is now, its integrity unchecked: what a changed file holds.
    fn read_unchecked(dir: &Path) -> Result<Dataset, DatasetError> {
        let meta_path = dir.join(crate::output::MANIFEST_FILE);
        let shown = meta_path.display().to_string();
        let text =
            crate::output::read_regular_to_string(&meta_path).map_err(|e| match e.kind() {
                std::io::ErrorKind::NotFound => {
                    file_error(&shown, "missing (not a gvsrom dataset)")
                }
                _ => file_error(&shown, format!("cannot read it: {e}")),
            })?;
        let value: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| file_error(&shown, format!("not valid JSON: {e}")))?;
        Dataset::read(dir, Integrity::Unhashed, value)
    }

    /// Reads and validates the arrays of the dataset in `dir` described by its meta.json `value`
    /// (its integrity checked or not).
    fn read(
        dir: &Path,
        integrity: Integrity,
        value: serde_json::Value,
    ) -> Result<Dataset, DatasetError> {
        let shown = dir.join(crate::output::MANIFEST_FILE).display().to_string();
        let format = value
            .get(crate::output::MANIFEST_KEY)
            .and_then(|m| m.get("format"))
            .and_then(|f| f.as_str());
        if format != Some(DATASET_FORMAT) {
            return Err(file_error(
                &shown,
                "not a gvsrom dataset (its manifest does not say format \"dataset\")",
            ));
        }
        let arrays = Arrays {
            dir,
            recorded: match integrity {
                Integrity::Checked => Some(recorded_hashes(&value)),
                Integrity::Unhashed => None,
            },
        };
        let origin = crate::provenance::DirOrigin::of_manifest(dir, &value);
        let meta: Meta = serde_json::from_value(value.clone())
            .map_err(|e| file_error(&shown, format!("does not describe a dataset: {e}")))?;
        let kind_ok = match meta.kind.as_str() {
            "statics" => meta.plan.is_some(),
            "dynamics" => meta.dynamic.is_some(),
            _ => false,
        };
        if !kind_ok {
            return Err(file_error(
                &shown,
                format!(
                    "kind `{}` without its plan (expected \"statics\" with `plan` or \"dynamics\" with `dynamic`)",
                    meta.kind
                ),
            ));
        }
        let n = meta.samples;
        let d = meta.parameters.len();
        let p = meta.strain_x.len();
        if meta.components.is_empty() || p == 0 || meta.n_dof == 0 {
            return Err(file_error(
                &shown,
                "no strain components, points or coordinates",
            ));
        }
        let row = p * meta.components.len();
        let f8 = "<f8";
        // in the files' order: the first file found wrong is the one named
        let inputs = arrays.read(FILES[0], f8, &[n, d])?;
        let (strain, strain_sha256) = arrays.read_hashed(FILES[1], f8, &[n, row])?;
        let ds = Dataset {
            inputs,
            strain,
            q: arrays.read(FILES[2], f8, &[n, meta.n_dof])?,
            tip_position: arrays.read(FILES[3], f8, &[n, 3])?,
            tip_rotation: arrays.read(FILES[4], f8, &[n, 3, 3])?,
            status: arrays.read(FILES[5], "|u1", &[n])?,
            iterations: arrays.read(FILES[6], "<u4", &[n])?,
            residual: arrays.read(FILES[7], f8, &[n])?,
            strain_x: arrays.read(FILES[8], f8, &[p])?,
            t: match meta.kind.as_str() {
                "dynamics" => Some(arrays.read(T_FILE, f8, &[n])?),
                _ => None,
            },
            tendon_lengths: match meta.n_tendons {
                Some(na) => Some(arrays.read(TENDON_LENGTHS_FILE, f8, &[n, na])?),
                None => None,
            },
            meta,
            integrity,
            strain_sha256,
            origin,
            meta_json: value,
        };
        ds.check_consistency(dir)?;
        Ok(ds)
    }

    fn check_consistency(&self, dir: &Path) -> Result<(), DatasetError> {
        let at = |f: &str| dir.join(f).display().to_string();
        let m = &self.meta;
        for (j, (a, b)) in self.strain_x.iter().zip(&m.strain_x).enumerate() {
            let close = (a - b).abs() <= 1e-12 * (1.0 + b.abs()); // false for a NaN
            if !close {
                return Err(file_error(
                    &at(FILES[8]),
                    format!(
                        "differs from strain_x in meta.json: point {j} at {a}, meta.json says {b}"
                    ),
                ));
            }
        }
        let mut counts = [0usize; 3];
        for (k, &s) in self.status.iter().enumerate() {
            if s > STATUS_NOT_COMPUTED {
                return Err(file_error(
                    &at(FILES[5]),
                    format!("row {k} has status {s} (accepted: 0 ok, 1 failed, 2 not computed)"),
                ));
            }
            counts[s as usize] += 1;
            let done = m
                .chunk_done
                .get(k / m.chunk_size.max(1))
                .copied()
                .unwrap_or(false);
            if done == (s == STATUS_NOT_COMPUTED) {
                return Err(file_error(
                    &at(FILES[5]),
                    format!("row {k} has status {s}, inconsistent with chunk_done in meta.json"),
                ));
            }
            if s == STATUS_OK {
                self.check_ok_row(dir, k)?;
            }
            // ‖R‖∞ is a norm whatever the status (NaN where nothing was solved)
            let r = self.residual[k];
            if r < 0.0 {
                return Err(file_error(
                    &at(FILES[7]),
                    format!("row {k} holds the residual {r}, a norm ‖R‖∞ (accepted: ≥ 0)"),
                ));
            }
        }
        let c = &m.counts;
        if counts != [c.ok, c.failed, c.not_computed] {
            return Err(file_error(
                &at(FILES[5]),
                format!(
                    "{} ok, {} failed, {} not computed, but meta.json counts {} ok, {} failed, {} not computed",
                    counts[0], counts[1], counts[2], c.ok, c.failed, c.not_computed
                ),
            ));
        }
        if m.chunk_done.len() != m.samples.div_ceil(m.chunk_size.max(1)) {
            return Err(file_error(
                &at(crate::output::MANIFEST_FILE),
                "chunk_done does not have one entry per chunk",
            ));
        }
        Ok(())
    }

    /// The values of the row `k` of status ok: finite strain, inputs, coordinates, tip position and
    /// rotation (and residual of a static dataset, sample time of a dynamic one), and a tip rotation
    /// that is one ([`is_rotation`]).
    fn check_ok_row(&self, dir: &Path, k: usize) -> Result<(), DatasetError> {
        let at = |f: &str| dir.join(f).display().to_string();
        if self.strain_row(k).iter().any(|v| !v.is_finite()) {
            return Err(file_error(
                &at(FILES[1]),
                format!("row {k} has status ok but holds NaN or infinite values"),
            ));
        }
        let d = self.meta.parameters.len();
        if let Some(v) = self.inputs[k * d..(k + 1) * d]
            .iter()
            .find(|v| !v.is_finite())
        {
            return Err(file_error(
                &at(FILES[0]),
                format!("row {k} has status ok but holds the input {v} (expected finite values)"),
            ));
        }
        // a plan's sample lies in its range (a corrupt input would widen what a model built on
        // the dataset records as its training inputs, and so what it answers without a warning)
        let columns = (self.meta.plan.iter()).flat_map(|p| &p.parameters);
        for (p, &v) in columns.zip(&self.inputs[k * d..(k + 1) * d]) {
            let slack = 1e-12 * p.lo.abs().max(p.hi.abs()).max(1.0);
            if !(p.lo - slack..=p.hi + slack).contains(&v) {
                return Err(file_error(
                    &at(FILES[0]),
                    format!(
                        "row {k} holds the input {v} for `{}`, outside the range [{}, {}] of its plan (`{}`): a corrupt sample",
                        p.path, p.lo, p.hi, p.spec
                    ),
                ));
            }
        }
        let n = self.meta.n_dof;
        let rotation = &self.tip_rotation[9 * k..9 * (k + 1)];
        let mut rows: Vec<(&str, &[f64])> = vec![
            (FILES[2], &self.q[k * n..(k + 1) * n]),
            (FILES[3], &self.tip_position[3 * k..3 * (k + 1)]),
            (FILES[4], rotation),
        ];
        match &self.t {
            // a dynamic dataset's samples are not solves: no residual (NaN)
            Some(t) => rows.push((T_FILE, &t[k..=k])),
            None => rows.push((FILES[7], &self.residual[k..=k])),
        }
        for (file, values) in rows {
            if let Some((j, v)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(file_error(
                    &at(file),
                    format!(
                        "row {k} has status ok but holds {v} at index {j} of the row (expected finite values)"
                    ),
                ));
            }
        }
        if let (Some(lengths), Some(na)) = (&self.tendon_lengths, self.meta.n_tendons) {
            let row = &lengths[k * na..(k + 1) * na];
            if let Some((j, v)) = row
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.is_finite() && **v > 0.0))
            {
                return Err(file_error(
                    &at(TENDON_LENGTHS_FILE),
                    format!(
                        "row {k} has status ok but holds the length {v} for tendon {j} (expected a finite length > 0 m)"
                    ),
                ));
            }
        }
        if let Err((orthogonality, det)) = is_rotation(rotation) {
            return Err(file_error(
                &at(FILES[4]),
                format!(
                    "row {k} is not a rotation: ‖RᵀR − I‖_F = {orthogonality:e} (accepted ≤ {ROTATION_TOL:e}), det R = {det} (accepted > 0)"
                ),
            ));
        }
        Ok(())
    }

    pub fn samples(&self) -> usize {
        self.meta.samples
    }

    /// Values per strain row.
    pub fn row_len(&self) -> usize {
        self.strain_x.len() * self.meta.components.len()
    }

    /// The tendons' lengths of sample `k` (`None` for a dataset written before they were recorded).
    pub fn tendon_lengths_row(&self, k: usize) -> Option<&[f64]> {
        let na = self.meta.n_tendons?;
        Some(&self.tendon_lengths.as_ref()?[k * na..(k + 1) * na])
    }

    /// The strain row of sample `k`.
    pub fn strain_row(&self, k: usize) -> &[f64] {
        let r = self.row_len();
        &self.strain[k * r..(k + 1) * r]
    }

    /// Indices of the samples with status ok (the rows to learn from).
    pub fn ok_rows(&self) -> Vec<usize> {
        (0..self.samples())
            .filter(|&k| self.status[k] == STATUS_OK)
            .collect()
    }

    /// One line per sample that is not usable: failed (with its reason) or not computed.
    pub fn problems(&self) -> Vec<String> {
        let mut v = vec![];
        for (k, &s) in self.status.iter().enumerate() {
            if s == STATUS_FAILED {
                let reason = self
                    .meta
                    .failures
                    .iter()
                    .find(|f| f.index == k)
                    .map(|f| f.reason.as_str())
                    .unwrap_or("no reason recorded");
                v.push(format!("sample {k}: failed: {reason}"));
            } else if s == STATUS_NOT_COMPUTED {
                v.push(format!("sample {k}: not computed (incomplete dataset)"));
            }
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use npyz::WriterBuilder;

    /// `dir/a.npy`: the f64 array [1, 2]; returns its bytes.
    fn write_array(dir: &Path) -> Vec<u8> {
        let mut bytes = vec![];
        let mut npy = npyz::WriteOptions::<f64>::new()
            .default_dtype()
            .shape(&[2])
            .writer(&mut bytes)
            .begin_nd()
            .unwrap();
        npy.extend([1.0, 2.0]).unwrap();
        npy.finish().unwrap();
        std::fs::write(dir.join("a.npy"), &bytes).unwrap();
        bytes
    }

    #[test]
    fn an_array_is_used_only_with_the_hash_its_manifest_records() {
        let dir = crate::output::test_util::sandbox("dataset-reader", "hashed");
        let bytes = write_array(&dir);
        // the hash of the bytes written, computed here independently of the reader
        let sha = {
            use sha2::{Digest, Sha256};
            let d = Sha256::digest(&bytes);
            d.iter().map(|b| format!("{b:02x}")).collect::<String>()
        };
        let with = |recorded: Option<&[(&str, &str)]>| Arrays {
            dir: &dir,
            recorded: recorded.map(|r| {
                r.iter()
                    .map(|(f, h)| (f.to_string(), h.to_string()))
                    .collect()
            }),
        };
        // unhashed: read, and its hash given
        let (v, h) = with(None).read_hashed::<f64>("a.npy", "<f8", &[2]).unwrap();
        assert_eq!((v, &h), (vec![1.0, 2.0], &sha));
        // the recorded hash: read
        let (v, h) = with(Some(&[("a.npy", &sha)]))
            .read_hashed::<f64>("a.npy", "<f8", &[2])
            .unwrap();
        assert_eq!((v, h), (vec![1.0, 2.0], sha));
        // another hash recorded (the file replaced after the check): refused, naming the file
        let other = "0".repeat(64);
        let e = with(Some(&[("a.npy", &other)]))
            .read::<f64>("a.npy", "<f8", &[2])
            .unwrap_err()
            .to_string();
        assert!(e.contains("a.npy") && e.contains("changed while"), "{e}");
        // no hash recorded for it in a hashed dataset: refused
        let e = with(Some(&[]))
            .read::<f64>("a.npy", "<f8", &[2])
            .unwrap_err()
            .to_string();
        assert!(e.contains("a.npy") && e.contains("records no hash"), "{e}");
    }
}
