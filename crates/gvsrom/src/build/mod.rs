//! Scenario → engine: validates every value against its accepted range (naming the TOML field) and
//! builds the rod, discretization, strain basis, tendons, loads and solver options of the engine.
//!
//! The engine validates too; the checks here come first so that messages use the scenario's own key
//! paths, and they add what the engine cannot know (conflicting shorthand keys, sizes).

mod basis;
mod describe;
mod fem_points;
mod limits;
mod loads;
pub mod reduced;
mod resolve;
mod rod;
mod tendon_warnings;
mod tendons;

pub use describe::{body_lines, describe, drive_words, significant, wrench_count, wrench_frames};
pub use limits::*;
pub use loads::loads;
pub use reduced::Reduced;
pub use resolve::{resolve, Request, Resolved};
pub use tendon_warnings::{
    tendon_ends_inside_divisions, uncovered_tendon_components, under_resolved_helices,
    MIN_POINTS_PER_TURN,
};

use basis::{basis, fem_alignment, kinematics_resolution, quadrature};
use rod::{base_pose, division_material, geometry, material, radius_range, reference_strain};
use tendons::tendon;

use crate::error::ScenarioError;
use crate::scenario::Scenario;
use gvs::bodies::RigidBody;
use gvs::discretize::Discretization;
use gvs::loads::Loads;
use gvs::model::Model;
use gvs::rod::Rod;
use gvs::solve::statics::StaticsOptions;
use gvs::strain::{DivisionBasis, LinearBasis};

/// Everything a statics run needs, built and validated.
pub struct Built {
    pub name: String,
    pub model: Model<LinearBasis>,
    pub loads: Loads,
    /// Tendon tensions u \[N\], in tendon order (0 for a tendon driven by its displacement).
    pub u: Vec<f64>,
    /// Per tendon, the displacement δ \[m\] it is driven by (wound in from its rest length), or
    /// `None` for a tension-driven one ([`Built::drives`]).
    pub displacement: Vec<Option<f64>>,
    pub options: StaticsOptions,
    pub centerline_points: usize,
    /// A reduced model (`--model`) that replaces the scenario's basis in statics and dynamics.
    pub reduced: Option<Reduced>,
}

impl Built {
    /// How each tendon is driven: by its displacement if the scenario gives one, else by its
    /// tension.
    pub fn drives(&self) -> Vec<gvs::solve::tendon_drive::Drive> {
        use gvs::solve::tendon_drive::Drive;
        (self.u.iter().zip(&self.displacement))
            .map(|(&u, d)| match d {
                Some(d) => Drive::Displacement(*d),
                None => Drive::Tension(u),
            })
            .collect()
    }

    /// Whether a tendon is driven by its displacement.
    pub fn displacement_driven(&self) -> bool {
        self.displacement.iter().any(Option::is_some)
    }

    /// How this scenario's answer at the tensions `u` used its reduced model outside its
    /// training (`--extrapolate`): the sentences of attaching it, then, for tensions found for
    /// displacement drives, how they lie outside it (`Reduced::found_tensions_outside`; without
    /// `--extrapolate` such tensions are refused). Empty for the full model.
    pub fn model_extrapolated(&self, u: &[f64]) -> Vec<String> {
        let Some(r) = &self.reduced else {
            return vec![];
        };
        let mut out = r.extrapolated.clone();
        if self.displacement_driven() && r.extrapolate {
            out.extend(
                (r.found_tensions_outside(u, &self.drive_flags()).into_iter())
                    .map(|s| format!("the tensions the displacements need: {s}")),
            );
        }
        out
    }

    /// The tensions \[N\] at the coordinates `q` of the model that runs (the reduced one if
    /// attached) under the actuation `channels`: each displacement-driven tendon's found from its
    /// thread's stretch (`gvs::solve::dynamics::drive::thread_tension`; an inextensible one's
    /// stays 0, unknown without the solve), the others the tensions given.
    pub fn found_tensions(&self, q: &[f64], channels: &[f64]) -> Vec<f64> {
        use gvs::solve::dynamics::drive::thread_tension;
        let q = nalgebra::DVector::from_column_slice(q);
        let (lengths, rest, c) = match &self.reduced {
            Some(r) => {
                let m = &r.model;
                let l = m.tendon_lengths(&q, &mut m.workspace());
                (l, m.tendon_rest_lengths(), m.tendon_compliances())
            }
            None => {
                let m = &self.model;
                let l = m.tendon_lengths(&q, &mut m.workspace());
                (l, m.tendon_rest_lengths(), m.tendon_compliances())
            }
        };
        (channels.iter().enumerate())
            .map(|(k, &v)| match (self.displacement.get(k), c.get(k)) {
                (Some(Some(_)), Some(&ck)) if ck > 0.0 => {
                    thread_tension(lengths[k], rest[k], v, ck)
                }
                (Some(Some(_)), _) => 0.0,
                _ => v,
            })
            .collect()
    }

    /// Per tendon, whether it is driven by its displacement.
    pub fn drive_flags(&self) -> Vec<bool> {
        self.displacement.iter().map(Option::is_some).collect()
    }

    /// The actuation channels of a run under the scenario's drives: each tendon's tension \[N\],
    /// or the displacement \[m\] its motor has wound in where it is driven by one
    /// (`gvs::solve::dynamics::drive`).
    pub fn channels(&self) -> Vec<f64> {
        (self.u.iter().zip(&self.displacement))
            .map(|(&u, d)| d.unwrap_or(u))
            .collect()
    }

    /// Refuses a tendon driven by its displacement without its thread's axial stiffness, for
    /// `what` (`"a motion"`, `"the state-space model"`): there the thread's stretch is what carries
    /// the motor's displacement to the rod (`gvs::solve::dynamics::drive`), and an inextensible
    /// tendon held at its length is a constraint `what` does not impose.
    pub fn require_threads(&self, what: &str) -> Result<(), ScenarioError> {
        let missing = (0..self.displacement.len()).find(|&k| {
            self.displacement[k].is_some() && self.model.tendons[k].axial_stiffness.is_none()
        });
        match missing {
            None => Ok(()),
            Some(k) => Err(ScenarioError::invalid(
                format!("tendons[{k}].axial_stiffness"),
                format!(
                    "missing: in {what} a tendon driven by its displacement is an elastic thread whose stretch carries the motor's displacement to the rod; give its axial stiffness EA in N (Young's modulus times the thread's section: about 20000 for a 0.5 mm Dyneema line) — an inextensible tendon held at its length is a constraint {what} does not impose"
                ),
            )),
        }
    }

    /// Refuses a scenario with a displacement-driven tendon for `what` (a command that drives
    /// tendons by tension only): the error names the tendon and how to find its tension.
    pub fn tension_driven_for(&self, what: &str) -> Result<(), ScenarioError> {
        match self.displacement.iter().position(Option::is_some) {
            None => Ok(()),
            Some(k) => Err(ScenarioError::invalid(
                format!("tendons[{k}].displacement"),
                format!(
                    "{what} drives tendons by their tension only (its samples and sweeps are tensions); `gvsrom statics` (Python: `Robot.statics()`) finds the tension that holds this displacement at rest: give it with `--tension` (`u`)"
                ),
            )),
        }
    }

    /// Generalized coordinates of the model that runs: the reduced one if attached.
    pub fn n_dof(&self) -> usize {
        match &self.reduced {
            Some(r) => r.model.n_dof(),
            None => self.model.n_dof(),
        }
    }

    /// Tensions `u` \[N\] for a run in place of the scenario's, checked as a scenario built with
    /// them (`--tension`) would be: one value for every tendon or one per tendon
    /// ([`crate::scenario::tensions_for`]), finite, and plausible with the loads
    /// ([`crate::plausibility::check`]). Returns one value per tendon.
    pub fn tensions(&self, u: &[f64]) -> Result<Vec<f64>, ScenarioError> {
        let u = crate::scenario::tensions_for(self.model.n_actuators(), u)?;
        for (k, v) in u.iter().enumerate() {
            finite(&format!("tendons[{k}].tension"), *v)?;
        }
        let u_abs: Vec<f64> = u.iter().map(|v| v.abs()).collect();
        crate::plausibility::check(self, &u_abs, 1.0)?;
        Ok(u)
    }
}

/// Tendon `k`'s displacement, if it is driven by one: finite, and not with a tension.
fn displacement(k: usize, t: &crate::scenario::TendonSpec) -> Result<Option<f64>, ScenarioError> {
    let Some(d) = t.displacement else {
        return Ok(None);
    };
    finite(&format!("tendons[{k}].displacement"), d)?;
    if t.tension != 0.0 {
        return Err(ScenarioError::invalid(
            format!("tendons[{k}]"),
            format!(
                "both `tension` ({} N) and `displacement` ({d} m) are given: a tendon is driven by one of them (statics finds the tension a displacement needs)",
                t.tension
            ),
        ));
    }
    Ok(Some(d))
}

/// Each displacement less than its tendon's rest length in magnitude (a tendon cannot be wound
/// in, or paid out, by its whole length).
fn check_displacements(
    model: &Model<LinearBasis>,
    displacement: &[Option<f64>],
) -> Result<(), ScenarioError> {
    let rest = model.tendon_rest_lengths();
    for (k, (d, rest)) in displacement.iter().zip(rest).enumerate() {
        if let Some(d) = *d {
            if d.abs() >= rest {
                return Err(ScenarioError::value(
                    format!("tendons[{k}].displacement"),
                    d,
                    format!("|δ| below the tendon's rest length, {rest:.6} m"),
                ));
            }
        }
    }
    Ok(())
}

/// Validates `s` and builds the engine's model, loads, tensions and solver options; the loads must
/// pass [`crate::plausibility::check`] with the scenario's tensions and load factor 1.
pub fn build(s: &Scenario) -> Result<Built, ScenarioError> {
    let material = material(s)?;
    if s.divisions.is_empty() {
        return Err(ScenarioError::invalid(
            "divisions",
            "at least one [[divisions]] entry is required",
        ));
    }
    let geometry = s
        .divisions
        .iter()
        .enumerate()
        .map(|(j, d)| {
            let mut g = geometry(j, d)?;
            g.material = division_material(j, d, &material)?;
            Ok(g)
        })
        .collect::<Result<Vec<_>, ScenarioError>>()?;
    let rod = Rod {
        material,
        divisions: geometry,
    };
    let length = rod.length();
    for (j, d) in s.divisions.iter().enumerate() {
        radius_range(j, d, length)?;
    }
    let bases = s
        .divisions
        .iter()
        .enumerate()
        .map(|(j, d)| basis(j, d))
        .collect::<Result<Vec<_>, _>>()?;
    let n_dof: usize = bases.iter().map(DivisionBasis::dofs).sum();
    if n_dof > MAX_DOF {
        return Err(ScenarioError::invalid(
            "divisions",
            format!(
                "the basis has {n_dof} DOF (accepted <= {MAX_DOF}): statics factorizes a dense {n_dof} × {n_dof} Jacobian per iteration; lower the basis orders or elements"
            ),
        ));
    }
    let quads = s
        .divisions
        .iter()
        .zip(&bases)
        .enumerate()
        .map(|(j, (d, b))| quadrature(j, d, b))
        .collect::<Result<Vec<_>, _>>()?;
    let base = base_pose(s)?;
    let tendons = s
        .tendons
        .iter()
        .enumerate()
        .map(|(k, t)| tendon(k, t, &rod))
        .collect::<Result<Vec<_>, _>>()?;
    let u = s
        .tendons
        .iter()
        .enumerate()
        .map(|(k, t)| finite(&format!("tendons[{k}].tension"), t.tension))
        .collect::<Result<Vec<_>, _>>()?;
    let displacement = s
        .tendons
        .iter()
        .enumerate()
        .map(|(k, t)| displacement(k, t))
        .collect::<Result<Vec<_>, _>>()?;
    let loads = loads(s, length)?;
    s.solver.validate()?;
    let centerline_points = s.output.centerline_points;
    if !(2..=MAX_CENTERLINE_POINTS).contains(&centerline_points) {
        return Err(ScenarioError::value(
            "output.centerline_points",
            centerline_points as f64,
            format!("an integer in [2, {MAX_CENTERLINE_POINTS}]"),
        ));
    }

    let bodies = s
        .bodies
        .iter()
        .map(|b| RigidBody {
            // a tip body at 0.9 m on divisions of 0.7 + 0.2 m sits at their sum, 0.8999999999999999
            x: gvs::rod::abscissa_on(length, b.x).unwrap_or(b.x),
            mass: b.mass,
            center: b.center,
            inertia: b.inertia.tensor(),
        })
        .collect::<Vec<_>>();
    for (k, b) in bodies.iter().enumerate() {
        b.validate(k, length)?;
    }
    let mut extra_x = loads.point_abscissae();
    extra_x.extend(bodies.iter().map(|b| b.x));
    let disc = Discretization::new(&rod, &quads, s.magnus, &extra_x)?;
    if n_dof.saturating_mul(disc.n_sites()) > MAX_BASIS_SIZE {
        return Err(ScenarioError::invalid(
            "divisions",
            format!(
                "the model is too large: {n_dof} DOF × {} strain sites = {} (accepted <= {MAX_BASIS_SIZE}); lower the basis orders/elements or the quadrature points",
                disc.n_sites(),
                n_dof * disc.n_sites()
            ),
        ));
    }
    let basis = LinearBasis::per_division(&disc, &bases)?;
    let reference = s
        .divisions
        .iter()
        .enumerate()
        .map(|(j, d)| reference_strain(j, d))
        .collect::<Result<Vec<_>, _>>()?;
    let model = Model::new(rod, disc, basis, tendons)?
        .with_base(base)
        .with_reference_strain(|_, div| reference[div])
        .with_bodies(bodies)?;
    // the loads as the points take them (`check` too: a distributed load they do not resolve)
    model.prepare_loads(&loads)?;
    check_displacements(&model, &displacement)?;
    let built = Built {
        name: s.name.clone().unwrap_or_else(|| "scenario".to_string()),
        model,
        loads,
        u,
        displacement,
        options: s.solver.clone(),
        centerline_points,
        reduced: None,
    };
    let u_abs: Vec<f64> = built.u.iter().map(|v| v.abs()).collect();
    crate::plausibility::check(&built, &u_abs, 1.0)?;
    Ok(built)
}

/// The divisions of `s` whose points integrate their basis poorly: the kinematics less exactly
/// than the stiffness (`basis::kinematics_resolution`), or a fem basis under a quadrature that
/// straddles its elements' kinks (`basis::fem_alignment`). One sentence each, for the front-ends
/// to warn with, as [`uncovered_tendon_components`]. Empty for a scenario that does not build
/// (its error says why).
pub fn under_integrated_divisions(s: &Scenario) -> Vec<String> {
    (s.divisions.iter().enumerate())
        .flat_map(|(j, d)| {
            let checked = basis(j, d)
                .ok()
                .and_then(|b| quadrature(j, d, &b).ok().map(|q| (b, q)));
            let Some((b, q)) = checked else {
                return vec![];
            };
            [
                kinematics_resolution(j, &b, &q, s.magnus),
                fem_alignment(j, &b, &q),
            ]
            .into_iter()
            .flatten()
            .collect()
        })
        .collect()
}

/// The warnings of a built model alone: tendon loads the basis cannot hold
/// ([`uncovered_tendon_components`]), tendon ends inside divisions
/// ([`tendon_ends_inside_divisions`]) and helices sampled by too few points
/// ([`under_resolved_helices`]).
pub fn model_warnings(model: &Model<LinearBasis>) -> Vec<String> {
    let mut w = uncovered_tendon_components(model);
    w.extend(tendon_ends_inside_divisions(model));
    w.extend(under_resolved_helices(model));
    w
}

/// Every build warning of `s` built as `built`: [`model_warnings`] and divisions whose points
/// integrate their basis poorly ([`under_integrated_divisions`]: the kinematics, a fem basis's
/// element ends).
pub fn warnings(s: &Scenario, built: &Built) -> Vec<String> {
    let mut w = model_warnings(&built.model);
    w.extend(under_integrated_divisions(s));
    w
}

impl<'a> From<&'a Built> for crate::plausibility::Subject<'a> {
    fn from(b: &'a Built) -> Self {
        crate::plausibility::Subject {
            model: &b.model,
            u: &b.u,
            loads: &b.loads,
        }
    }
}
