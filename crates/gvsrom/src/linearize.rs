//! A scenario's equations of motion linearized for control: `δẋ = A δx + B δu`, `δy = C δx` with the
//! state `x = [q; q̇]`, the tendon tensions `u` and the output `y`, the positions of the tip (by
//! default) or of points along the rod in world axes ([`Outputs`]), about the
//! static equilibrium under the scenario's tensions (as `gvsrom statics` solves it) or about any
//! state. With a reduced model attached, its `2r`-state linearization: the same engine on the
//! decoder's coordinates.
//!
//! * `A`, `B`: the engine's [`Model::linearize`] (gvs-spec §9.3): exact static part, the inertial
//!   terms that vanish at rest included in motion; about an equilibrium
//!   [`Model::linearize_equilibrium`] (`q̈ = 0` held: analytic throughout).
//! * `C = [R_tip J_tip,v  0]` (3 × 2n): the tip's world velocity per unit `q̇` (rows 4–6 of the tip
//!   Jacobian, body frame, rotated to the world); with several output points, their 3 rows each,
//!   `∂p(X)/∂q` of the centreline between the computational points
//!   ([`Model::position_jacobian_at`]; `R_i J_v,i` at a point); with the tip's orientation as an
//!   output, 3 rows `[R_tip J_tip,ω  0]` after them (its small rotation in world axes); with
//!   tendon lengths, a row `[∂ℓ_k/∂q  0]` per tendon last ([`Model::tendon_length_jacobian`]).
//! * Poles: the eigenvalues of `A`, each with its natural frequency `|λ|/2π` and damping ratio
//!   `ζ = −Re λ / |λ|`; conjugate pairs listed once (`Im λ ≥ 0`), slowest (`|λ|` smallest) first.
//! * Static gain (about an equilibrium): `G = −C A⁻¹ B` (C's rows × n_actuators), the settled
//!   change of each output per newton of each tendon; it equals the derivative
//!   of the equilibrium's output positions in the tensions (and of its tendon lengths: the
//!   tendons' compliance, `∂ℓ/∂u = X_e (1/EA + d²/EI)` for a straight tendon on a straight rod).

use crate::build::Built;
use crate::error::{ScenarioError, StaticsFailure};
use crate::statics::{self, StaticsReport};
use gvs::dynamics::{Channel, DynamicsError, StateSpace};
use gvs::error::{fmt_rounded, fmt_value};
use gvs::model::Model;
use gvs::strain::StrainParam;
use gvs::ModelError;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use thiserror::Error;

/// A pole is unstable when `Re λ > UNSTABLE_RATIO |λ|` (a damping ratio below `−UNSTABLE_RATIO`):
/// well above the eigensolver's rounding on the imaginary axis of an undamped model.
pub const UNSTABLE_RATIO: f64 = 1e-8;

/// Poles printed when `--count` is not given.
pub const DEFAULT_COUNT: usize = 10;

#[derive(Debug, Error)]
pub enum LinearizeError {
    #[error("--sample-time `{}`: expected a duration in seconds, finite and > 0, at most {MAX_SAMPLE_TIME} (the hold of the zero-order-hold discretization, e.g. 0.01 for a 100 Hz controller)", fmt_value(*value))]
    SampleTime { value: f64 },
    #[error("--sample-time `{}`: the zero-order-hold matrices over it are not finite ({why}); accepted: a shorter hold{}", fmt_value(*value), match most { Some(h) => format!(", below about {} s, where e^(λh) reaches the largest float", fmt_value(*h)), None => String::new() })]
    HoldOverflow {
        value: f64,
        why: String,
        most: Option<f64>,
    },
    #[error("{field} `{}`: expected abscissae along the rod, each finite and within [0, {}] m (0 the base, {} m the tip)", fmt_value(*value), fmt_rounded(*length), fmt_rounded(*length))]
    OutputAt {
        field: &'static str,
        value: f64,
        length: f64,
    },
    #[error("{field}: no abscissa given; expected at least one (the tip is {} m)", fmt_rounded(*length))]
    NoOutput { field: &'static str, length: f64 },
    #[error("--output-tendon-lengths: the rod has no tendons, so no tendon length to output; accepted with tendons only")]
    NoTendons,
    #[error("--count `{value}`: expected an integer ≥ 1 (the number of slowest poles to print; the linearization has {n_poles} states, so at most {n_poles} poles)")]
    Count { value: String, n_poles: usize },
    #[error("the equilibrium: {0}")]
    Statics(#[from] StaticsFailure),
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error("the linearization: {0}")]
    Dynamics(#[from] DynamicsError),
}

/// How many poles to print for `--count text` (`None`: [`DEFAULT_COUNT`]): an integer ≥ 1, else an
/// error naming the value; a count beyond the poles prints them all.
pub fn parse_count(text: Option<&str>, n_states: usize) -> Result<usize, LinearizeError> {
    match text {
        None => Ok(DEFAULT_COUNT),
        Some(t) => match t.trim().parse::<usize>() {
            Ok(k) if k >= 1 => Ok(k),
            _ => Err(LinearizeError::Count {
                value: t.to_string(),
                n_poles: n_states,
            }),
        },
    }
}

/// Longest sample time \[s\] accepted: far beyond any controller's (ms to s) and any soft arm's
/// slowest time constant; the hold of 1e300 s that was accepted before overflowed `A h`.
pub const MAX_SAMPLE_TIME: f64 = 1e4;

/// A sample time `h` \[s\] of [`Linearization::discretize`]: finite, > 0 and at most
/// [`MAX_SAMPLE_TIME`], else an error naming it (checked before the equilibrium is solved, as a bad
/// `--count` is).
pub fn check_sample_time(h: f64) -> Result<(), LinearizeError> {
    if h.is_finite() && h > 0.0 && h <= MAX_SAMPLE_TIME {
        Ok(())
    } else {
        Err(LinearizeError::SampleTime { value: h })
    }
}

/// One pole of the linearization (an eigenvalue `λ` of `A`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Pole {
    /// `Re λ` \[1/s\].
    pub re: f64,
    /// `Im λ ≥ 0` \[rad/s\] (the conjugate is not listed).
    pub im: f64,
    /// `|λ| / 2π` \[Hz\].
    pub natural_frequency_hz: f64,
    /// `−Re λ / |λ|`: 0 undamped, 1 critical, > 1 for a real pole's pair, negative if unstable.
    pub damping_ratio: f64,
}

/// The linearization (also the `--json` output, with the model path and provenance added).
#[derive(Debug, Clone, Serialize)]
pub struct Linearization {
    pub scenario: String,
    /// Tendon tensions u₀ \[N\] of the operating point.
    pub u: Vec<f64>,
    pub n_dof: usize,
    pub n_actuators: usize,
    /// `"equilibrium"` (solved as `gvsrom statics`) or `"state"` (given).
    pub about: &'static str,
    /// The operating point's `q` and `q̇`.
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    /// `ẋ = f(x₀, u₀)` there (≈ 0 about an equilibrium).
    pub xdot: Vec<f64>,
    /// Tip position at `q` (world) \[m\].
    pub tip_position: [f64; 3],
    /// The abscissae \[m\] of the output points, in the order of `C`'s row triples.
    pub outputs: Vec<f64>,
    /// Their positions at `q` (world) \[m\].
    pub output_positions: Vec<[f64; 3]>,
    /// With the tip's orientation as an output (`--output-tip-orientation`), the tip's rotation
    /// matrix at `q` (rows, section → world): `C`'s 3 rows after the positions are its small
    /// rotation `δθ` in world axes \[rad\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub output_tip_rotation: Option<[[f64; 3]; 3]>,
    /// With tendon lengths as outputs (`--output-tendon-lengths`), each tendon's length at `q` \[m\]:
    /// `C`'s last rows (`∂ℓ/∂q`, one per tendon, after the positions and the orientation); empty
    /// otherwise.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub output_tendon_lengths: Vec<f64>,
    /// The actuators whose channel is their motor's displacement \[m\] through the elastic
    /// thread (`tendons[k].displacement` with its `axial_stiffness`,
    /// `gvs::dynamics::Channel`): `B`'s and the static gain's columns are per metre wound in
    /// there, per newton of tension elsewhere; empty (and not written) when every channel is a
    /// tension.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub displacement_channels: Vec<usize>,
    /// `A` (2n × 2n), rows.
    pub a: Vec<Vec<f64>>,
    /// `B` (2n × n_actuators), rows.
    pub b: Vec<Vec<f64>>,
    /// `C` (3k × 2n for k output points; then 3 rows of the tip's orientation and a row per tendon
    /// when they are outputs), rows.
    pub c: Vec<Vec<f64>>,
    /// Every pole (`n` with `Im λ ≥ 0` for an underdamped model; real poles each listed), by `|λ|`.
    pub poles: Vec<Pole>,
    /// The material's relaxation time `t_d = min Ds/Es` \[s\] (Kelvin–Voigt: `3η/E`; 0 undamped).
    pub damping_time_s: f64,
    /// Poles within 5 % of `−1/t_d`: each overdamped mode of a Kelvin–Voigt rod has its slow pole
    /// there (`λ² + t_d ω² λ + ω² = 0` → `λ → −1/t_d` as `ω → ∞`), so they cluster: all real when
    /// the stiffness is proportional to the damping, some paired with small imaginary parts when
    /// loads and tendons stiffen the rod unlike its damping.
    pub relaxation_poles: usize,
    /// Poles with `Re λ > UNSTABLE_RATIO |λ|` (conjugates counted): directions in which the
    /// operating point is unstable. An undamped model's poles lie on the imaginary axis, up to
    /// rounding (`|Re λ| ~ 1e-12 |λ|`), and count as stable.
    pub unstable_poles: usize,
    /// Static gain `−C A⁻¹ B` (C's rows × n_actuators) \[m/N\] about an equilibrium; `None` about
    /// a state, or if `A` is singular. The tendon rows are the tendons' compliance `∂ℓ_j/∂u_k`.
    pub static_gain: Option<Vec<Vec<f64>>>,
    /// Wall time of the linearization \[s\] (`A`, `B`, `C` and the poles; not the equilibrium).
    pub time_s: f64,
    /// With a sample time: the zero-order-hold discretization `x_{k+1} = A_d x_k + B_d u_k`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub discrete: Option<Discrete>,
    /// About an equilibrium, its solver's residual `‖R‖∞`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub equilibrium_residual_norm: Option<f64>,
}

impl Linearization {
    /// `A` as a matrix.
    pub fn a_matrix(&self) -> DMatrix<f64> {
        from_rows(&self.a)
    }

    /// `B` as a matrix.
    pub fn b_matrix(&self) -> DMatrix<f64> {
        from_rows(&self.b)
    }

    /// `C` as a matrix.
    pub fn c_matrix(&self) -> DMatrix<f64> {
        from_rows(&self.c)
    }

    /// The static gain (3k × n_actuators) as a matrix, if there is one.
    pub fn static_gain_matrix(&self) -> Option<DMatrix<f64>> {
        self.static_gain.as_deref().map(from_rows)
    }
}

impl Discrete {
    /// `A_d` as a matrix.
    pub fn ad_matrix(&self) -> DMatrix<f64> {
        from_rows(&self.ad)
    }

    /// `B_d` as a matrix.
    pub fn bd_matrix(&self) -> DMatrix<f64> {
        from_rows(&self.bd)
    }
}

/// The zero-order-hold discretization of a linearization: `δx_{k+1} = A_d δx_k + B_d δu_k` for
/// tensions held over each sample time `h` (Van Loan): `exp([A B; 0 0] h) = [A_d B_d; 0 I]`, so
/// `A_d = e^{A h}` and `B_d = ∫₀^h e^{A s} ds B`. Its poles are `e^{λ h}`.
#[derive(Debug, Clone, Serialize)]
pub struct Discrete {
    /// `h` \[s\].
    pub sample_time_s: f64,
    /// `A_d` (2n × 2n), rows.
    pub ad: Vec<Vec<f64>>,
    /// `B_d` (2n × n_actuators), rows.
    pub bd: Vec<Vec<f64>>,
    /// `max |e^{λ h}|` over the poles: below 1 for a stable operating point.
    pub spectral_radius: f64,
}

impl Linearization {
    /// Adds the zero-order-hold discretization at the sample time `h` \[s\] ([`Discrete`]).
    pub fn discretize(&mut self, h: f64) -> Result<(), LinearizeError> {
        check_sample_time(h)?;
        let (a, b) = (self.a_matrix(), self.b_matrix());
        let (n2, na) = (a.nrows(), b.ncols());
        let mut m = DMatrix::zeros(n2 + na, n2 + na);
        m.view_mut((0, 0), (n2, n2)).copy_from(&(&a * h));
        m.view_mut((0, n2), (n2, na)).copy_from(&(&b * h));
        let e = m.exp();
        let ad = e.view((0, 0), (n2, n2)).into_owned();
        let bd = e.view((0, n2), (n2, na)).into_owned();
        if ad.iter().chain(bd.iter()).any(|v| !v.is_finite()) {
            // e^{λh} beyond the largest float (e^709.78) for an unstable pole λ
            let fastest = (self.poles.iter().map(|p| p.re)).fold(f64::NEG_INFINITY, f64::max);
            let (why, most) = match fastest > 0.0 {
                true => (
                    format!(
                        "e^(λh) of the unstable pole λ = {} 1/s overflows",
                        fmt_value(fastest)
                    ),
                    Some(f64::MAX.ln() / fastest),
                ),
                false => ("e^(Ah) overflows in floating point".to_string(), None),
            };
            return Err(LinearizeError::HoldOverflow {
                value: h,
                why,
                most,
            });
        }
        let spectral_radius = self
            .poles
            .iter()
            .fold(0.0_f64, |r, p| r.max((p.re * h).exp()));
        self.discrete = Some(Discrete {
            sample_time_s: h,
            ad: rows(&ad),
            bd: rows(&bd),
            spectral_radius,
        });
        Ok(())
    }
}

/// The `--json` document: the linearization, the reduced model used and how it was made.
#[derive(Debug, Serialize)]
pub struct LinearizationJson<'a> {
    #[serde(flatten)]
    pub report: &'a Linearization,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub model_extrapolated: Vec<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub provenance: Option<&'a crate::provenance::Provenance>,
}

/// Where the output `y` is read: the positions of points along the rod, by abscissa, and, if
/// asked, the tip's orientation (3 rows of `C`) and the tendons' lengths (one row each) after them.
#[derive(Debug, Clone, PartialEq)]
pub struct Outputs {
    xs: Vec<f64>,
    tip_orientation: bool,
    tendon_lengths: bool,
}

impl Outputs {
    /// The tip's position alone (the default).
    pub fn tip(built: &Built) -> Self {
        Outputs {
            xs: vec![built.model.disc.length()],
            tip_orientation: false,
            tendon_lengths: false,
        }
    }

    /// The positions at the abscissae `xs` \[m\] (world axes, 3 rows of `C` each, in this order),
    /// each finite and within `[0, L]`; at least one.
    pub fn at(built: &Built, xs: &[f64]) -> Result<Self, LinearizeError> {
        let xs = check_abscissae("--output-at", xs, built.model.disc.length())?;
        Ok(Outputs {
            xs,
            tip_orientation: false,
            tendon_lengths: false,
        })
    }

    /// Adds the tendons' lengths \[m\] after the positions, one row of `C` each
    /// ([`gvs::model::Model::tendon_length_jacobian`]): for actuators under position control, and
    /// the tendons' compliance `∂ℓ/∂u` in the static gain. Refused for a rod without tendons.
    pub fn with_tendon_lengths(self, built: &Built) -> Result<Self, LinearizeError> {
        match built.model.n_actuators() {
            0 => Err(LinearizeError::NoTendons),
            _ => Ok(Outputs {
                tendon_lengths: true,
                ..self
            }),
        }
    }

    /// Adds the tip's orientation after the positions, 3 rows of `C`: the small rotation `δθ`
    /// of the tip section in world axes, `R_tip J_tip,ω δq` (its rotation turns by `exp([δθ]×)`),
    /// for a controller that points the tip.
    pub fn with_tip_orientation(self) -> Self {
        Outputs {
            tip_orientation: true,
            ..self
        }
    }

    /// Whether the tip's orientation is an output.
    pub fn tip_orientation(&self) -> bool {
        self.tip_orientation
    }

    /// The abscissae.
    pub fn abscissae(&self) -> &[f64] {
        &self.xs
    }

    /// Whether the tendons' lengths are outputs too.
    pub fn tendon_lengths(&self) -> bool {
        self.tendon_lengths
    }
}

/// The abscissae `xs` of option `field` (at least one, each finite and within `[0, length]`; one
/// past the tip by the rounding of the divisions' summed lengths is the tip,
/// [`gvs::rod::abscissa_on`]): where positions along the rod are read.
pub fn check_abscissae(
    field: &'static str,
    xs: &[f64],
    length: f64,
) -> Result<Vec<f64>, LinearizeError> {
    if xs.is_empty() {
        return Err(LinearizeError::NoOutput { field, length });
    }
    xs.iter()
        .map(|&value| {
            gvs::rod::abscissa_on(length, value).ok_or(LinearizeError::OutputAt {
                field,
                value,
                length,
            })
        })
        .collect()
}

/// Solves the equilibrium of `built` (as `gvsrom statics` does, with the reduced model if one is
/// attached) and linearizes about it, at rest.
pub fn about_equilibrium(
    built: &Built,
    outputs: &Outputs,
) -> Result<(StaticsReport, Linearization), LinearizeError> {
    crate::simulate::require_mass(built)?;
    // a tendon driven by its displacement is an input through its elastic thread
    built.require_threads("the state-space model")?;
    let eq = statics::solve(built)?;
    statics::check_reduced(built, &eq)?;
    let q = DVector::from_column_slice(&eq.q);
    let qd = DVector::zeros(q.len());
    // the tensions found for the drives, and each channel's kind (a slack tendon's motor moves
    // nothing to first order)
    let channels: Vec<Channel> = (built.displacement.iter().enumerate())
        .map(|(k, d)| match d {
            None => Channel::Tension,
            Some(_) => Channel::Displacement {
                taut: !eq.drives.get(k).is_some_and(|r| r.slack),
            },
        })
        .collect();
    let at = Point {
        q: &q,
        qd: &qd,
        u: &eq.u,
        channels: &channels,
    };
    let mut lin = match &built.reduced {
        Some(r) => on_model(built, &r.model, &at, outputs, true)?,
        None => on_model(built, &built.model, &at, outputs, true)?,
    };
    lin.about = "equilibrium";
    lin.equilibrium_residual_norm = Some(eq.residual_norm);
    lin.static_gain = static_gain(&lin);
    Ok((eq, lin))
}

/// Linearizes `built` (its reduced model if one is attached) at the state `(q, q̇)` under the
/// tensions `u`, which the caller has checked (lengths, finite, a reduced model's range).
pub fn about_state(
    built: &Built,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    u: &[f64],
    outputs: &Outputs,
) -> Result<Linearization, LinearizeError> {
    crate::simulate::require_mass(built)?;
    let at = Point {
        q,
        qd,
        u,
        channels: &[],
    };
    match &built.reduced {
        Some(r) => on_model(built, &r.model, &at, outputs, false),
        None => on_model(built, &built.model, &at, outputs, false),
    }
}

/// An operating point: the state, every tension there, and how each channel enters (empty: all
/// by tension).
struct Point<'a> {
    q: &'a DVector<f64>,
    qd: &'a DVector<f64>,
    u: &'a [f64],
    channels: &'a [Channel],
}

fn on_model<P: StrainParam>(
    built: &Built,
    model: &Model<P>,
    at: &Point<'_>,
    outputs: &Outputs,
    equilibrium: bool,
) -> Result<Linearization, LinearizeError> {
    let Point { q, qd, u, channels } = *at;
    let start = std::time::Instant::now();
    let n = model.n_dof();
    let loads = model.prepare_loads(&built.loads)?;
    let mut ws = model.workspace();
    let StateSpace { a, b, xdot } = if equilibrium {
        model.linearize_equilibrium_driven(q, u, channels, &loads, &mut ws)?
    } else {
        model.linearize(q, qd, u, &loads, &mut ws)?
    };
    let displacement_channels: Vec<usize> = (channels.iter().enumerate())
        .filter(|(_, c)| **c != Channel::Tension)
        .map(|(k, _)| k)
        .collect();
    let t_d = model.damping_time();
    let poles = poles(&a);

    model.forward(q, &mut ws, true);
    let pos = ws.g[model.disc.tip()].pos;
    let xs = outputs.abscissae();
    let na = if outputs.tendon_lengths() {
        model.n_actuators()
    } else {
        0
    };
    let turns = if outputs.tip_orientation() { 3 } else { 0 };
    let mut c = DMatrix::zeros(3 * xs.len() + turns + na, 2 * n);
    let mut output_positions = Vec::with_capacity(xs.len());
    for (k, &x) in xs.iter().enumerate() {
        let (p, dp) = model.position_jacobian_at(&ws, x);
        c.view_mut((3 * k, 0), (3, n)).copy_from(&dp);
        output_positions.push([p[0], p[1], p[2]]);
    }
    let tip = model.disc.tip();
    let rot = ws.g[tip].rot;
    let output_tip_rotation = (turns > 0).then(|| {
        let j = ws.jac.columns(tip * n, n);
        c.view_mut((3 * xs.len(), 0), (3, n))
            .copy_from(&(rot * j.fixed_rows::<3>(0)));
        std::array::from_fn(|i| std::array::from_fn(|k| rot[(i, k)]))
    });
    let mut output_tendon_lengths = vec![0.0; na];
    if na > 0 {
        let dl = model.tendon_length_jacobian(q, &mut ws);
        c.view_mut((3 * xs.len() + turns, 0), (na, n))
            .tr_copy_from(&dl);
        model.tendon_lengths_after_forward(&ws, &mut output_tendon_lengths);
    }

    Ok(Linearization {
        scenario: built.name.clone(),
        u: u.to_vec(),
        n_dof: n,
        n_actuators: model.n_actuators(),
        about: "state",
        q: q.iter().copied().collect(),
        qd: qd.iter().copied().collect(),
        xdot: xdot.iter().copied().collect(),
        tip_position: [pos[0], pos[1], pos[2]],
        outputs: xs.to_vec(),
        output_positions,
        output_tip_rotation,
        output_tendon_lengths,
        displacement_channels,
        relaxation_poles: relaxation_poles(&poles, t_d),
        unstable_poles: poles
            .iter()
            .filter(|p| p.damping_ratio < -UNSTABLE_RATIO)
            .map(|p| if p.im > 0.0 { 2 } else { 1 })
            .sum(),
        poles,
        damping_time_s: t_d,
        a: rows(&a),
        b: rows(&b),
        c: rows(&c),
        static_gain: None,
        time_s: start.elapsed().as_secs_f64(),
        discrete: None,
        equilibrium_residual_norm: None,
    })
}

/// The eigenvalues of `A`, conjugate pairs once (`Im λ ≥ 0`), by `|λ|` ascending. `A` is balanced
/// first ([`balance`]): a rod's `[0 I; −M⁻¹K −M⁻¹D]` has a norm of order `ω_max²`, and the QR
/// algorithm's absolute error `ε‖A‖` would swamp the slow poles; balanced, the norm is of order
/// `ω_max`.
pub fn poles(a: &DMatrix<f64>) -> Vec<Pole> {
    let eig = balance(a).complex_eigenvalues();
    let mut poles: Vec<Pole> = eig
        .iter()
        // one of each conjugate pair (the real Schur form gives real poles a zero `Im`)
        .filter(|l| l.im >= 0.0)
        .map(|l| {
            let modulus = l.norm();
            Pole {
                re: l.re,
                im: l.im.max(0.0),
                natural_frequency_hz: modulus / (2.0 * std::f64::consts::PI),
                damping_ratio: if modulus > 0.0 { -l.re / modulus } else { 0.0 },
            }
        })
        .collect();
    poles.sort_by(|x, y| x.natural_frequency_hz.total_cmp(&y.natural_frequency_hz));
    poles
}

/// `T⁻¹ A T` with `T` diagonal, powers of 2 (exact in floating point), chosen so that each row
/// and column have about the same norm (Parlett & Reinsch 1969, LAPACK's `gebal` without the
/// permutations): the same eigenvalues, a smaller norm.
pub fn balance(a: &DMatrix<f64>) -> DMatrix<f64> {
    let mut a = a.clone();
    let n = a.nrows();
    let radix = 2.0_f64;
    let mut converged = false;
    while !converged {
        converged = true;
        for i in 0..n {
            let (mut c, mut r) = (0.0, 0.0);
            for j in 0..n {
                if j != i {
                    c += a[(j, i)].abs();
                    r += a[(i, j)].abs();
                }
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let (s, mut f) = (c + r, 1.0);
            let (mut c2, mut r2) = (c, r);
            while c2 < r2 / radix {
                c2 *= radix;
                r2 /= radix;
                f *= radix;
            }
            while c2 >= r2 * radix {
                c2 /= radix;
                r2 *= radix;
                f /= radix;
            }
            if c2 + r2 < 0.95 * s {
                converged = false;
                // column i × f, row i ÷ f
                a.column_mut(i).scale_mut(f);
                a.row_mut(i).scale_mut(1.0 / f);
            }
        }
    }
    a
}

/// How many poles (conjugates counted) lie within 5 % of `−1/t_d` (none without damping).
fn relaxation_poles(poles: &[Pole], t_d: f64) -> usize {
    if t_d <= 0.0 {
        return 0;
    }
    let s = -1.0 / t_d;
    poles
        .iter()
        .filter(|p| (p.re - s).hypot(p.im) <= 0.05 * s.abs())
        .map(|p| if p.im > 0.0 { 2 } else { 1 })
        .sum()
}

/// `−C A⁻¹ B`, or `None` if `A` is singular or the result not finite.
fn static_gain(lin: &Linearization) -> Option<Vec<Vec<f64>>> {
    let lu = lin.a_matrix().lu();
    let x = lu.solve(&lin.b_matrix())?;
    let g = -(lin.c_matrix() * x);
    g.iter().all(|v| v.is_finite()).then(|| rows(&g))
}

fn rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    m.row_iter().map(|r| r.iter().copied().collect()).collect()
}

fn from_rows(r: &[Vec<f64>]) -> DMatrix<f64> {
    let ncols = r.first().map_or(0, Vec::len);
    DMatrix::from_fn(r.len(), ncols, |i, j| r[i][j])
}
