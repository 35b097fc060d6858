//! External loads resolved onto the computational points ([`PreparedLoads`]): point wrenches on
//! their points, distributed densities × quadrature weight, gravity; follower and world-fixed parts
//! kept apart.

use super::Model;
use crate::error::ModelError;
use crate::lie::{V3, V6};
use crate::loads::{Frame, Loads};
use crate::strain::StrainParam;

/// Loads resolved onto the computational points.
#[derive(Debug, Clone)]
pub struct PreparedLoads {
    pub(super) gravity: V3,
    /// Local (follower) wrench per point: point loads plus distributed densities × W.
    pub(super) local: Vec<V6>,
    /// World-fixed wrench per point (world components).
    pub(super) global: Vec<V6>,
}

impl PreparedLoads {
    /// `self = λ · base` without allocating (time-varying load schedules).
    pub fn scale_from(&mut self, base: &PreparedLoads, lambda: f64) {
        self.gravity = base.gravity * lambda;
        for (a, b) in self.local.iter_mut().zip(&base.local) {
            *a = b * lambda;
        }
        for (a, b) in self.global.iter_mut().zip(&base.global) {
            *a = b * lambda;
        }
    }
}

impl<P: StrainParam> Model<P> {
    /// Resolves loads onto the points. Point wrenches must sit on computational points (build the
    /// discretization with their abscissae as extra points).
    pub fn prepare_loads(&self, loads: &Loads) -> Result<PreparedLoads, ModelError> {
        loads.validate(self.disc.length())?;
        let np = self.disc.n_points();
        let mut local = vec![V6::zeros(); np];
        let mut global = vec![V6::zeros(); np];
        for (k, pw) in loads.point.iter().enumerate() {
            let i = self.disc.point_at(pw.x).ok_or_else(|| {
                ModelError::invalid(
                    format!("loads.point[{k}].x"),
                    format!("X = {} m is not a computational point; add it to the discretization's extra points", pw.x),
                )
            })?;
            let w = V6::from_row_slice(&pw.wrench);
            match pw.frame {
                Frame::Local => local[i] += w,
                Frame::Global => global[i] += w,
            }
        }
        for d in &loads.distributed {
            for (i, p) in self.disc.points.iter().enumerate() {
                if p.weight == 0.0 {
                    continue;
                }
                let (f, frame) = d.density_at(p.x);
                match frame {
                    Frame::Local => local[i] += f * p.weight,
                    Frame::Global => global[i] += f * p.weight,
                }
            }
        }
        Ok(PreparedLoads {
            gravity: V3::from_row_slice(&loads.gravity),
            local,
            global,
        })
    }
}
