//! Rod geometry and constitutive data (gvs-spec §3): linearly tapered sections per division
//! (circular, or rectangular, elliptical and tubular: [`Section`]), material (E, ν, ρ, damping
//! constant η),
//! and the per-point cross-section matrices
//! `Es = diag(GJ_t, EI_y, EI_z, EA, GA, GA)`, `Ms = ρ diag(J, I_y, I_z, A, A, A)`,
//! `Ds = η diag(J_t, 3I_y, 3I_z, 3A, A, A)` with `G = E / (2(1+ν))`, `J = I_y + I_z` the polar
//! moment and `J_t` the torsion constant (SoRoSim `MEG`, which takes `J_t = J`; the two are equal
//! for a circle and a tube, see [`SectionProps::rectangle`]).

mod section;

pub use section::*;

use crate::error::{check_positive, check_range, ModelError};
use serde::{Deserialize, Serialize};

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

/// One division of the rod: length and a section tapering linearly over the normalized division
/// coordinate `X̄ ∈ [0, 1]` (spec §3.1): a circle from `radius_start` to `radius_end`, or the
/// rectangle, ellipse or tube of [`DivisionGeometry::section`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DivisionGeometry {
    pub length: f64,
    /// The circle's radius at `X̄ = 0` \[m\]; with a [`Section`], its circumscribed radius
    /// ([`Section::circumradius`]), the farthest the section reaches from the axis.
    pub radius_start: f64,
    /// The same at `X̄ = 1`.
    pub radius_end: f64,
    /// The division's own material where it differs from the rod's (a stiff base and a soft tip,
    /// SoRoSim's material per link); `None`: the rod's ([`Rod::material_of`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<Material>,
    /// A rectangular, elliptical or tubular section in place of the solid circle; `None` (the
    /// default, not written): the circle of the radii.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub section: Option<Section>,
}

impl DivisionGeometry {
    /// A division of section `section` (its radii the circumscribed ones).
    pub fn with_section(length: f64, section: Section) -> Self {
        DivisionGeometry {
            length,
            radius_start: section.circumradius(0.0),
            radius_end: section.circumradius(1.0),
            material: None,
            section: Some(section),
        }
    }

    /// The radius at `X̄` (the circumscribed radius of a [`Section`]): the farthest the section
    /// reaches from the axis.
    pub fn radius_at(&self, x_bar: f64) -> f64 {
        self.radius_start + x_bar * (self.radius_end - self.radius_start)
    }

    /// The section's properties at `X̄` for `material`.
    pub fn props_at(&self, material: &Material, x_bar: f64) -> SectionProps {
        match &self.section {
            None => SectionProps::circular(material, self.radius_at(x_bar)),
            Some(s) => s.props_at(material, x_bar),
        }
    }

    /// The gauge of the section at `X̄` at the point `(y, z)` of the section plane: ≤ 1 inside
    /// (the circle's `√(y² + z²)/r`, the rectangle's `max(2|y|/w, 2|z|/h)`, the ellipse's
    /// `√((2y/w)² + (2z/h)²)`), growing linearly along each ray from the axis.
    pub fn gauge_at(&self, x_bar: f64, y: f64, z: f64) -> f64 {
        match &self.section {
            None => y.hypot(z) / self.radius_at(x_bar),
            Some(s) => {
                let (w, h) = s.extents_at(x_bar);
                let (a, b) = (2.0 * y / w, 2.0 * z / h);
                match s.shape {
                    Shape::Rectangle => a.abs().max(b.abs()),
                    Shape::Ellipse | Shape::Tube { .. } => a.hypot(b),
                }
            }
        }
    }

    /// What the section at `X̄` is, for a message: "radius 0.01 m", "0.03 × 0.01 m rectangle".
    pub fn describe_at(&self, x_bar: f64) -> String {
        match &self.section {
            None => format!("radius {} m", self.radius_at(x_bar)),
            Some(s) => {
                let (w, h) = s.extents_at(x_bar);
                let shape = match s.shape {
                    Shape::Rectangle => "rectangle",
                    Shape::Ellipse => "ellipse",
                    Shape::Tube { .. } => {
                        let r_i = s.inner_radius_at(x_bar);
                        return format!("tube of radius {} m and inner radius {r_i} m", 0.5 * w);
                    }
                };
                format!("{w} × {h} m {shape} (width along y, height along z)")
            }
        }
    }
}

/// Rod: material plus its divisions laid end to end along the local x-axis (a division may have
/// a material of its own, [`DivisionGeometry::material`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Rod {
    pub material: Material,
    pub divisions: Vec<DivisionGeometry>,
}

/// `x` as an abscissa of a rod of `length`: `x` itself in `[0, L]`, `L` for an `x` past the end by
/// at most the rounding of the divisions' summed lengths (`1e-12 L`: `0.7 + 0.2` is
/// `0.8999999999999999`, and `x = 0.9` is the tip), `None` otherwise (NaN included).
pub fn abscissa_on(length: f64, x: f64) -> Option<f64> {
    (x >= 0.0 && x <= length * (1.0 + 1e-12)).then(|| x.min(length))
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
                section: None,
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
            if let Some(s) = &d.section {
                for (name, v) in [("width", s.width), ("height", s.height)] {
                    for (end, x) in ["start", "end"].iter().zip(v) {
                        check_positive(
                            &format!("rod.divisions[{j}].section.{name}_{end}"),
                            x,
                            "m",
                        )?;
                    }
                }
                if let Shape::Tube { inner_radius } = s.shape {
                    let outer = [0.5 * s.width[0], 0.5 * s.width[1]];
                    if s.height != s.width {
                        return Err(ModelError::invalid(
                            format!("rod.divisions[{j}].section.height"),
                            format!(
                                "{:?} m: a tube's outer diameter, equal to `width` {:?} m",
                                s.height, s.width
                            ),
                        ));
                    }
                    for ((end, r_i), r) in ["start", "end"].iter().zip(inner_radius).zip(outer) {
                        if !(r_i >= 0.0 && r_i < r) {
                            // (a wall thinner than the scenario's 1e-7 m is a model's to allow)
                            return Err(ModelError::value(
                                format!("rod.divisions[{j}].section.inner_radius_{end}"),
                                r_i,
                                format!("a radius in [0, {r}) m: inside the outer radius"),
                            ));
                        }
                    }
                }
                for (end, x_bar, r) in [("start", 0.0, d.radius_start), ("end", 1.0, d.radius_end)]
                {
                    let c = s.circumradius(x_bar);
                    if (r - c).abs() > 1e-12 * c {
                        return Err(ModelError::value(
                            format!("rod.divisions[{j}].radius_{end}"),
                            r,
                            format!("the section's circumscribed radius {c} m (`DivisionGeometry::with_section`)"),
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// Total length `L = Σ ℓ_j`.
    pub fn length(&self) -> f64 {
        self.divisions.iter().map(|d| d.length).sum()
    }

    /// `x` as an abscissa of this rod; see [`abscissa_on`].
    pub fn abscissa(&self, x: f64) -> Option<f64> {
        abscissa_on(self.length(), x)
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

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    #[test]
    fn a_sectioned_division_tapers_and_holds_its_tendons_inside() {
        let s = Section {
            shape: Shape::Rectangle,
            width: [0.04, 0.02],
            height: [0.01, 0.01],
        };
        let d = DivisionGeometry::with_section(0.5, s);
        assert!(rel(d.radius_at(0.0), 0.5 * 0.04f64.hypot(0.01)) < 1e-14);
        assert_eq!(s.extents_at(0.5), (0.03, 0.01));
        // the corner is inside, just beyond the short side is not
        assert!(d.gauge_at(0.0, 0.02, 0.005) <= 1.0 + 1e-12);
        assert!(d.gauge_at(0.0, 0.0, 0.0051) > 1.0);
        assert!(
            d.gauge_at(1.0, 0.0101, 0.0) > 1.0,
            "the width tapers to 2 cm"
        );
        let e = DivisionGeometry::with_section(
            0.5,
            Section {
                shape: Shape::Ellipse,
                ..s
            },
        );
        assert!(e.gauge_at(0.0, 0.02 * 0.8, 0.005 * 0.6) <= 1.0 + 1e-12);
        assert!(
            e.gauge_at(0.0, 0.02, 0.005) > 1.0,
            "the box's corner is outside the ellipse"
        );
        let rod = Rod {
            material: Material {
                youngs_modulus: 1e6,
                poisson_ratio: 0.5,
                density: 1000.0,
                damping: 0.0,
            },
            divisions: vec![d],
        };
        rod.validate().unwrap();
        let mut bad = rod.clone();
        bad.divisions[0].section.as_mut().unwrap().height[1] = -0.01;
        let e = bad.validate().unwrap_err().to_string();
        assert!(
            e.contains("rod.divisions[0].section.height_end") && e.contains("-0.01"),
            "{e}"
        );
        let mut bad = rod.clone();
        bad.divisions[0].radius_end = 0.01;
        let e = bad.validate().unwrap_err().to_string();
        assert!(
            e.contains("rod.divisions[0].radius_end") && e.contains("circumscribed"),
            "{e}"
        );
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

    #[test]
    fn a_tube_is_refused_with_its_bore_outside_or_its_sides_unequal() {
        let tube = |inner_radius: [f64; 2], height: [f64; 2]| Rod {
            material: Material {
                youngs_modulus: 1e6,
                poisson_ratio: 0.5,
                density: 1000.0,
                damping: 0.0,
            },
            divisions: vec![DivisionGeometry::with_section(
                0.5,
                Section {
                    shape: Shape::Tube { inner_radius },
                    width: [0.02, 0.01],
                    height,
                },
            )],
        };
        tube([0.008, 0.0], [0.02, 0.01]).validate().unwrap();
        let e = tube([0.008, 0.005], [0.02, 0.01])
            .validate()
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("rod.divisions[0].section.inner_radius_end")
                && e.contains("0.005")
                && e.contains("[0, 0.005)"),
            "{e}"
        );
        let e = tube([-0.001, 0.0], [0.02, 0.01])
            .validate()
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("inner_radius_start") && e.contains("-0.001"),
            "{e}"
        );
        let e = tube([0.008, 0.0], [0.02, 0.02])
            .validate()
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("section.height") && e.contains("outer diameter"),
            "{e}"
        );
    }
}
