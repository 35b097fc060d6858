//! The layout of a built scenario's strain rows: the computational points and the strain
//! components its basis can excite. Datasets, statics comparisons and reduced models share it
//! (build layer: it depends on [`crate::build`](mod@crate::build) and the scenario's component names only).

use crate::build::Built;

/// What every sample row holds: the computational points and the strain components stored.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    pub n_dof: usize,
    pub strain_x: Vec<f64>,
    /// Indices (0..6) of the active strain components.
    pub active: Vec<usize>,
    /// Tendons, whose lengths a sample row records.
    pub n_tendons: usize,
}

impl Layout {
    /// The layout of `built`: a strain component is active if the basis can excite it at any site.
    pub fn of(built: &Built) -> Layout {
        let m = &built.model;
        Layout {
            n_dof: m.n_dof(),
            strain_x: m.disc.points.iter().map(|p| p.x).collect(),
            active: rom::reduced::PointLayout::active_in(&m.param, &m.disc).active,
            n_tendons: m.n_actuators(),
        }
    }

    /// Names of the active components (`bend_y`, …), in column order within a point.
    pub fn component_names(&self) -> Vec<String> {
        self.active
            .iter()
            .map(|&a| crate::scenario::StrainMode::ALL[a].name().to_string())
            .collect()
    }

    /// Values per strain row: points × active components.
    pub fn row_len(&self) -> usize {
        self.strain_x.len() * self.active.len()
    }
}
