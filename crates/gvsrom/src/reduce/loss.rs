//! The loss of an autoencoder's training (`gvsrom train --loss`): how each snapshot feature's
//! error weighs, and the per-feature weighting it makes for a Built's point layout.

use crate::build::Built;
use rom::reduced::PointLayout;

/// How a snapshot feature's error weighs in the autoencoder's training loss (`gvsrom train --loss`).
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum Loss {
    /// Each feature standardized by its own spread: every point and component weighs the same
    /// relative to its own variation, whatever its physical magnitude.
    Standardized,
    /// The physical mean squared error, every feature with weight 1 (the RMSE of Table I).
    Physical,
    /// The strain-energy norm: feature (point j, component a) weighted by the section stiffness
    /// `Σ_s,aa` at point j (not by the quadrature weight, under which the kinematic points would
    /// weigh nothing). Errors in stiff shear and elongation weigh what they cost in elastic force.
    /// The default: the reduced model feels strain errors through exactly this norm.
    #[default]
    Energy,
}

impl Loss {
    /// The loss of a [`Loss::name`].
    pub fn from_name(name: &str) -> Option<Loss> {
        [Loss::Standardized, Loss::Physical, Loss::Energy]
            .into_iter()
            .find(|l| l.name() == name)
    }

    /// The name used on the command line and in `meta.json`.
    pub fn name(self) -> &'static str {
        match self {
            Loss::Standardized => "standardized",
            Loss::Physical => "physical",
            Loss::Energy => "energy",
        }
    }

    /// The per-feature weighting of the point layout `layout` of `built`.
    pub(super) fn weighting(self, built: &Built, layout: &PointLayout) -> rom::nn::Weighting {
        use rom::nn::Weighting;
        match self {
            Loss::Standardized => Weighting::Standardize,
            Loss::Physical => Weighting::Physical(vec![1.0; layout.len()]),
            Loss::Energy => Weighting::Physical(super::stiffness_weights(built, layout)),
        }
    }
}
