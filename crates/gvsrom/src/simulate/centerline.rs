//! The centreline of a sample at equally spaced abscissae: shared by the trajectory writer and the
//! in-memory buffer.

use crate::build::Built;

/// The centreline of each sample: the forward kinematics of the model that runs (the reduced one
/// shares the scenario's rod and points) at `q`, sampled at `x` — buffers allocated once, before
/// the run.
pub(super) struct Centerline {
    /// Abscissae `x_k = L k / (c − 1)`, `k = 0 … c − 1` [m].
    pub(super) x: Vec<f64>,
    pub(super) q: nalgebra::DVector<f64>,
    pub(super) ws: gvs::model::Workspace,
    /// `c × 3` positions of the current sample.
    pub(super) points: Vec<f64>,
    /// `tendons × c × 3`: each tendon's thread `r + R d(X)` at the abscissae `x` clamped to its
    /// span ([`gvs::model::Model::tendon_position_at`]), of the current sample.
    pub(super) tendons: Vec<f64>,
    /// Each tendon's length \[m\] ([`gvs::model::Model::tendon_lengths`]) of the current sample.
    pub(super) lengths: Vec<f64>,
    /// `bodies × 2 × 3`: each rigid body's section and centre of mass \[m\]
    /// ([`gvs::model::Model::body_positions`]) of the current sample.
    pub(super) bodies: Vec<f64>,
}

impl Centerline {
    pub(super) fn new(built: &Built) -> Self {
        let (n, ws) = match &built.reduced {
            Some(r) => (r.model.n_dof(), r.model.workspace()),
            None => (built.model.n_dof(), built.model.workspace()),
        };
        let c = built.centerline_points.max(2);
        Centerline {
            x: crate::statics::centerline_abscissae(built.model.disc.length(), c),
            q: nalgebra::DVector::zeros(n),
            ws,
            points: vec![0.0; 3 * c],
            tendons: vec![0.0; 3 * c * built.model.n_actuators()],
            lengths: vec![0.0; built.model.n_actuators()],
            bodies: vec![0.0; 6 * built.model.bodies().len()],
        }
    }

    /// The centreline at `q` into [`Self::points`], the tendons' threads and lengths.
    pub(super) fn sample(&mut self, built: &Built, q: &[f64]) {
        self.q.as_mut_slice().copy_from_slice(q);
        match &built.reduced {
            Some(r) => self.fill(&r.model),
            None => self.fill(&built.model),
        }
    }

    pub(super) fn fill<P: gvs::strain::StrainParam>(&mut self, model: &gvs::model::Model<P>) {
        model.forward_pose(&self.q, &mut self.ws);
        for (k, &x) in self.x.iter().enumerate() {
            let p = model.position_at(&self.ws, x);
            self.points[3 * k..3 * k + 3].copy_from_slice(&[p[0], p[1], p[2]]);
        }
        let c = self.x.len();
        for t in 0..model.tendons.len() {
            let Some((xa, xb)) = model.tendon_extent(t) else {
                continue;
            };
            for (k, &x) in self.x.iter().enumerate() {
                let p = model.tendon_position_at(&self.ws, t, x.clamp(xa, xb));
                let o = 3 * (t * c + k);
                self.tendons[o..o + 3].copy_from_slice(&[p[0], p[1], p[2]]);
            }
        }
        model.tendon_lengths_after_forward(&self.ws, &mut self.lengths);
        for (b, (section, center)) in model.body_positions(&self.ws).enumerate() {
            self.bodies[6 * b..6 * b + 3].copy_from_slice(section.as_slice());
            self.bodies[6 * b + 3..6 * b + 6].copy_from_slice(center.as_slice());
        }
    }
}
