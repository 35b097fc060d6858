//! The tendon tensions `u` of a scenario: read them, set them (one value for all or one per tendon).

use super::types::Scenario;
use crate::error::ScenarioError;

impl Scenario {
    /// The tensions `u` of the tendons, in order.
    pub fn tensions(&self) -> Vec<f64> {
        self.tendons.iter().map(|t| t.tension).collect()
    }

    /// Sets the tendon tensions: one value for every tendon, or one value per tendon. A tendon
    /// driven by its displacement becomes driven by this tension.
    pub fn set_tensions(&mut self, u: &[f64]) -> Result<(), ScenarioError> {
        let u = tensions_for(self.tendons.len(), u)?;
        for (t, u) in self.tendons.iter_mut().zip(u) {
            t.tension = u;
            t.displacement = None;
        }
        Ok(())
    }

    /// Drives the tendons by their displacements \[m\] (wound in from the rest length): one value
    /// for every tendon, or one value per tendon; their tensions are cleared (statics finds them).
    pub fn set_displacements(&mut self, d: &[f64]) -> Result<(), ScenarioError> {
        let d = values_for(self.tendons.len(), d, "displacement")?;
        for (t, d) in self.tendons.iter_mut().zip(d) {
            t.tension = 0.0;
            t.displacement = Some(d);
        }
        Ok(())
    }

    /// Whether a tendon is driven by its displacement.
    pub fn displacement_driven(&self) -> bool {
        self.tendons.iter().any(|t| t.displacement.is_some())
    }
}

/// The tensions of `n` tendons from `u`: one value for every tendon, or one value per tendon.
pub fn tensions_for(n: usize, u: &[f64]) -> Result<Vec<f64>, ScenarioError> {
    values_for(n, u, "tension")
}

/// One `noun` per tendon of `n` from `u`: one value for every tendon, or one value per tendon.
fn values_for(n: usize, u: &[f64], noun: &str) -> Result<Vec<f64>, ScenarioError> {
    if n == 0 && u.is_empty() {
        // `u = zeros(n_actuators)` of a rod without tendons: nothing to set
        return Ok(vec![]);
    }
    if n == 0 {
        return Err(ScenarioError::invalid(
            "tendons",
            format!("the scenario has no tendons to set a {noun} on"),
        ));
    }
    if u.len() != 1 && u.len() != n {
        return Err(ScenarioError::invalid(
            "tendons",
            format!(
                "{} {noun}{} given for {n} {} ({})",
                u.len(),
                if u.len() == 1 { "" } else { "s" },
                if n == 1 { "tendon" } else { "tendons" },
                match n {
                    1 => "give 1".to_string(),
                    _ => format!("give 1 value for all, or {n}"),
                },
            ),
        ));
    }
    Ok((0..n)
        .map(|k| if u.len() == 1 { u[0] } else { u[k] })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::tensions_for;

    #[test]
    fn one_value_is_for_every_tendon_and_none_is_for_a_rod_without_tendons() {
        assert_eq!(tensions_for(3, &[-2.0]).unwrap(), [-2.0; 3]);
        assert_eq!(tensions_for(2, &[-1.0, -3.0]).unwrap(), [-1.0, -3.0]);
        // `u = zeros(n_actuators)` of a soft beam
        assert!(tensions_for(0, &[]).unwrap().is_empty());
        let e = tensions_for(0, &[-1.0]).unwrap_err().to_string();
        assert!(e.contains("no tendons"), "{e}");
        let e = tensions_for(1, &[-1.0, -2.0]).unwrap_err().to_string();
        assert!(e.contains("2 tensions given for 1 tendon (give 1)"), "{e}");
        let e = tensions_for(6, &[-1.0, -2.0]).unwrap_err().to_string();
        assert!(e.contains("(give 1 value for all, or 6)"), "{e}");
        assert!(tensions_for(2, &[]).is_err());
    }
}
