//! Rod geometry and constitutive data (gvs-spec §3): linearly tapered circular sections per division,
//! material (E, ν, ρ, damping constant η), and the per-point cross-section matrices
//! `Es = diag(GJ, EI_y, EI_z, EA, GA, GA)`, `Ms = ρ diag(J, I_y, I_z, A, A, A)`,
//! `Ds = η diag(J, 3I_y, 3I_z, 3A, A, A)` with `G = E / (2(1+ν))` and `J = I_y + I_z` (SoRoSim `MEG`).

use crate::error::{check_positive, check_range, ModelError};
use crate::lie::V6;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Isotropic linear-elastic material with viscous (Kelvin–Voigt) damping.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Young's modulus E \[Pa\].
    pub youngs_modulus: f64,
    /// Poisson ratio ν, in (−1, 0.5].
    pub poisson_ratio: f64,
    /// Density ρ [kg/m³].
    pub density: f64,
    /// Material damping constant η [Pa·s] (paper Table II: 1e4).
    pub damping: f64,
}

impl Material {
    pub fn validate(&self) -> Result<(), ModelError> {
        self.validate_as("material")
    }

    /// [`Self::validate`] with the fields named under `prefix` (`divisions[1].material`).
    pub fn validate_as(&self, prefix: &str) -> Result<(), ModelError> {
        let f = |n: &str| format!("{prefix}.{n}");
        check_positive(&f("youngs_modulus"), self.youngs_modulus, "Pa")?;
        check_range(
            &f("poisson_ratio"),
            self.poisson_ratio,
            Some((-1.0, false)),
            Some((0.5, true)),
            "a number in (-1, 0.5]",
        )?;
        check_range(
            &f("density"),
            self.density,
            Some((0.0, true)),
            None,
            "a finite number >= 0 kg/m^3",
        )?;
        check_range(
            &f("damping"),
            self.damping,
            Some((0.0, true)),
            None,
            "a finite number >= 0 Pa*s",
        )?;
        Ok(())
    }

    /// Shear modulus `G = E / (2(1+ν))`.
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }
}

/// One division of the rod: length and a circular section tapering linearly from `radius_start` to
/// `radius_end` over the normalized division coordinate `X̄ ∈ [0, 1]` (spec §3.1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DivisionGeometry {
    pub length: f64,
    pub radius_start: f64,
    pub radius_end: f64,
    /// The division's own material where it differs from the rod's (a stiff base and a soft tip,
    /// SoRoSim's material per link); `None`: the rod's ([`Rod::material_of`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<Material>,
}

impl DivisionGeometry {
    pub fn radius_at(&self, x_bar: f64) -> f64 {
        self.radius_start + x_bar * (self.radius_end - self.radius_start)
    }
}

/// Rod: material plus its divisions laid end to end along the local x-axis (a division may have
/// a material of its own, [`DivisionGeometry::material`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Rod {
    pub material: Material,
    pub divisions: Vec<DivisionGeometry>,
}

impl Rod {
    /// A single-division rod with a linear taper.
    pub fn tapered(material: Material, length: f64, radius_start: f64, radius_end: f64) -> Self {
        Rod {
            material,
            divisions: vec![DivisionGeometry {
                length,
                radius_start,
                radius_end,
                material: None,
            }],
        }
    }

    /// The material of division `j`: its own, or the rod's.
    pub fn material_of(&self, j: usize) -> &Material {
        self.divisions[j]
            .material
            .as_ref()
            .unwrap_or(&self.material)
    }

    /// The materials of every division (the rod's where a division has none of its own).
    pub fn materials(&self) -> impl Iterator<Item = &Material> {
        (0..self.divisions.len()).map(|j| self.material_of(j))
    }

    pub fn validate(&self) -> Result<(), ModelError> {
        self.material.validate()?;
        for (j, d) in self.divisions.iter().enumerate() {
            if let Some(m) = &d.material {
                m.validate_as(&format!("rod.divisions[{j}].material"))?;
            }
        }
        if self.divisions.is_empty() {
            return Err(ModelError::invalid(
                "rod.divisions",
                "at least one division is required",
            ));
        }
        for (j, d) in self.divisions.iter().enumerate() {
            check_positive(&format!("rod.divisions[{j}].length"), d.length, "m")?;
            check_positive(
                &format!("rod.divisions[{j}].radius_start"),
                d.radius_start,
                "m",
            )?;
            check_positive(&format!("rod.divisions[{j}].radius_end"), d.radius_end, "m")?;
        }
        Ok(())
    }

    /// Total length `L = Σ ℓ_j`.
    pub fn length(&self) -> f64 {
        self.divisions.iter().map(|d| d.length).sum()
    }

    /// Abscissa of the start of each division.
    pub fn division_starts(&self) -> Vec<f64> {
        let mut x = 0.0;
        self.divisions
            .iter()
            .map(|d| {
                let s = x;
                x += d.length;
                s
            })
            .collect()
    }
}

/// Diagonals of the cross-section matrices at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionProps {
    pub radius: f64,
    pub area: f64,
    /// diag of `Es` [N·m², N·m², N·m², N, N, N].
    pub es: V6,
    /// diag of `Ms` per unit length.
    pub ms: V6,
    /// diag of `Ds`.
    pub ds: V6,
}

impl SectionProps {
    /// Circular section of radius r: `A = πr²`, `I = πr⁴/4`, `J = 2I` (spec §3.1–3.2).
    pub fn circular(material: &Material, r: f64) -> Self {
        let a = PI * r * r;
        let i = PI * r.powi(4) / 4.0;
        let j = 2.0 * i;
        let e = material.youngs_modulus;
        let g = material.shear_modulus();
        let rho = material.density;
        let eta = material.damping;
        SectionProps {
            radius: r,
            area: a,
            es: V6::new(g * j, e * i, e * i, e * a, g * a, g * a),
            ms: V6::new(j, i, i, a, a, a) * rho,
            ds: V6::new(j, 3.0 * i, 3.0 * i, 3.0 * a, a, a) * eta,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    #[test]
    fn section_values_match_spec_table() {
        // gvs-spec §3.4, single-actuator base and tip, six-actuator base.
        let m = Material {
            youngs_modulus: 0.617e6,
            poisson_ratio: 0.5,
            density: 1121.0,
            damping: 1e4,
        };
        let s = SectionProps::circular(&m, 0.0125);
        assert!(rel(s.area, 4.9087e-4) < 1e-4);
        assert!(rel(s.es[1], 1.1831e-2) < 1e-4);
        assert!(rel(s.es[3], 302.87) < 1e-4);
        assert!(rel(s.es[4], 100.96) < 1e-4);
        assert!(rel(s.es[0], 7.8872e-3) < 1e-4);
        let s = SectionProps::circular(&m, 0.005);
        assert!(rel(s.es[1], 3.0287e-4) < 1e-4);
        assert!(rel(s.es[5], 16.153) < 1e-4);
        let m6 = Material {
            youngs_modulus: 1e6,
            poisson_ratio: 0.5,
            density: 1000.0,
            damping: 1e4,
        };
        let s = SectionProps::circular(&m6, 0.02);
        assert!(rel(s.es[1], 0.12566) < 1e-4);
        assert!(rel(s.es[0], 8.3776e-2) < 1e-4);
        // damping uses the factor 3 on bending/extension regardless of ν
        assert!(rel(s.ds[1], 3.0 * 1e4 * PI * 0.02f64.powi(4) / 4.0) < 1e-12);
        assert!(rel(s.ds[4], 1e4 * s.area) < 1e-12);
    }

    #[test]
    fn every_stiffness_inertia_and_damping_entry_matches_its_closed_form() {
        // gvs-spec §3.4 for a solid circle of radius r: A = πr², I = πr⁴/4, J = 2I;
        // Ms = ρ diag(J, I, I, A, A, A), Ds = η diag(J, 3I, 3I, 3A, A, A) (§3.4), entry by entry
        let m = Material {
            youngs_modulus: 2e6,
            poisson_ratio: 0.3,
            density: 1200.0,
            damping: 3e3,
        };
        let r = 0.015;
        let s = SectionProps::circular(&m, r);
        let a = PI * r * r;
        let i = PI * r.powi(4) / 4.0;
        let j = 2.0 * i;
        let ms = [j, i, i, a, a, a].map(|x| 1200.0 * x);
        let ds = [j, 3.0 * i, 3.0 * i, 3.0 * a, a, a].map(|x| 3e3 * x);
        // Es = diag(GJ, EI, EI, EA, GA, GA), G = E/(2(1 + ν)) = E/2.6 here (shear factor 1)
        let g = 2e6 / 2.6;
        let es = [g * j, 2e6 * i, 2e6 * i, 2e6 * a, g * a, g * a];
        for k in 0..6 {
            assert!(
                rel(s.es[k], es[k]) < 1e-14,
                "es[{k}] = {} against {}",
                s.es[k],
                es[k]
            );
            assert!(
                rel(s.ms[k], ms[k]) < 1e-14,
                "ms[{k}] = {} against {}",
                s.ms[k],
                ms[k]
            );
            assert!(
                rel(s.ds[k], ds[k]) < 1e-14,
                "ds[{k}] = {} against {}",
                s.ds[k],
                ds[k]
            );
        }
        // for ν = 1/2 (G = E/3) the damping is the stiffness times 3η/E, entry by entry
        let half = Material {
            poisson_ratio: 0.5,
            ..m
        };
        let s = SectionProps::circular(&half, r);
        for k in 0..6 {
            assert!(rel(s.ds[k], 3.0 * 3e3 / 2e6 * s.es[k]) < 1e-14, "ds[{k}]");
        }
    }

    #[test]
    fn invalid_material_names_field_and_range() {
        let m = Material {
            youngs_modulus: 1e6,
            poisson_ratio: 0.7,
            density: 1000.0,
            damping: 0.0,
        };
        let e = m.validate().unwrap_err().to_string();
        assert!(
            e.contains("material.poisson_ratio") && e.contains("0.7") && e.contains("(-1, 0.5]"),
            "{e}"
        );
        let rod = Rod::tapered(
            Material {
                youngs_modulus: 1e6,
                poisson_ratio: 0.5,
                density: 1000.0,
                damping: 0.0,
            },
            -0.2,
            0.01,
            0.01,
        );
        let e = rod.validate().unwrap_err().to_string();
        assert!(
            e.contains("rod.divisions[0].length") && e.contains("-0.2"),
            "{e}"
        );
    }
}
