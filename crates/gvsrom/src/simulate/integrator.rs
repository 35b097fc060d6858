//! The integrator of a run: the method and tolerances asked for (`--method`, `--rtol`, …), chosen
//! by the rod's damping unless named, and how `meta.json` records them.

use crate::build::Built;
use crate::error::ScenarioError;
use gvs::solve::dynamics::{IntegratorOptions, Method, OdeJacobian};
use gvs::solve::ode::{
    ErrorNorm, FixedStepOptions, GeneralizedAlphaOptions, MassRenewal, NdfOptions, SdirkOptions,
};
use serde::{Deserialize, Serialize};

/// The adaptive integrator asked for (`simulate --method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum MethodChoice {
    Auto,
    Ndf,
    Galpha,
    Sdirk,
}

/// The error test asked for (`simulate --error-norm`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum ErrorNormChoice {
    /// Every coordinate to its own tolerance (ode15s).
    Componentwise,
    /// Positions and velocities in the mass-matrix norm (mass-weighted displacement).
    Mass,
}

impl ErrorNormChoice {
    fn norm(self) -> ErrorNorm {
        match self {
            ErrorNormChoice::Componentwise => ErrorNorm::Componentwise,
            ErrorNormChoice::Mass => ErrorNorm::Mass,
        }
    }
}

/// What the user asked of the integrator (`simulate --method --rtol --atol --max-order
/// --error-norm --rho-inf --fixed-step --fd-jacobian`); `None` and `Auto` leave the choice to
/// [`choose_integrator`]. The default is the command's defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IntegratorChoice {
    pub method: MethodChoice,
    /// Relative tolerance; default 1e-3 (ode15s), or [`gvs::solve::dynamics::LIGHT_DAMPING_RTOL`]
    /// when the automatic method is SDIRK4.
    pub rtol: Option<f64>,
    /// Absolute tolerance; default [`DEFAULT_ATOL`].
    pub atol: Option<f64>,
    /// Highest NDF order (1–5); default 5, or 2 for a lightly damped rod.
    pub max_order: Option<usize>,
    pub error_norm: Option<ErrorNormChoice>,
    /// Generalized-α: spectral radius at infinite frequency, in \[0, 1\]; default
    /// [`DEFAULT_RHO_INF`].
    pub rho_inf: Option<f64>,
    /// A fixed step `h` \[s\]: the fixed-step BDF2 instead of an adaptive method.
    pub fixed_step: Option<f64>,
    /// Finite differences of the first-order right-hand side for the Jacobian (`--fd-jacobian`);
    /// else the structured iteration matrix.
    pub fd_jacobian: bool,
}

impl Default for IntegratorChoice {
    fn default() -> Self {
        IntegratorChoice {
            method: MethodChoice::Auto,
            rtol: None,
            atol: None,
            max_order: None,
            error_norm: None,
            rho_inf: None,
            fixed_step: None,
            fd_jacobian: false,
        }
    }
}

/// Refuses a rod without mass (`material.density = 0`, which statics accept) for what reads its
/// mass matrix, zero there; the damping is not looked at (`modes` are undamped).
pub fn require_mass_only(built: &Built) -> Result<(), ScenarioError> {
    let model = &built.model;
    let massless = (0..model.disc.n_points()).find(|&j| {
        let ms = model.section(j).ms;
        ms.iter().any(|m| m.is_nan() || *m <= 0.0)
    });
    if let Some(j) = massless {
        return Err(ScenarioError::invalid(
            material_field(built, model.disc.points[j].div, "density"),
            "0: a motion needs a rod with mass (a positive density); statics take density 0",
        ));
    }
    Ok(())
}

/// The scenario field that sets `name` (`density` or `damping`) of division `div`'s material: its
/// own (`divisions[1].material.density`) where it differs from the rod's, else the rod's
/// (`material.density`), which the division inherits.
fn material_field(built: &Built, div: usize, name: &str) -> String {
    let rod = &built.model.rod;
    let value = |m: &gvs::rod::Material| match name {
        "density" => m.density,
        _ => m.damping,
    };
    match &rod.divisions[div].material {
        Some(own) if value(own) != value(&rod.material) => {
            format!("divisions[{div}].material.{name}")
        }
        _ => format!("material.{name}"),
    }
}

/// Refuses a rod without mass for a motion (`material.density = 0`, which statics accept): its mass
/// matrix is zero, and the motion it would define has no meaning. Refuses too a damping whose
/// relaxation time `η / E` exceeds [`MAX_RELAXATION_TIME`] (statics ignore the damping). Checked before anything reads
/// the mass matrix: [`choose_integrator`] (every simulation), dynamic datasets and `linearize`;
/// `modes`, undamped, checks the mass alone ([`require_mass_only`]).
pub fn require_mass(built: &Built) -> Result<(), ScenarioError> {
    require_mass_only(built)?;
    // a damping no material has: checked for motions only, as statics ignore it
    for (div, m) in built.model.rod.materials().enumerate() {
        let most = MAX_RELAXATION_TIME * m.youngs_modulus;
        if m.damping <= most {
            continue;
        }
        return Err(ScenarioError::value(
            material_field(built, div, "damping"),
            m.damping,
            format!(
                "at most {most:e} Pa*s for this Young's modulus in a motion: a relaxation time η / E of {:.2e} s against {MAX_RELAXATION_TIME} s accepted (the paper's material: 0.016 s; statics ignore the damping)",
                m.damping / m.youngs_modulus,
            ),
        ));
    }
    Ok(())
}

/// The integrator for `built` (with its reduced model, if attached) under `choice`, and the note
/// to print when the rod's damping chose it (`integrator …` line), else `None`.
///
/// - Jacobian: finite differences with `fd_jacobian`, else the structured one. A decoder's `M(q)`
///   varies strongly, so for it the NDF renews `M` at every attempt ([`MassRenewal::EveryAttempt`];
///   measured on IV-C2's AE-7, 10 s: 2289 steps, 322 failed, 0.27 s, against 2399 steps, 1009
///   failed, 0.31 s when renewed only when slow and 2267 steps, 414 failed, 0.38 s with the
///   first-order form's finite-difference Jacobian, 2r right-hand sides per Jacobian).
/// - Method: `fixed_step` gives the fixed-step BDF2; `galpha` and `sdirk` as named; `auto` and `ndf`
///   with a decoder are the NDF of orders ≤ 5 (SDIRK4, which renews `M` only with `D` and `K`,
///   failed 1864 of 2164 attempts in Newton on IV-C2's AE-2, 0.84 s against 0.1 s); `auto` and `ndf`
///   with the structured Jacobian and neither the NDF's order nor its norm given look at the rod's
///   damping ([`gvs::solve::dynamics::damping_regime`]): for a lightly damped rod (stiffest mode
///   underdamped) `auto` is SDIRK4 with the mass-norm error test at rtol 1e-4 and `ndf` the NDF of
///   orders ≤ 2 with the mass norm; otherwise the NDF of orders ≤ 5, componentwise (ode15s).
pub fn choose_integrator(
    built: &Built,
    choice: &IntegratorChoice,
) -> Result<(IntegratorOptions, Option<String>), ScenarioError> {
    require_mass(built)?;
    check_choice(choice)?;
    let decoder = built
        .reduced
        .as_ref()
        .is_some_and(|r| !r.model.param.is_linear());
    let jacobian = if choice.fd_jacobian {
        OdeJacobian::FiniteDifference
    } else {
        OdeJacobian::Structured
    };
    let mut note = None;
    let rtol = choice.rtol.unwrap_or(NdfOptions::default().rtol);
    let atol = choice.atol.unwrap_or(DEFAULT_ATOL);
    let error_norm = |default: ErrorNorm| choice.error_norm.map_or(default, ErrorNormChoice::norm);
    // the rod's damping chooses for `auto` and `ndf` unless the NDF's order or norm is given
    let ndf_choice = choice.max_order.is_some() || choice.error_norm.is_some();
    let regime = if choice.fixed_step.is_none()
        && matches!(choice.method, MethodChoice::Auto | MethodChoice::Ndf)
        && !ndf_choice
        && jacobian == OdeJacobian::Structured
        && !decoder
    {
        Some(match &built.reduced {
            Some(r) => gvs::solve::dynamics::damping_regime(&r.model)?,
            None => gvs::solve::dynamics::damping_regime(&built.model)?,
        })
    } else {
        None
    };
    let method = match (choice.fixed_step, choice.method) {
        (Some(h), _) => Method::Fixed(FixedStepOptions {
            h,
            // a decoder's M(q): see `FixedStepOptions::second_order`; the same test as the
            // driver's `fixed_step_in_second_order`, which `integrator_record`'s `form` relies on
            second_order: !decoder,
            ..FixedStepOptions::default()
        }),
        (None, MethodChoice::Galpha) => Method::GeneralizedAlpha(GeneralizedAlphaOptions {
            rtol,
            atol,
            rho_inf: choice.rho_inf.unwrap_or(DEFAULT_RHO_INF),
            error_norm: error_norm(ErrorNorm::Componentwise),
            ..GeneralizedAlphaOptions::default()
        }),
        (None, MethodChoice::Sdirk) => Method::Sdirk(SdirkOptions {
            rtol,
            atol,
            error_norm: error_norm(ErrorNorm::Mass),
            ..SdirkOptions::default()
        }),
        (None, MethodChoice::Auto) if regime.is_some_and(|r| r.is_light()) => {
            let zeta = regime.map_or(0.0, |r| r.zeta_max);
            let rtol = choice
                .rtol
                .unwrap_or(gvs::solve::dynamics::LIGHT_DAMPING_RTOL);
            note = Some(format!(
                "integrator SDIRK4 (order 4, L-stable) with the mass-norm error test at rtol {rtol:e}: lightly damped (stiffest mode ζ = {zeta:.3}; --method or --rtol to choose)"
            ));
            Method::Sdirk(SdirkOptions {
                rtol,
                atol,
                error_norm: ErrorNorm::Mass,
                ..SdirkOptions::default()
            })
        }
        (None, MethodChoice::Ndf | MethodChoice::Auto) => {
            let base = NdfOptions {
                rtol,
                atol,
                max_order: choice.max_order.unwrap_or(5),
                error_norm: error_norm(ErrorNorm::Componentwise),
                mass_renewal: if decoder {
                    MassRenewal::EveryAttempt
                } else {
                    MassRenewal::WhenSlow
                },
                ..NdfOptions::default()
            };
            match regime {
                Some(regime) => {
                    if regime.is_light() {
                        note = Some(format!(
                            "integrator NDF orders ≤ 2 with the mass-norm error test: lightly damped (stiffest mode ζ = {:.3}; --max-order or --error-norm to choose)",
                            regime.zeta_max
                        ));
                    }
                    Method::Ndf(gvs::solve::dynamics::ndf_for_regime(&base, &regime))
                }
                None => Method::Ndf(base),
            }
        }
    };
    Ok((IntegratorOptions { method, jacobian }, note))
}

/// The integrator of a run as its provenance records it (`"integrator"`): the method that ran
/// with its tolerances and options (as [`choose_integrator`] resolved them) and what was
/// `requested` (the command's options).
pub fn integrator_record(
    options: &IntegratorOptions,
    requested: &IntegratorChoice,
) -> serde_json::Value {
    use serde_json::json;
    let norm = |n: ErrorNorm| match n {
        ErrorNorm::Componentwise => "componentwise",
        ErrorNorm::Mass => "mass",
    };
    let renewal = |r: MassRenewal| match r {
        MassRenewal::WhenSlow => "when_slow",
        MassRenewal::EveryAttempt => "every_attempt",
    };
    let mut v = match &options.method {
        Method::Ndf(o) => json!({
            "rtol": o.rtol, "atol": o.atol, "max_order": o.max_order, "bdf": o.bdf,
            "error_norm": norm(o.error_norm),
            "mass_renewal": renewal(o.mass_renewal),
            "max_steps": o.max_steps,
        }),
        Method::Fixed(o) => {
            let mut v = json!({"h": o.h, "newton_tol": o.newton_tol, "max_newton": o.max_newton});
            if o.second_order && options.jacobian == OdeJacobian::Structured {
                v["form"] = json!("second_order");
                v["mass_renewal"] = json!(renewal(o.mass_renewal));
            } else {
                v["form"] = json!("first_order");
            }
            v
        }
        Method::GeneralizedAlpha(o) => json!({
            "rtol": o.rtol, "atol": o.atol, "rho_inf": o.rho_inf,
            "error_norm": norm(o.error_norm), "max_steps": o.max_steps,
        }),
        Method::Sdirk(o) => json!({
            "rtol": o.rtol, "atol": o.atol, "error_norm": norm(o.error_norm),
            "max_steps": o.max_steps,
        }),
    };
    v["method"] = json!(options.method.name());
    v["jacobian"] = json!(match options.jacobian {
        OdeJacobian::FiniteDifference => "finite_difference",
        OdeJacobian::Structured => "structured",
    });
    v["requested"] = serde_json::to_value(requested).unwrap_or(serde_json::Value::Null);
    v
}

/// Smallest `--atol` accepted: `1e-14 ≈ 45 ε`. The coordinates of a rod (strain coefficients
/// in 1/m, reduced coordinates, and their rates) are of order 1e-3 … 1e2 in the presets and carry
/// a round-off of `ε` times their scale; a run from rest starts at `q = 0`, where the absolute
/// tolerance alone bounds the error, so below about `10 ε` the error test and Newton's ask for
/// digits no iteration delivers (measured on the single-tendon arm at `--rtol 1e-12`: SDIRK4 took
/// 1371 steps for the first millisecond at `--atol 1e-16`, made no progress in 10 minutes at
/// `--rtol 1e-30 --atol 1e-30`; the NDF failed in Newton at `--atol 1e-30`). The library takes
/// any `atol > 0` (its units are the problem's); `--rtol` is bounded as the library bounds it,
/// [[`gvs::solve::ode::MIN_RTOL`], [`gvs::solve::ode::MAX_RTOL`]).
pub const MIN_ATOL: f64 = 1e-14;

/// `--atol` when it is not given: 1e-6, ode15s's.
pub const DEFAULT_ATOL: f64 = 1e-6;

/// Largest `--rtol` accepted: 0.1. The library takes any `rtol < 1`, but a looser tolerance
/// gives a motion off by percents of the length that reads as a normal run (measured on
/// `six-tendon` under `--steps=-15,0,1` for 3 s against the default tolerances, largest tip error:
/// 0.05 % of L at 1e-2, 1.3 % at 0.1, 4.0 % at 0.5, 9.0 % at 0.9).
pub const MAX_RTOL: f64 = 0.1;

/// Largest `--atol` accepted: 1e-2. The coordinates of a rod are of order 1e-3 … 1e2 (above): an
/// absolute tolerance of their size lets the error test pass anything (measured as for
/// [`MAX_RTOL`]: 0.02 % of L at 1e-3, 0.2 % at 1e-2, 1.8 % at 0.1, 12 % at 1, 150 % at 100).
pub const MAX_ATOL: f64 = 1e-2;

/// `--rtol` in [[`gvs::solve::ode::MIN_RTOL`], [`MAX_RTOL`]] and `--atol` in [[`MIN_ATOL`],
/// [`MAX_ATOL`]]: checked when a run is planned, before anything is written.
pub fn check_tolerances(choice: &IntegratorChoice) -> Result<(), ScenarioError> {
    use gvs::solve::ode::MIN_RTOL;
    if let Some(rtol) = choice.rtol {
        if !(MIN_RTOL..=MAX_RTOL).contains(&rtol) {
            return Err(ScenarioError::value(
                "--rtol",
                rtol,
                format!(
                    "a number in [{MIN_RTOL:e}, {MAX_RTOL}]; below {MIN_RTOL:e} the error estimates are round-off, above {MAX_RTOL} the motion is off by percents of the length"
                ),
            ));
        }
    }
    let atol = choice.atol.unwrap_or(DEFAULT_ATOL);
    if !(MIN_ATOL..=MAX_ATOL).contains(&atol) {
        return Err(ScenarioError::value(
            "--atol",
            atol,
            format!(
                "a number in [{MIN_ATOL:e}, {MAX_ATOL:e}]; below {MIN_ATOL:e} the coordinates' round-off exceeds the tolerance, above {MAX_ATOL:e} it is the size of the coordinates themselves and the error test passes anything"
            ),
        ));
    }
    Ok(())
}

/// Largest relaxation time `η / E` of the material's viscous damping in a motion \[s\]: 1000 s.
/// The paper's silicone has 1e4 Pa·s / 617 kPa ≈ 0.016 s, soft materials 1e-3–1 s; a rod whose
/// damping takes longer than minutes to relax behaves as a rigid one in any motion gvsrom
/// simulates.
pub const MAX_RELAXATION_TIME: f64 = 1e3;

/// Generalized-α's spectral radius at infinite frequency when `--rho-inf` is not given.
pub const DEFAULT_RHO_INF: f64 = 0.8;

/// Checks every option of `choice` ([`check_tolerances`], then the rest) before anything runs:
/// `--max-order` in 1–5, `--rho-inf` in \[0, 1\], `--fixed-step` finite and positive, and no
/// option the chosen method would ignore (`--max-order` only with the NDF, `--rho-inf` only with
/// generalized-α, `--fd-jacobian` not with SDIRK4 or generalized-α, no `--method`, `--rtol`, `--atol` or `--error-norm` with the fixed step, which
/// is a method of its own without error control).
pub fn check_choice(choice: &IntegratorChoice) -> Result<(), ScenarioError> {
    check_tolerances(choice)?;
    if let Some(m) = choice.max_order {
        if !(1..=5).contains(&m) {
            return Err(ScenarioError::value(
                "--max-order",
                m as f64,
                "a whole number from 1 to 5 (the NDF's orders; ≤ 2 are A-stable)",
            ));
        }
    }
    if let Some(rho) = choice.rho_inf {
        if !(0.0..=1.0).contains(&rho) {
            return Err(ScenarioError::value(
                "--rho-inf",
                rho,
                "a number in [0, 1] (1: no numerical dissipation)",
            ));
        }
    }
    let ignored = |option: &str, method: &str| {
        Err(ScenarioError::invalid(
            option,
            format!("does not apply to {method}, which would ignore it"),
        ))
    };
    if let Some(h) = choice.fixed_step {
        if !(h.is_finite() && h > 0.0) {
            return Err(ScenarioError::value(
                "--fixed-step",
                h,
                "a finite step > 0 s",
            ));
        }
        let fixed = "the fixed-step method (--fixed-step)";
        if choice.method != MethodChoice::Auto {
            return ignored("--method", fixed);
        }
        let tolerance = |option: &str| {
            Err(ScenarioError::invalid(
                option,
                "does not apply to the fixed-step method (--fixed-step): its error is not controlled, so it would ignore a tolerance",
            ))
        };
        if choice.rtol.is_some() {
            return tolerance("--rtol");
        }
        if choice.atol.is_some() {
            return tolerance("--atol");
        }
        if choice.error_norm.is_some() {
            return ignored("--error-norm", fixed);
        }
        if choice.max_order.is_some() {
            return ignored("--max-order", fixed);
        }
        if choice.rho_inf.is_some() {
            return ignored("--rho-inf", fixed);
        }
        return Ok(());
    }
    match choice.method {
        MethodChoice::Galpha | MethodChoice::Sdirk if choice.max_order.is_some() => ignored(
            "--max-order",
            "this method (it is the NDF's; --method ndf or auto)",
        ),
        MethodChoice::Auto | MethodChoice::Ndf | MethodChoice::Sdirk
            if choice.rho_inf.is_some() =>
        {
            ignored(
                "--rho-inf",
                "this method (it is generalized-α's; --method galpha)",
            )
        }
        // both iterate on their own second-order matrix `M + γh D + βh² K`
        MethodChoice::Galpha | MethodChoice::Sdirk if choice.fd_jacobian => ignored(
            "--fd-jacobian",
            "this method, which builds its own iteration matrix in second-order form (the finite-difference Jacobian is the NDF's and the fixed step's; --method ndf or auto)",
        ),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with(rtol: Option<f64>, atol: Option<f64>) -> Result<(), ScenarioError> {
        check_tolerances(&IntegratorChoice {
            rtol,
            atol,
            ..IntegratorChoice::default()
        })
    }

    #[test]
    fn tolerances_are_accepted_up_to_their_bounds_and_refused_past_them_naming_the_option() {
        assert!(with(Some(0.1), Some(1e-2)).is_ok());
        assert!(with(Some(1e-12), Some(1e-14)).is_ok());
        for (rtol, atol, flag) in [
            (Some(0.11), None, "--rtol"),
            (Some(0.999), None, "--rtol"),
            (Some(1e-13), None, "--rtol"),
            (None, Some(0.011), "--atol"),
            (None, Some(100.0), "--atol"),
            (None, Some(1e-15), "--atol"),
            (None, Some(f64::INFINITY), "--atol"),
        ] {
            let e = with(rtol, atol).unwrap_err().to_string();
            assert!(e.contains(flag), "{e}");
        }
    }
}
