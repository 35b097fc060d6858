//! The energy balance of a conservative run: an undamped rod under gravity and constant,
//! frictionless tendon tensions keeps its total energy
//!
//! ```text
//! E = T + U_e + U_g − Σ_k u_k ℓ_k(q),   T = ½ q̇ᵀ M q̇,  U_e = ½ Σ W Ψᵀ Es Ψ,
//! U_g = −Σ W ρA g·r − Σ_b m_b g·(r_b + R_b c_b)
//! ```
//!
//! (the rigid bodies' weights at their centres of mass, and their inertia in `M`, `gvs::bodies`)
//!
//! (spec §9.4; a frictionless tendon's generalized force is `B u` with `B = ∂ℓ/∂qᵀ`, the gradient
//! of `u·ℓ`, so its potential is `−u·ℓ`). A tendon driven by a constant displacement is a spring
//! (`gvs::solve::dynamics::drive`): its term is the energy its thread stores,
//! `½ max(0, ℓ_k − ℓ*_k)² / c_k` ([`ThreadSprings`]), in place of `−u_k ℓ_k`. The integrators are implicit and dissipate a little of it;
//! one that *adds* energy is wrong in a way the samples do not show — an undamped rod falling
//! under gravity was integrated at +2.6 J of a possible 0.4 J, with every sample written and the
//! run reported complete. The balance is measured at every sample and reported with the run.

use crate::build::Built;
use gvs::model::{Model, Workspace};
use gvs::solve::dynamics::Sample;
use gvs::strain::StrainParam;
use nalgebra::DVector;
use serde::Serialize;

/// Gain of the total energy, relative to the largest kinetic energy of the run, above which the
/// run is reported as having gained energy (an implicit integrator loses a little; measured: the
/// default SDIRK4 on an undamped small-amplitude release lost 0.11 %).
pub const GAIN_NOTE: f64 = 0.01;

/// Loss of the total energy, relative to the largest kinetic energy of the run, above which the
/// run is reported as numerically damped: an L-stable integrator damps the vibrations its steps
/// do not resolve, strongly on a whipping rod (measured 2026-12-07 on an undamped 12-element rod
/// falling from horizontal for 4 s, the automatic SDIRK4: 19 % at rtol 1e-4, 7 % at 1e-5; a
/// small-amplitude release loses 0.1 %, a rod under a sudden tendon tension 5.6 %).
pub const LOSS_NOTE: f64 = 0.10;

/// The energy balance of a conservative run \[J\].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EnergyBalance {
    /// `E` at the first sample.
    pub initial: f64,
    /// `E` at the last sample.
    pub last: f64,
    /// The largest `E − E(0)` over the samples (0 if it never rose).
    pub largest_gain: f64,
    /// The largest `E(0) − E` over the samples (0 if it never fell).
    pub largest_loss: f64,
    /// The largest kinetic energy over the samples: the scale of the balance.
    pub kinetic_max: f64,
}

impl EnergyBalance {
    /// [`EnergyBalance::largest_gain`] relative to [`EnergyBalance::kinetic_max`] (0 for a rod
    /// that never moved).
    pub fn relative_gain(&self) -> f64 {
        match self.kinetic_max > 0.0 {
            true => self.largest_gain / self.kinetic_max,
            false => 0.0,
        }
    }

    /// [`EnergyBalance::largest_loss`] relative to [`EnergyBalance::kinetic_max`].
    pub fn relative_loss(&self) -> f64 {
        match self.kinetic_max > 0.0 {
            true => self.largest_loss / self.kinetic_max,
            false => 0.0,
        }
    }

    /// What the user is told about the balance: energy added beyond [`GAIN_NOTE`] (the motion is
    /// not to be trusted) and energy dissipated beyond [`LOSS_NOTE`], each naming what to do;
    /// `tolerances` spells the tolerance options as the front end does (`--rtol`, `rtol`).
    pub fn notes(&self, tolerances: [&str; 2]) -> Vec<String> {
        let [rtol, atol] = tolerances;
        let mut notes = Vec::new();
        if self.relative_gain() > GAIN_NOTE {
            notes.push(format!(
                "the integration added energy that no force supplies ({:.1} % of the largest kinetic energy): the motion is not to be trusted; tighten {rtol} and {atol} together, or give the rod some damping (material.damping)",
                100.0 * self.relative_gain()
            ));
        }
        if self.relative_loss() > LOSS_NOTE {
            notes.push(format!(
                "the integrator dissipated {:.1} % of the largest kinetic energy of this undamped run: the numerical damping of the vibrations its steps do not resolve; where the undamped motion must keep its energy, tighten {rtol}",
                100.0 * self.relative_loss()
            ));
        }
        notes
    }
}

/// Why a run's energy is not expected to be conserved (`None` if it is): material damping, tendon
/// friction, point or distributed loads (follower ones do work), or a load schedule.
pub fn not_conservative(built: &Built, scheduled: bool) -> Option<&'static str> {
    let m = &built.model;
    if m.rod.materials().any(|material| material.damping != 0.0) {
        Some("material damping")
    } else if m.tendons.iter().any(|t| t.friction != 0.0) {
        Some("tendon friction")
    } else if built.loads.point.iter().any(|p| p.wrench != [0.0; 6])
        || (built.loads.distributed.iter()).any(|d| d.peak_density().0 != gvs::lie::V6::zeros())
    {
        Some("point or distributed loads")
    } else if scheduled {
        Some("a load schedule")
    } else {
        None
    }
}

/// The threads of tendons driven by constant displacements: per tendon whether it is driven, its
/// unstretched length `ℓ*_k = ℓ_k,rest − δ_k` \[m\] and its compliance `c_k` \[m/N\].
pub struct ThreadSprings {
    driven: Vec<bool>,
    target: Vec<f64>,
    compliance: Vec<f64>,
}

impl ThreadSprings {
    /// The threads of `model`'s tendons `driven` at the displacements `channels[k]` \[m\].
    pub fn new<P: StrainParam>(model: &Model<P>, driven: &[bool], channels: &[f64]) -> Self {
        let rest = model.tendon_rest_lengths();
        ThreadSprings {
            driven: driven.to_vec(),
            target: (rest.iter().zip(channels)).map(|(l, d)| l - d).collect(),
            compliance: model.tendon_compliances(),
        }
    }

    /// The energy the threads store at the path lengths `lengths` \[J\].
    fn energy(&self, lengths: &[f64]) -> f64 {
        (0..self.driven.len())
            .filter(|&k| self.driven[k] && self.compliance[k] > 0.0)
            .map(|k| (lengths[k] - self.target[k]).max(0.0).powi(2) / (2.0 * self.compliance[k]))
            .sum()
    }
}

/// Measures `E` at each sample of a conservative run; stops measuring (and reports nothing) once
/// the tensions change, since they then do work.
pub(super) struct EnergyMonitor {
    ws: Workspace,
    lengths: Vec<f64>,
    q: DVector<f64>,
    qd: DVector<f64>,
    u0: Option<Vec<f64>>,
    balance: Option<EnergyBalance>,
    changed_input: bool,
    /// The threads of the tendons driven by constant displacements.
    springs: Option<ThreadSprings>,
}

impl EnergyMonitor {
    pub(super) fn new<P: StrainParam>(model: &Model<P>, springs: Option<ThreadSprings>) -> Self {
        let n = model.n_dof();
        EnergyMonitor {
            ws: model.workspace(),
            lengths: vec![0.0; model.n_actuators()],
            q: DVector::zeros(n),
            qd: DVector::zeros(n),
            u0: None,
            balance: None,
            changed_input: false,
            springs,
        }
    }

    /// Adds the sample `s` of a run of `model` under `gravity`.
    pub(super) fn push<P: StrainParam>(
        &mut self,
        model: &Model<P>,
        gravity: &[f64; 3],
        s: &Sample<'_>,
    ) {
        if self.changed_input {
            return;
        }
        // a driven tendon's tension follows its stretch: only the given tensions must hold
        let driven = |k: usize| self.springs.as_ref().is_some_and(|s| s.driven[k]);
        match &self.u0 {
            None => self.u0 = Some(s.u.to_vec()),
            Some(u0) if (0..u0.len()).any(|k| !driven(k) && u0[k] != s.u[k]) => {
                self.changed_input = true;
                return;
            }
            Some(_) => {}
        }
        self.q.copy_from_slice(s.q);
        self.qd.copy_from_slice(s.qd);
        let e = model.energy(&self.q, &self.qd, gravity, &mut self.ws);
        // `energy` left the forward pass at q in the workspace
        model.tendon_lengths_after_forward(&self.ws, &mut self.lengths);
        let tendons: f64 = (s.u.iter().zip(&self.lengths).enumerate())
            .filter(|(k, _)| !driven(*k))
            .map(|(_, (u, l))| u * l)
            .sum();
        let threads = self
            .springs
            .as_ref()
            .map_or(0.0, |s| s.energy(&self.lengths));
        let total = e.total() - tendons + threads;
        if !(total.is_finite() && e.kinetic.is_finite()) {
            return;
        }
        let b = self.balance.get_or_insert(EnergyBalance {
            initial: total,
            last: total,
            largest_gain: 0.0,
            largest_loss: 0.0,
            kinetic_max: 0.0,
        });
        b.last = total;
        b.largest_gain = b.largest_gain.max(total - b.initial);
        b.largest_loss = b.largest_loss.max(b.initial - total);
        b.kinetic_max = b.kinetic_max.max(e.kinetic);
    }

    /// The balance, if the run was measured throughout (at least two samples, constant tensions).
    pub(super) fn finish(self, samples: usize) -> Option<EnergyBalance> {
        match self.changed_input || samples < 2 {
            true => None,
            false => self.balance,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn balance(gain: f64, loss: f64) -> EnergyBalance {
        EnergyBalance {
            initial: 0.0,
            last: 0.0,
            largest_gain: gain,
            largest_loss: loss,
            kinetic_max: 2.0,
        }
    }

    #[test]
    fn notes_name_a_gain_above_one_per_cent_and_a_loss_above_ten() {
        // of a largest kinetic energy of 2 J: 0.02 J is the gain threshold, 0.2 J the loss's
        assert!(balance(0.019, 0.19).notes(["--rtol", "--atol"]).is_empty());
        let gain = balance(0.03, 0.0).notes(["--rtol", "--atol"]);
        assert_eq!(gain.len(), 1);
        assert!(
            gain[0].contains("added energy") && gain[0].contains("(1.5 %"),
            "{gain:?}"
        );
        assert!(gain[0].contains("tighten --rtol and --atol"), "{gain:?}");
        let loss = balance(0.0, 0.5).notes(["rtol", "atol"]);
        assert_eq!(loss.len(), 1);
        assert!(loss[0].contains("dissipated 25.0 %"), "{loss:?}");
        assert!(loss[0].contains("tighten rtol"), "{loss:?}");
        assert_eq!(balance(0.03, 0.5).notes(["--rtol", "--atol"]).len(), 2);
        // a rod that never moved has no scale: nothing to say
        let still = EnergyBalance {
            kinetic_max: 0.0,
            ..balance(1e-12, 1e-12)
        };
        assert!(still.notes(["--rtol", "--atol"]).is_empty());
    }
}
