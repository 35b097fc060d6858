//! The tendon tensions `u` of a scenario: read them, set them (one value for all or one per tendon).

use super::types::Scenario;
use crate::error::ScenarioError;

impl Scenario {
    /// The tensions `u` of the tendons, in order.
    pub fn tensions(&self) -> Vec<f64> {
        self.tendons.iter().map(|t| t.tension).collect()
    }

    /// Sets the tendon tensions: one value for every tendon, or one value per tendon.
    pub fn set_tensions(&mut self, u: &[f64]) -> Result<(), ScenarioError> {
        let u = tensions_for(self.tendons.len(), u)?;
        for (t, u) in self.tendons.iter_mut().zip(u) {
            t.tension = u;
        }
        Ok(())
    }
}

/// The tensions of `n` tendons from `u`: one value for every tendon, or one value per tendon.
pub fn tensions_for(n: usize, u: &[f64]) -> Result<Vec<f64>, ScenarioError> {
    if n == 0 {
        return Err(ScenarioError::invalid(
            "tendons",
            "the scenario has no tendons to set a tension on",
        ));
    }
    if u.len() != 1 && u.len() != n {
        return Err(ScenarioError::invalid(
            "tendons",
            format!(
                "{} {} given for {n} {} (give 1 value for all, or {n})",
                u.len(),
                if u.len() == 1 { "tension" } else { "tensions" },
                if n == 1 { "tendon" } else { "tendons" },
            ),
        ));
    }
    Ok((0..n)
        .map(|k| if u.len() == 1 { u[0] } else { u[k] })
        .collect())
}
