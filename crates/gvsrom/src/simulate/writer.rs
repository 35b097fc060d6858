//! A trajectory written to a directory sample by sample ([`TrajectoryWriter`], [`run`],
//! [`run_to_dir`]): the files of the module documentation, staged and moved into place.

use super::centerline::*;
use super::options::*;
use super::plan::*;
use super::run::*;
use crate::build::Built;
use crate::error::ScenarioError;
use crate::npy::NpyRows;
use crate::output::{OutputDir, OutputError};
use gvs::solve::dynamics::{IntegratorOptions, Sample};
use serde::Serialize;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

/// The file of per-sample tendon paths in a trajectory: `[samples, tendons, c, 3]`, each tendon's
/// thread at the centreline abscissae clamped to its span (written only with tendons).
pub const TENDON_PATHS_FILE: &str = "tendon_paths.npy";

/// The file of per-sample tendon lengths in a trajectory: `[samples, tendons]` \[m\]
/// ([`gvs::model::Model::tendon_lengths`]; written only with tendons, their rest lengths in
/// `meta.json`'s `tendon_rest_lengths`).
pub const TENDON_LENGTHS_FILE: &str = "tendon_lengths.npy";

/// The file of per-sample rigid-body positions in a trajectory: `[samples, bodies, 2, 3]`, each
/// body's section and centre of mass \[m\] (written only with `[[bodies]]`).
pub const BODY_POSITIONS_FILE: &str = "body_positions.npy";

/// Largest trajectory one run writes \[bytes\] (16 GiB).
pub const MAX_OUTPUT_BYTES: f64 = 16.0 * 1024.0 * 1024.0 * 1024.0;

/// The scenario's physics as `meta.json` records it (`"physics"`), for `gvsrom compare`: the
/// material, the divisions' geometry, the base pose, the tendons' routing and friction, and the
/// loads (gravity, point and distributed wrenches), and the rigid bodies where there are. Not the tensions (the input), not the strain
/// basis nor the computational points (the discretization, which a reduced model replaces).
pub(super) fn physics_record(built: &Built) -> serde_json::Value {
    let m = &built.model;
    let rot: Vec<[f64; 3]> = (0..3)
        .map(|i| [m.base.rot[(i, 0)], m.base.rot[(i, 1)], m.base.rot[(i, 2)]])
        .collect();
    let mut record = serde_json::json!({
        "material": m.rod.material,
        "divisions": m.rod.divisions,
        "base": {"position": [m.base.pos[0], m.base.pos[1], m.base.pos[2]], "rotation": rot},
        "tendons": m.tendons,
        "loads": built.loads,
    });
    // only with bodies, so that the record of a run without is that of a run before they existed
    let bodies: Vec<_> = m.bodies().collect();
    if !bodies.is_empty() {
        record["bodies"] = serde_json::json!(bodies);
    }
    record
}

/// Runs the planned simulation, streaming each sample to `writer` (if any) and calling
/// `control(t)` after each and before every step attempt of the integrator (with `t` the last
/// sample's time): returning `ControlFlow::Break(reason)` interrupts the run within one step (the
/// samples so far are kept), however far the next sample is. A failed write stops the run with an
/// error.
pub fn run(
    built: &Built,
    plan: &Plan,
    integrator: &IntegratorOptions,
    writer: Option<&mut TrajectoryWriter>,
    control: &mut dyn FnMut(f64) -> ControlFlow<String>,
) -> Result<Outcome, ScenarioError> {
    let sink = writer.map(|w| w as &mut dyn SampleSink);
    run_into(built, plan, integrator, sink, control)
}

impl SampleSink for TrajectoryWriter {
    fn push(&mut self, built: &Built, s: &Sample<'_>) -> std::io::Result<()> {
        TrajectoryWriter::push(self, built, s)
    }
}

/// The displacements \[m\] the motors were commanded, one per tendon per sample (NaN for a
/// tendon driven by its tension): written only when a tendon is driven by its displacement, whose
/// tension `u.npy` holds as found from its thread's stretch.
pub const DISPLACEMENT_FILE: &str = "displacement.npy";

/// The commanded displacement of each tendon `driven` at the sample `s` (NaN for the others).
pub fn commanded<'s>(driven: &'s [bool], s: &'s Sample<'_>) -> impl Iterator<Item = f64> + 's {
    (driven.iter().zip(s.input)).map(|(&d, &v)| if d { v } else { f64::NAN })
}

/// Why [`run_to_dir`] could not run or write a trajectory.
#[derive(Debug, thiserror::Error)]
pub enum TrajectoryError {
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// A run written to a trajectory directory by [`run_to_dir`].
#[derive(Debug)]
pub struct Written {
    pub outcome: Outcome,
    /// The trajectory directory, in place.
    pub dir: PathBuf,
    /// Samples written.
    pub samples: usize,
}

/// `gvsrom simulate … --out DIR` without the printing: plans the run ([`plan`], the output size),
/// stages the trajectory at `out` (`force`: replacing an earlier gvsrom output there), runs it
/// ([`run`], `control` as there) and moves it into place. A run that ended early is written too,
/// marked partial; `outcome.ending` says why. `provenance` (without the input and sampling, which
/// are added here) is recorded in `meta.json`.
pub fn run_to_dir(
    built: &Built,
    opts: &SimulateOptions,
    out: &Path,
    force: bool,
    provenance: Option<crate::provenance::Provenance>,
    control: &mut dyn FnMut(f64) -> ControlFlow<String>,
) -> Result<Written, TrajectoryError> {
    let plan = plan(built, opts)?;
    check_output_size(built, &plan)?;
    let mut writer = TrajectoryWriter::create(out, force, built)?;
    if let Some(p) = provenance {
        let p = p
            .input(plan.input.clone())
            .sampling(opts.duration, opts.sample_rate);
        writer.set_provenance(&p);
    }
    let outcome = run(built, &plan, &opts.integrator, Some(&mut writer), control)?;
    let samples = writer.samples();
    let dir = writer.finish(built, &plan, &outcome)?;
    Ok(Written {
        outcome,
        dir,
        samples,
    })
}

/// Bytes written per sample: `t`, `q`, `q̇`, `u`, tip position and rotation, strains, centreline,
/// tendon paths and lengths (f64 each).
pub(super) fn bytes_per_sample(built: &Built) -> f64 {
    let m = &built.model;
    let c = built.centerline_points.max(2);
    let (na, np) = (m.n_actuators(), m.disc.n_points());
    8.0 * (1 + 2 * built.n_dof() + 2 * na + 3 + 9 + 6 * np + 3 * c * (1 + na)) as f64
}

/// Refuses a trajectory larger than [`MAX_OUTPUT_BYTES`] before anything is computed.
pub fn check_output_size(built: &Built, plan: &Plan) -> Result<(), ScenarioError> {
    let bytes = plan.t_out.len() as f64 * bytes_per_sample(built);
    if bytes > MAX_OUTPUT_BYTES {
        return Err(ScenarioError::invalid(
            "--out",
            format!(
                "the trajectory would take {:.1} GB ({} samples of {} kB; accepted <= {:.1} GB); lower --duration or --sample-rate",
                bytes / 1e9,
                plan.t_out.len(),
                bytes_per_sample(built) / 1e3,
                MAX_OUTPUT_BYTES / 1e9
            ),
        ));
    }
    Ok(())
}

/// A trajectory being written sample by sample into an output directory (see the module
/// documentation for the files). Memory does not depend on the number of samples.
pub struct TrajectoryWriter {
    dir: OutputDir,
    t: NpyRows,
    q: NpyRows,
    qd: NpyRows,
    u: NpyRows,
    tip_position: NpyRows,
    tip_rotation: NpyRows,
    strain: NpyRows,
    centerline: NpyRows,
    /// `tendon_paths.npy` and `tendon_lengths.npy`, with tendons only.
    tendon_paths: Option<(NpyRows, NpyRows)>,
    /// `body_positions.npy`, with bodies only.
    body_positions: Option<NpyRows>,
    /// `displacement.npy`, with a tendon driven by its displacement only.
    displacement: Option<NpyRows>,
    /// Per tendon, whether it is driven by its displacement.
    driven: Vec<bool>,
    shape: Centerline,
    provenance: Option<serde_json::Value>,
}

impl TrajectoryWriter {
    /// Opens the output directory `path` (refusing unsafe targets, see [`crate::output`]) and the
    /// arrays, before the run starts.
    pub fn create(path: &Path, force: bool, built: &Built) -> Result<Self, OutputError> {
        let mut dir = OutputDir::create("--out", path, "trajectory", force)?;
        let m = &built.model;
        let (n, na, np) = (built.n_dof(), m.n_actuators(), m.disc.n_points());
        let shape = Centerline::new(built);
        let nc = shape.x.len();
        let open = |dir: &mut OutputDir| -> std::io::Result<_> {
            Ok((
                NpyRows::new(dir, "t.npy", &[])?,
                NpyRows::new(dir, "q.npy", &[n])?,
                NpyRows::new(dir, "qd.npy", &[n])?,
                NpyRows::new(dir, "u.npy", &[na])?,
                NpyRows::new(dir, "tip_position.npy", &[3])?,
                NpyRows::new(dir, "tip_rotation.npy", &[3, 3])?,
                NpyRows::new(dir, "strain.npy", &[np, 6])?,
                NpyRows::new(dir, "centerline.npy", &[nc, 3])?,
            ))
        };
        let (t, q, qd, u, tip_position, tip_rotation, strain, centerline) =
            open(&mut dir).map_err(|e| dir.io_error("create the trajectory files", e))?;
        let tendons = |dir: &mut OutputDir| -> std::io::Result<_> {
            Ok((
                NpyRows::new(dir, TENDON_PATHS_FILE, &[na, nc, 3])?,
                NpyRows::new(dir, TENDON_LENGTHS_FILE, &[na])?,
            ))
        };
        let tendon_paths = match na {
            0 => None,
            _ => Some(
                tendons(&mut dir).map_err(|e| dir.io_error("create the trajectory files", e))?,
            ),
        };
        let nb = m.bodies().len();
        let body_positions = match nb {
            0 => None,
            _ => Some(
                NpyRows::new(&mut dir, BODY_POSITIONS_FILE, &[nb, 2, 3])
                    .map_err(|e| dir.io_error("create the trajectory files", e))?,
            ),
        };
        let displacement = match built.displacement_driven() {
            false => None,
            true => Some(
                NpyRows::new(&mut dir, DISPLACEMENT_FILE, &[na])
                    .map_err(|e| dir.io_error("create the trajectory files", e))?,
            ),
        };
        Ok(TrajectoryWriter {
            dir,
            t,
            q,
            qd,
            u,
            tip_position,
            tip_rotation,
            strain,
            centerline,
            tendon_paths,
            body_positions,
            displacement,
            driven: built.drive_flags(),
            shape,
            provenance: None,
        })
    }

    /// Records how the run was made in `meta.json` (`"provenance"`, [`crate::provenance`]).
    pub fn set_provenance(&mut self, provenance: &crate::provenance::Provenance) {
        self.provenance = serde_json::to_value(provenance).ok();
    }

    /// Appends one sample of the run of `built` (the model that runs computes its centreline).
    pub fn push(&mut self, built: &Built, s: &Sample<'_>) -> std::io::Result<()> {
        if s.q.len() != self.shape.q.len() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "a sample of {} coordinates for a trajectory of {}",
                    s.q.len(),
                    self.shape.q.len()
                ),
            ));
        }
        self.shape.sample(built, s.q);
        self.centerline.push(self.shape.points.iter().copied())?;
        if let Some((paths, lengths)) = &mut self.tendon_paths {
            paths.push(self.shape.tendons.iter().copied())?;
            lengths.push(self.shape.lengths.iter().copied())?;
        }
        if let Some(bodies) = &mut self.body_positions {
            bodies.push(self.shape.bodies.iter().copied())?;
        }
        if let Some(d) = &mut self.displacement {
            d.push(commanded(&self.driven, s))?;
        }
        self.t.push([s.t])?;
        self.q.push(s.q.iter().copied())?;
        self.qd.push(s.qd.iter().copied())?;
        self.u.push(s.u.iter().copied())?;
        self.tip_position.push(s.tip.pos.iter().copied())?;
        let r = &s.tip.rot;
        self.tip_rotation
            .push((0..3).flat_map(|i| (0..3).map(move |j| r[(i, j)])))?;
        self.strain
            .push(s.strain.iter().flat_map(|xi| xi.iter().copied()))
    }

    /// Samples written so far.
    pub fn samples(&self) -> usize {
        self.t.rows()
    }

    /// Completes the arrays, writes `meta.json` (with `"complete"`, the reason for an early end,
    /// the last time reached, and the plan's sample rate and input record) and moves the directory
    /// into place.
    pub fn finish(
        self,
        built: &Built,
        plan: &Plan,
        outcome: &Outcome,
    ) -> Result<PathBuf, OutputError> {
        let requested_end = plan.t_out.last().copied().unwrap_or(0.0);
        let TrajectoryWriter {
            mut dir,
            t,
            q,
            qd,
            u,
            tip_position,
            tip_rotation,
            strain,
            centerline,
            tendon_paths,
            body_positions,
            displacement,
            driven: _,
            shape,
            provenance,
        } = self;
        let samples = t.rows();
        let arrays = [t, q, qd, u, tip_position, tip_rotation, strain, centerline];
        (|| -> std::io::Result<()> {
            let tendons = tendon_paths.into_iter().flat_map(|(p, l)| [p, l]);
            for a in (arrays.into_iter().chain(tendons))
                .chain(body_positions)
                .chain(displacement)
            {
                a.finish(&mut dir)?;
            }
            crate::npy::write_array(
                &mut dir,
                "strain_x.npy",
                &[built.model.disc.n_points()],
                &built
                    .model
                    .disc
                    .points
                    .iter()
                    .map(|p| p.x)
                    .collect::<Vec<_>>(),
            )?;
            let m = &built.model;
            crate::npy::write_array(
                &mut dir,
                "strain_reference.npy",
                &[m.disc.n_points(), 6],
                &(0..m.disc.n_points())
                    .flat_map(|j| m.xi_star(j).iter().copied().collect::<Vec<_>>())
                    .collect::<Vec<_>>(),
            )
        })()
        .map_err(|e| dir.io_error("write the trajectory arrays", e))?;
        let sm = &outcome.summary;
        let (complete, reason, error) = match &outcome.ending {
            Ending::Complete => (true, None, None),
            Ending::Interrupted { reason } => (false, Some(reason.clone()), None),
            Ending::Failed { error, failure } => {
                (false, Some(failure.reason().into()), Some(error.clone()))
            }
        };
        let meta = Meta {
            scenario: &built.name,
            complete,
            reason,
            t_reached: sm.t_last,
            t_requested: requested_end,
            sample_rate: plan.sample_rate,
            samples,
            n_dof: built.n_dof(),
            n_points: built.model.disc.n_points(),
            n_actuators: built.model.n_actuators(),
            n_bodies: built.model.bodies().len(),
            length: built.model.rod.length(),
            wall_time_s: sm.wall_time_s,
            wall_times_s: match outcome.wall_times_s.len() {
                0 | 1 => vec![],
                _ => outcome.wall_times_s.clone(),
            },
            real_time_factor: outcome.real_time_factor(),
            steps: sm.stats.steps,
            failed_steps: sm.stats.failed_steps,
            newton_failures: sm.stats.newton_failures,
            rhs_evaluations: sm.stats.rhs_evals,
            jacobian_evaluations: sm.stats.jacobian_evals,
            lu_decompositions: sm.stats.lu_decompositions,
            error,
            input: &plan.input,
            physics: physics_record(built),
            model_extrapolated: built
                .reduced
                .iter()
                .flat_map(|r| r.extrapolated.iter())
                .chain(&plan.model_extrapolated)
                .chain(&outcome.model_extrapolated)
                .cloned()
                .collect(),
            centerline_x: shape.x,
            tendon_rest_lengths: built.model.tendon_rest_lengths(),
            energy_balance: outcome.energy,
            start_divergence: plan.start_divergence.or(sm.start_divergence),
            provenance,
        };
        dir.commit(meta)
    }
}

#[derive(Serialize)]
pub(super) struct Meta<'a> {
    scenario: &'a str,
    /// `false` if the run ended before `t_requested` (interrupted or failed): the arrays hold the
    /// samples up to `t_reached`.
    complete: bool,
    /// Why an incomplete run ended.
    reason: Option<String>,
    /// Time of the last sample written.
    t_reached: Option<f64>,
    t_requested: f64,
    /// Output samples per second.
    sample_rate: f64,
    samples: usize,
    n_dof: usize,
    n_points: usize,
    n_actuators: usize,
    /// Rigid bodies (`body_positions.npy` holds their positions); left out without bodies.
    #[serde(skip_serializing_if = "is_zero")]
    n_bodies: usize,
    /// Rod length [m].
    length: f64,
    /// Wall time of the integration \[s\]: with `--repeat`, the smallest of `wall_times_s`.
    wall_time_s: f64,
    /// Every timed run's wall time \[s\] (`--repeat` > 1), the written one first.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    wall_times_s: Vec<f64>,
    real_time_factor: f64,
    /// Work counts of the integrator (up to the end of the run, or to where it stopped).
    steps: usize,
    failed_steps: usize,
    /// Of `failed_steps`, the attempts whose Newton iteration did not converge.
    newton_failures: usize,
    rhs_evaluations: usize,
    jacobian_evaluations: usize,
    lu_decompositions: usize,
    /// The integrator's error if it failed.
    error: Option<String>,
    /// The input signal, start and load schedule ([`input_record`]).
    input: &'a serde_json::Value,
    /// The scenario's physics besides the inputs ([`physics_record`]).
    physics: serde_json::Value,
    /// How the run lies outside its reduced model's training (`--extrapolate`): the scenario's and
    /// the input signal's differences.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    model_extrapolated: Vec<String>,
    /// Abscissae of the centreline samples in `centerline.npy` [m].
    centerline_x: Vec<f64>,
    /// Each tendon's length at rest \[m\], what `tendon_lengths.npy` is shortened from.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    tendon_rest_lengths: Vec<f64>,
    /// The total energy over the samples of a conservative run ([`super::EnergyBalance`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    energy_balance: Option<super::EnergyBalance>,
    /// `ω²` \[1/s²\] < 0 of the equilibrium a `--from-equilibrium` run started from, when it
    /// diverges (no stable one was found): [`super::unstable_start_note`].
    #[serde(skip_serializing_if = "Option::is_none")]
    start_divergence: Option<f64>,
    /// How the run was made ([`crate::provenance::Provenance`]), when the caller recorded it.
    #[serde(skip_serializing_if = "Option::is_none")]
    provenance: Option<serde_json::Value>,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}
