//! A trajectory kept in memory ([`TrajectoryBuffer`]): what the Python binding returns.

use super::centerline::*;
use super::run::*;
use crate::build::Built;
use gvs::solve::dynamics::Sample;

/// A trajectory kept in memory (the arrays of the files a `TrajectoryWriter` writes, row-major,
/// one row per sample): what the Python binding returns.
pub struct TrajectoryBuffer {
    pub t: Vec<f64>,
    /// `samples × n`.
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    /// `samples × n_a`.
    pub u: Vec<f64>,
    /// `samples × 3`.
    pub tip_position: Vec<f64>,
    /// `samples × 3 × 3`.
    pub tip_rotation: Vec<f64>,
    /// `samples × p × 6`.
    pub strain: Vec<f64>,
    /// `samples × c × 3`, at [`Self::centerline_x`].
    pub centerline: Vec<f64>,
    /// `samples × tendons × c × 3`: each tendon's thread at [`Self::centerline_x`] clamped to its
    /// span (`tendon_paths.npy` of a written trajectory).
    pub tendon_paths: Vec<f64>,
    /// `samples × tendons`: each tendon's length \[m\] (`tendon_lengths.npy`).
    pub tendon_lengths: Vec<f64>,
    /// `samples × bodies × 2 × 3`: each rigid body's section and centre of mass \[m\]
    /// (`body_positions.npy`).
    pub body_positions: Vec<f64>,
    /// `samples × tendons`: the commanded displacements \[m\] (NaN for a tendon driven by its
    /// tension; `displacement.npy`), empty unless a tendon is driven by its displacement.
    pub displacement: Vec<f64>,
    driven: Vec<bool>,
    shape: Centerline,
}

impl TrajectoryBuffer {
    /// An empty trajectory of the run of `built`.
    pub fn new(built: &Built) -> Self {
        TrajectoryBuffer {
            t: vec![],
            q: vec![],
            qd: vec![],
            u: vec![],
            tip_position: vec![],
            tip_rotation: vec![],
            strain: vec![],
            centerline: vec![],
            tendon_paths: vec![],
            tendon_lengths: vec![],
            body_positions: vec![],
            displacement: vec![],
            driven: built.drive_flags(),
            shape: Centerline::new(built),
        }
    }

    /// Abscissae of the centreline samples \[m\].
    pub fn centerline_x(&self) -> &[f64] {
        &self.shape.x
    }
}

impl SampleSink for TrajectoryBuffer {
    fn push(&mut self, built: &Built, s: &Sample<'_>) -> std::io::Result<()> {
        if s.q.len() != self.shape.q.len() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "a sample of another model's coordinates",
            ));
        }
        self.shape.sample(built, s.q);
        self.centerline.extend_from_slice(&self.shape.points);
        self.tendon_paths.extend_from_slice(&self.shape.tendons);
        self.tendon_lengths.extend_from_slice(&self.shape.lengths);
        self.body_positions.extend_from_slice(&self.shape.bodies);
        if self.driven.iter().any(|&d| d) {
            self.displacement
                .extend(super::writer::commanded(&self.driven, s));
        }
        self.t.push(s.t);
        self.q.extend_from_slice(s.q);
        self.qd.extend_from_slice(s.qd);
        self.u.extend_from_slice(s.u);
        self.tip_position.extend(s.tip.pos.iter().copied());
        let r = &s.tip.rot;
        self.tip_rotation
            .extend((0..3).flat_map(|i| (0..3).map(move |j| r[(i, j)])));
        self.strain
            .extend(s.strain.iter().flat_map(|xi| xi.iter().copied()));
        Ok(())
    }
}
