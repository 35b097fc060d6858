//! A trajectory directory written by `gvsrom simulate --out`, read for a comparison.

use crate::error::ScenarioError;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The reference strain `ξ* = [0, 0, 0, 1, 0, 0]` of the straight, unstretched rod: what a result
/// written before gvsrom recorded `strain_reference` was measured from (pre-strained rods came
/// later).
pub const STRAIGHT_STRAIN: [f64; 6] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0];

/// A trajectory directory written by `gvsrom simulate --out`.
#[derive(Debug, Clone)]
pub struct Trajectory {
    pub dir: PathBuf,
    /// `dir` by its manifest's hashes as read (what `compare` records of it).
    pub origin: crate::provenance::DirOrigin,
    pub scenario: String,
    pub n_dof: usize,
    pub complete: bool,
    pub wall_time_s: f64,
    /// Rod length \[m\].
    pub length: f64,
    pub t: Vec<f64>,
    /// `samples × 3`.
    pub tip: Vec<f64>,
    /// `samples × points × 6`: `ξ` at the computational points.
    pub strain: Vec<f64>,
    pub strain_x: Vec<f64>,
    /// `points × 6`: the reference strain `ξ*` at the computational points
    /// (`strain_reference.npy`; [`STRAIGHT_STRAIN`] at every point for a trajectory that does not
    /// record it).
    pub strain_reference: Vec<f64>,
    /// The requested end time (`t_requested`), if recorded.
    pub t_requested: Option<f64>,
    /// Output samples per second (`sample_rate`), if recorded.
    pub sample_rate: Option<f64>,
    /// The input record (`input`), if recorded.
    pub input: Option<Value>,
    /// The physics record (`physics`), if recorded.
    pub physics: Option<Value>,
    /// Abscissae of the centreline samples \[m\] (`centerline_x`; trajectories written before the
    /// centreline was recorded have none).
    pub centerline_x: Option<Vec<f64>>,
    /// `samples × centerline_x.len() × 3`: the centreline positions \[m\] (`centerline.npy`), with
    /// `centerline_x`.
    pub centerline: Option<Vec<f64>>,
    /// `samples × tendons × centerline_x.len() × 3`: each tendon's thread \[m\]
    /// (`tendon_paths.npy`; with tendons, in trajectories written since it was recorded), and the
    /// number of tendons.
    pub tendon_paths: Option<(usize, Vec<f64>)>,
    /// `samples × tendons`: each tendon's length \[m\] (`tendon_lengths.npy`; with tendons, in
    /// trajectories written since it was recorded), and the number of tendons.
    pub tendon_lengths: Option<(usize, Vec<f64>)>,
    /// `samples × bodies × 2 × 3`: each rigid body's section and centre of mass \[m\]
    /// (`body_positions.npy`; with bodies, in trajectories written since it was recorded), and
    /// the number of bodies.
    pub body_positions: Option<(usize, Vec<f64>)>,
    /// `samples × tendons`: each tendon's tension \[N\] at the samples (`u.npy`), and the number
    /// of tendons (`None` without tendons).
    pub tensions: Option<(usize, Vec<f64>)>,
    /// Each tendon's length at rest \[m\] (`meta.json`'s `tendon_rest_lengths`; empty when not
    /// recorded).
    pub tendon_rest_lengths: Vec<f64>,
    /// How the run was made (`provenance`), if recorded.
    pub provenance: Option<Value>,
    /// How its reduced model was used outside what it was trained on (`model_extrapolated`,
    /// `simulate --model … --extrapolate`); empty for a model used inside it, or no model.
    pub extrapolated: Vec<String>,
}

impl Trajectory {
    /// Loads and checks the trajectory in `dir`; `field` names it in errors (`REFERENCE`, `RUN`).
    pub fn load(dir: &Path, field: &str) -> Result<Trajectory, ScenarioError> {
        let bad = |message: String| ScenarioError::invalid(field, message);
        let meta_path = dir.join("meta.json");
        let text = crate::output::read::read_regular_to_string(&meta_path)
            .map_err(|e| bad(format!("cannot read {}: {e}", meta_path.display())))?;
        let meta: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| bad(format!("{} is not valid JSON: {e}", meta_path.display())))?;
        if meta["gvsrom"]["format"] != "trajectory" {
            return Err(bad(format!(
                "{} is not a trajectory (a directory written by `gvsrom simulate --out`)",
                dir.display()
            )));
        }
        // its files as written (an older trajectory without hashes is read unchecked), and its
        // meta.json as it was checked
        let crate::output::Verified { meta, files, .. } =
            crate::output::verify_dir_meta(dir, "trajectory").map_err(|e| {
                bad(format!(
                    "{e}; an edited trajectory is not the run that was simulated"
                ))
            })?;
        let origin = crate::provenance::DirOrigin::of_manifest(dir, &meta);
        let count = |key: &str| {
            meta[key]
                .as_u64()
                .map(|v| v as usize)
                .ok_or_else(|| bad(format!("{}: `{key}` is missing", meta_path.display())))
        };
        let (n, points) = (count("samples")?, count("n_points")?);
        let f8 = "<f8";
        let read = |name: &str, shape: &[usize]| {
            // the bytes parsed are the bytes whose hash is checked
            let bytes = files.read(name).map_err(|e| bad(e.to_string()))?;
            let shown = dir.join(name).display().to_string();
            let v = crate::npy::parse_checked::<f64>(&bytes, &shown, f8, shape)
                .map_err(|e| bad(e.to_string()))?;
            match v.iter().position(|x| !x.is_finite()) {
                Some(i) => Err(bad(format!(
                    "{}: entry {i} is {}, not a finite number",
                    dir.join(name).display(),
                    v[i]
                ))),
                None => Ok(v),
            }
        };
        let strain_x = read("strain_x.npy", &[points])?;
        let strain_reference = if files.lists("strain_reference.npy") {
            read("strain_reference.npy", &[points, 6])?
        } else {
            STRAIGHT_STRAIN.repeat(points)
        };
        let length = match meta["length"].as_f64() {
            Some(l) => l,
            None => *strain_x.last().unwrap_or(&0.0),
        };
        if !(length > 0.0 && length.is_finite()) {
            return Err(bad(format!(
                "{}: rod length {length} (expected > 0)",
                meta_path.display()
            )));
        }
        let centerline_x = match meta.get("centerline_x") {
            None => None,
            Some(v) => Some(
                serde_json::from_value::<Vec<f64>>(v.clone())
                    .ok()
                    .filter(|x| x.len() >= 2 && x.iter().all(|x| x.is_finite()))
                    .ok_or_else(|| {
                        bad(format!(
                            "{}: `centerline_x` is not a list of at least 2 finite numbers",
                            meta_path.display()
                        ))
                    })?,
            ),
        };
        let centerline = match &centerline_x {
            Some(x) => Some(read("centerline.npy", &[n, x.len(), 3])?),
            None => None,
        };
        let file = crate::simulate::TENDON_PATHS_FILE;
        let tendon_paths = match (&centerline_x, files.lists(file)) {
            (Some(x), true) => {
                let na = count("n_actuators")?;
                Some((na, read(file, &[n, na, x.len(), 3])?))
            }
            _ => None,
        };
        let file = crate::simulate::TENDON_LENGTHS_FILE;
        let tendon_lengths = match files.lists(file) {
            true => {
                let na = count("n_actuators")?;
                Some((na, read(file, &[n, na])?))
            }
            false => None,
        };
        let file = crate::simulate::BODY_POSITIONS_FILE;
        let body_positions = match files.lists(file) {
            true => {
                let nb = count("n_bodies")?;
                Some((nb, read(file, &[n, nb, 2, 3])?))
            }
            false => None,
        };
        let tensions = match (count("n_actuators"), files.lists("u.npy")) {
            (Ok(na), true) if na > 0 => Some((na, read("u.npy", &[n, na])?)),
            _ => None,
        };
        Ok(Trajectory {
            dir: dir.to_path_buf(),
            origin,
            scenario: meta["scenario"].as_str().unwrap_or("?").to_string(),
            n_dof: count("n_dof")?,
            complete: meta["complete"].as_bool().unwrap_or(false),
            wall_time_s: meta["wall_time_s"].as_f64().unwrap_or(f64::NAN),
            length,
            t: read("t.npy", &[n])?,
            tip: read("tip_position.npy", &[n, 3])?,
            strain: read("strain.npy", &[n, points, 6])?,
            strain_x,
            strain_reference,
            t_requested: meta["t_requested"].as_f64(),
            sample_rate: meta["sample_rate"].as_f64(),
            input: meta.get("input").filter(|v| v.is_object()).cloned(),
            physics: meta.get("physics").filter(|v| v.is_object()).cloned(),
            centerline_x,
            centerline,
            tendon_paths,
            tendon_lengths,
            body_positions,
            tensions,
            tendon_rest_lengths: (meta["tendon_rest_lengths"].as_array().into_iter().flatten())
                .filter_map(|v| v.as_f64())
                .collect(),
            provenance: meta.get("provenance").filter(|v| v.is_object()).cloned(),
            extrapolated: (meta["model_extrapolated"].as_array().into_iter().flatten())
                .filter_map(|v| v.as_str().map(str::to_string))
                .collect(),
        })
    }

    pub fn samples(&self) -> usize {
        self.t.len()
    }

    /// The strain deviation `ξ − ξ*` of component `c` at point `j` in sample `k`.
    pub fn deviation(&self, k: usize, j: usize, c: usize) -> f64 {
        let p = self.strain_x.len();
        self.strain[(k * p + j) * 6 + c] - self.strain_reference[j * 6 + c]
    }
}
