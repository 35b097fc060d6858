//! Natural frequencies and mode shapes about a static equilibrium (gvs-spec §10.5), and what each
//! shape looks like: which strain component carries its strain energy, how the tip moves.
//!
//! The equilibrium `q₀` is solved exactly as `gvsrom statics` does ([`crate::statics::solve`]); the
//! modes are the engine's [`Model::linearized_modes`] (with tendons driven by displacement, its
//! [`Model::held_modes`]: the taut ones held at their lengths): `(K_T − ω² M) φ = 0` with the tangent
//! stiffness `K_T = −∂R/∂q` (elastic plus load and tendon stiffness; non-symmetric under tendon
//! friction and follower loads, whose modes are then the eigenpairs of `M⁻¹K_T`) and mass-normalized
//! shapes `φᵀ M φ = 1`, so that `q = q₀ + φ η` with the modal coordinate `η` [√kg·m] has kinetic energy
//! `½ η̇²` and elastic energy `½ ω² η²`. Damping is ignored (undamped modes).
//!
//! Per mode, with `δξ_i = Ψ_q(q₀)_i φ` the modal strain at computational point `i`:
//! * strain energy per component `c`: `½ Σ_i W_i Es_i,c δξ_i,c²` (its share of the sum names the mode);
//! * tip motion: `J_tip φ = [δθ; δp]` (body frame), reported in world axes `R_tip δθ`, `R_tip δp`.
//!
//! Within a cluster of equal frequencies (a round rod's y/z bending pairs) the eigensolver returns an
//! arbitrary orthonormal basis; it is rotated here to the one that separates the strain components
//! (eigenvectors of `Σ_c (c+1) E_c`, `E_c` the cluster's component energy matrices), which keeps the
//! shapes M-orthonormal and makes the output reproducible. The sign of each shape makes its largest
//! tip component positive.

use crate::build::Built;
use crate::error::{ScenarioError, StaticsFailure};
use crate::scenario::StrainMode;
use crate::statics::{self, StaticsReport};
use gvs::dynamics::DynamicsError;
use gvs::lie::V6;
use gvs::model::Model;
use gvs::strain::StrainParam;
use gvs::ModelError;
use nalgebra::{DMatrix, DVector, SymmetricEigen};
use serde::Serialize;
use thiserror::Error;

/// Modes printed when `--count` is not given.
pub const DEFAULT_COUNT: usize = 10;

#[derive(Debug, Error)]
pub enum ModesError {
    #[error("--count `{value}`: expected an integer ≥ 1 (the number of lowest modes to report; the model has {n_dof} DOF, a larger count reports them all)")]
    Count { value: String, n_dof: usize },
    #[error("the equilibrium: {0}")]
    Statics(#[from] StaticsFailure),
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error("the modes: {0}")]
    Dynamics(#[from] DynamicsError),
}

/// How many modes to report for `--count text` (`None`: [`DEFAULT_COUNT`]) on an `n_dof` model: an
/// integer ≥ 1 (else an error naming the value and the range); more than `n_dof` is clipped to
/// `n_dof`, and the second value is then `true` if the count was given.
pub fn parse_count(text: Option<&str>, n_dof: usize) -> Result<(usize, bool), ModesError> {
    let requested = match text {
        None => DEFAULT_COUNT,
        Some(t) => match t.trim().parse::<usize>() {
            Ok(k) if k >= 1 => k,
            _ => {
                return Err(ModesError::Count {
                    value: t.to_string(),
                    n_dof,
                })
            }
        },
    };
    Ok((requested.min(n_dof), text.is_some() && requested > n_dof))
}

/// One mode (also its `--json` entry).
#[derive(Debug, Clone, Serialize)]
pub struct ModeReport {
    /// 1 for the lowest.
    pub mode: usize,
    /// Natural frequency `ω/2π` \[Hz\]; 0 when `ω² ≤ 0`.
    pub frequency_hz: f64,
    /// `1/f` \[s\]; `null` when the frequency is 0.
    pub period_s: Option<f64>,
    /// `φᵀ K_T φ` [1/s²] (with held tendons the constrained problem's eigenvalue); negative: the
    /// equilibrium is unstable along this shape (the real part of a complex eigenvalue of a
    /// non-symmetric `K_T`).
    pub omega_squared: f64,
    /// The imaginary part of `ω²`, non-zero for a complex pair of a non-symmetric `K_T` (flutter of
    /// the undamped linearization); absent when zero.
    #[serde(skip_serializing_if = "is_zero")]
    pub omega_squared_imag: f64,
    /// The strain component with the largest share of the modal strain energy.
    pub dominant_strain: &'static str,
    /// Share of the modal strain energy per component, `[torsion, bend-y, bend-z, elongation,
    /// shear-y, shear-z]` (sums to 1).
    pub strain_energy_share: [f64; 6],
    /// `φ` in q-space, mass-normalized (`φᵀ M φ = 1`).
    pub shape: Vec<f64>,
    /// Tip displacement per unit modal coordinate, world axes [m per √kg·m].
    pub tip_displacement: [f64; 3],
    /// Tip rotation (rotation vector) per unit modal coordinate, world axes [rad per √kg·m].
    pub tip_rotation: [f64; 3],
    /// Modal strain `δξ` at the computational points (`strain_x`), per unit modal coordinate.
    pub strain: Vec<[f64; 6]>,
    /// Displacement of the centreline at the report's `centerline_x`, world axes, per unit modal
    /// coordinate: `∂p(X)/∂q φ` ([`Model::position_jacobian_at`]), the shape `gvsrom plot` draws.
    pub centerline_shape: Vec<[f64; 3]>,
}

/// The modes of a scenario about its equilibrium (this is also the `--json` output, with the
/// manifest and the model path added).
#[derive(Debug, Clone, Serialize)]
pub struct ModesReport {
    pub scenario: String,
    /// Tendon tensions u \[N\] of the equilibrium (those found for displacement drives).
    pub u: Vec<f64>,
    /// The tendons held by their motors (taut and driven by displacement: the motors locked)
    /// ([`Model::held_modes`]): an inextensible one keeps its length, a constraint; one with an
    /// elastic thread ([`ModesReport::held_by_threads`]) is the spring its thread is.
    /// `n_dof − (inextensible held)` modes. Empty when every tendon is driven by tension.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub held_tendons: Vec<usize>,
    /// Of [`ModesReport::held_tendons`], those held through an elastic thread
    /// (`tendons[k].axial_stiffness`): springs, not constraints.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub held_by_threads: Vec<usize>,
    pub n_dof: usize,
    pub n_points: usize,
    /// The equilibrium `q₀` and its statics report's tip position and residual.
    pub q0: Vec<f64>,
    pub equilibrium_tip_position: [f64; 3],
    pub equilibrium_residual_norm: f64,
    /// Frequencies of all `n_dof` modes (one fewer per inextensible held tendon), ascending \[Hz\].
    pub all_frequencies_hz: Vec<f64>,
    /// `‖K_T − K_Tᵀ‖_F / ‖K_T‖_F`: above [`gvs::dynamics::SYMMETRY_TOLERANCE`] (tendon friction,
    /// follower loads) the modes are the eigenpairs of the non-symmetric `M⁻¹ K_T`, whose shapes
    /// are not `M`-orthogonal ([`Model::linearized_modes`]).
    pub stiffness_asymmetry: f64,
    /// Abscissae of the computational points \[m\].
    pub strain_x: Vec<f64>,
    /// The equilibrium's centreline: its samples' abscissae \[m\] (`output.centerline_points`, as
    /// `gvsrom statics`) and world positions \[m\].
    pub centerline_x: Vec<f64>,
    pub centerline: Vec<[f64; 3]>,
    /// The lowest `--count` modes.
    pub modes: Vec<ModeReport>,
}

/// Solves the equilibrium of `built` (as `gvsrom statics` does, with the reduced model if one is
/// attached) and returns it with the lowest `count` modes about it.
pub fn compute(built: &Built, count: usize) -> Result<(StaticsReport, ModesReport), ModesError> {
    // the modes are undamped: any damping is fine here
    crate::simulate::require_mass_only(built)?;
    let eq = statics::solve(built)?;
    statics::check_reduced(built, &eq)?;
    // the taut tendons driven by displacement are held at their lengths (their motors locked)
    let held: Vec<usize> = (0..built.displacement.len())
        .filter(|&k| built.displacement[k].is_some() && !eq.drives.get(k).is_some_and(|d| d.slack))
        .collect();
    let modes = match &built.reduced {
        Some(r) => modes_on(built, &r.model, &eq, count, &held)?,
        None => modes_on(built, &built.model, &eq, count, &held)?,
    };
    Ok((eq, modes))
}

/// The modes of `model` about its equilibrium `eq` (under the tensions `eq.u`, those found for
/// displacement drives), the tendons `held` at their lengths ([`Model::held_modes`]).
fn modes_on<P: StrainParam>(
    built: &Built,
    model: &Model<P>,
    eq: &StaticsReport,
    count: usize,
    held: &[usize],
) -> Result<ModesReport, ModesError> {
    let n = model.n_dof();
    let q0 = DVector::from_column_slice(&eq.q);
    let loads = model.prepare_loads(&built.loads)?;
    let mut ws = model.workspace();
    let raw = model.held_modes(&q0, &eq.u, &loads, held, &mut ws)?;

    // Signed ω² (the engine reports 0 Hz for ω² < 0): the Rayleigh quotient with K_T = −sym(∂R/∂q),
    // which is the eigenvalue of a real eigenvector whether K_T is symmetric or not (φᵀ K φ =
    // φᵀ sym(K) φ = ω² φᵀ M φ); a complex pair's is the engine's real part. Ascending ω², so that
    // unstable directions (ω² < 0, all at 0 Hz) are ordered too.
    let mut dr = DMatrix::zeros(n, n);
    model.statics_jacobian(&q0, &eq.u, &loads, &mut ws, &mut dr);
    let stiffness_asymmetry = (&dr - dr.transpose()).norm() / dr.norm();
    let kt = (&dr + dr.transpose()) * -0.5;
    // (ω², its imaginary part, φ)
    let mut raw: Vec<(f64, f64, DVector<f64>)> = raw
        .into_iter()
        .map(|m| match m.omega_squared_imag {
            // held tendons: the constrained problem's own ω² (with friction the Rayleigh
            // quotient of K_T is not its eigenvalue)
            0.0 if held.is_empty() => (m.shape.dot(&(&kt * &m.shape)), 0.0, m.shape),
            im => (m.omega_squared, im, m.shape),
        })
        .collect();
    raw.sort_by(|a, b| a.0.total_cmp(&b.0));
    let lam: Vec<f64> = raw.iter().map(|m| m.0).collect();
    let lam_imag: Vec<f64> = raw.iter().map(|m| m.1).collect();
    let all_frequencies_hz: Vec<f64> = lam.iter().map(|&l| frequency(l)).collect();
    let count = count.min(raw.len());

    // Take whole clusters of equal ω², so that the alignment sees every partner.
    let lam_max = lam.iter().fold(0.0, |a: f64, b| a.max(b.abs()));
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-7 * a.abs().max(b.abs()) + 1e-11 * lam_max;
    // equal ω², imaginary parts included: the members of a complex pair (conjugates) are not a
    // cluster of equal frequencies, and mixing their shapes would zero one of them
    let same = |a: usize, b: usize| close(lam[a], lam[b]) && close(lam_imag[a], lam_imag[b]);
    let mut taken = count;
    while taken < raw.len() && same(taken - 1, taken) {
        taken += 1;
    }
    let mut shapes: Vec<DVector<f64>> = raw[..taken].iter().map(|m| m.2.clone()).collect();
    let mut strains: Vec<Vec<V6>> = shapes
        .iter()
        .map(|phi| modal_strain(model, &q0, phi, &mut ws))
        .collect();

    // Align each cluster of equal frequencies with the strain components.
    let mut start = 0;
    while start < taken {
        let mut end = start + 1;
        while end < taken && same(end - 1, end) {
            end += 1;
        }
        if end - start > 1 {
            align_cluster(model, &mut shapes[start..end], &mut strains[start..end]);
        }
        start = end;
    }

    model.forward(&q0, &mut ws, true);
    let tip = model.disc.tip();
    let rot = ws.g[tip].rot;
    let length = model.disc.length();
    let mut modes = Vec::with_capacity(count);
    for k in 0..count {
        let mut phi = shapes[k].clone();
        let mut strain = strains[k].clone();
        let twist: V6 = ws.jac.columns(tip * n, n) * &phi;
        let mut dtheta = rot * twist.fixed_rows::<3>(0);
        let mut dp = rot * twist.fixed_rows::<3>(3);
        // sign: the largest tip component (rotations scaled by the length) positive, else the
        // largest coordinate
        let tip6 = [
            dp[0],
            dp[1],
            dp[2],
            dtheta[0] * length,
            dtheta[1] * length,
            dtheta[2] * length,
        ];
        let big = tip6
            .iter()
            .cloned()
            .fold(0.0, |a: f64, b| if b.abs() > a.abs() { b } else { a });
        let flip = if big.abs() > 1e-9 * phi.amax() * length {
            big < 0.0
        } else {
            phi.iter()
                .cloned()
                .fold(0.0, |a: f64, b| if b.abs() > a.abs() { b } else { a })
                < 0.0
        };
        if flip {
            phi = -phi;
            dtheta = -dtheta;
            dp = -dp;
            strain.iter_mut().for_each(|s| *s = -*s);
        }
        let centerline_shape = (eq.centerline_x.iter())
            .map(|&x| {
                let d = model.position_jacobian_at(&ws, x).1 * &phi;
                [d[0], d[1], d[2]]
            })
            .collect();
        let energy = component_energy(model, &strain);
        let total: f64 = energy.iter().sum();
        let share = energy.map(|e| if total > 0.0 { e / total } else { 0.0 });
        let dominant = (0..6).fold(0, |best, c| if share[c] > share[best] { c } else { best });
        let omega_squared_imag = lam_imag[k];
        let omega_squared = match omega_squared_imag {
            0.0 if held.is_empty() => phi.dot(&(&kt * &phi)),
            _ => lam[k],
        };
        let f = frequency(omega_squared);
        modes.push(ModeReport {
            mode: k + 1,
            frequency_hz: f,
            period_s: (f > 0.0).then(|| 1.0 / f),
            omega_squared,
            omega_squared_imag,
            dominant_strain: StrainMode::ALL[dominant].name(),
            strain_energy_share: share,
            shape: phi.iter().copied().collect(),
            tip_displacement: [dp[0], dp[1], dp[2]],
            tip_rotation: [dtheta[0], dtheta[1], dtheta[2]],
            strain: strain
                .iter()
                .map(|s| [s[0], s[1], s[2], s[3], s[4], s[5]])
                .collect(),
            centerline_shape,
        });
    }
    Ok(ModesReport {
        scenario: built.name.clone(),
        u: eq.u.clone(),
        held_tendons: held.to_vec(),
        held_by_threads: (held.iter().copied())
            .filter(|&k| model.tendons[k].axial_stiffness.is_some())
            .collect(),
        n_dof: n,
        n_points: model.disc.n_points(),
        q0: eq.q.clone(),
        equilibrium_tip_position: eq.tip_position,
        equilibrium_residual_norm: eq.residual_norm,
        all_frequencies_hz,
        stiffness_asymmetry,
        strain_x: model.disc.points.iter().map(|p| p.x).collect(),
        centerline_x: eq.centerline_x.clone(),
        centerline: eq.centerline.clone(),
        modes,
    })
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// `f = √ω² / 2π` [Hz], 0 for `ω² ≤ 0`.
fn frequency(omega_squared: f64) -> f64 {
    omega_squared.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)
}

/// `δξ_i = Ψ_q(q₀)_i φ` at the computational points, by central differences of the strain along `φ`
/// (exact up to rounding for a linear basis, `O(ε²)` for a decoder).
fn modal_strain<P: StrainParam>(
    model: &Model<P>,
    q0: &DVector<f64>,
    phi: &DVector<f64>,
    ws: &mut gvs::model::Workspace,
) -> Vec<V6> {
    let eps = 1e-6 / phi.amax().max(f64::MIN_POSITIVE);
    model.forward_pose(&(q0 + phi * eps), ws);
    let plus = model.point_strains(ws);
    model.forward_pose(&(q0 - phi * eps), ws);
    let minus = model.point_strains(ws);
    plus.iter()
        .zip(&minus)
        .map(|(p, m)| (p - m) / (2.0 * eps))
        .collect()
}

/// `2 × strain energy` per component: `Σ_i W_i Es_i,c δξ_i,c²`.
fn component_energy<P: StrainParam>(model: &Model<P>, strain: &[V6]) -> [f64; 6] {
    let mut e = [0.0; 6];
    for (i, (p, s)) in model.disc.points.iter().zip(strain).enumerate() {
        let es = model.section(i).es;
        for c in 0..6 {
            e[c] += p.weight * es[c] * s[c] * s[c];
        }
    }
    e
}

/// Rotates the shapes of one cluster of equal frequencies (and their modal strains, which are linear
/// in the shape) to the eigenvectors of `Σ_c (c+1) E_c`, `E_c[a,b] = Σ_i W_i Es_i,c δξ_a,i,c δξ_b,i,c`,
/// ascending: pure-component shapes come out separated, in the order of the components.
fn align_cluster<P: StrainParam>(
    model: &Model<P>,
    shapes: &mut [DVector<f64>],
    strains: &mut [Vec<V6>],
) {
    let m = shapes.len();
    let mut s = DMatrix::<f64>::zeros(m, m);
    for (i, p) in model.disc.points.iter().enumerate() {
        let es = model.section(i).es;
        for c in 0..6 {
            let w = (c + 1) as f64 * p.weight * es[c];
            for a in 0..m {
                for b in 0..m {
                    s[(a, b)] += w * strains[a][i][c] * strains[b][i][c];
                }
            }
        }
    }
    let eig = SymmetricEigen::new(s);
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let old_shapes = shapes.to_vec();
    let old_strains = strains.to_vec();
    for (k, &col) in order.iter().enumerate() {
        let v = eig.eigenvectors.column(col);
        shapes[k] = old_shapes
            .iter()
            .zip(v.iter())
            .fold(DVector::zeros(old_shapes[0].len()), |acc, (phi, &c)| {
                acc + phi * c
            });
        strains[k] = (0..old_strains[0].len())
            .map(|i| {
                old_strains
                    .iter()
                    .zip(v.iter())
                    .fold(V6::zeros(), |acc, (st, &c)| acc + st[i] * c)
            })
            .collect();
    }
}

impl ModeReport {
    /// The share of the strain energy in [`ModeReport::dominant_strain`].
    pub fn dominant_share(&self) -> f64 {
        self.strain_energy_share.iter().cloned().fold(0.0, f64::max)
    }
}

/// A short description of how the tip moves in a mode: `translation z, rotation y` (world axes; a
/// direction off the axes is printed as a unit vector). Rotations count against translations scaled
/// by the rod's length; a part below 1 % of the larger one is left out.
pub fn tip_motion(mode: &ModeReport, length: f64) -> String {
    let norm = |v: &[f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let (t, r) = (
        norm(&mode.tip_displacement),
        norm(&mode.tip_rotation) * length,
    );
    let big = t.max(r);
    if big == 0.0 {
        return "tip at rest".into();
    }
    let dir = |v: &[f64; 3], n: f64| {
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            if v[k].abs() >= 0.995 * n {
                return (*axis).to_string();
            }
        }
        // a component that rounds to zero prints as 0.00, whatever its sign's round-off
        let c = |x: f64| match format!("{x:.2}") {
            z if z == "-0.00" => "0.00".to_string(),
            z => z,
        };
        format!("[{}, {}, {}]", c(v[0] / n), c(v[1] / n), c(v[2] / n))
    };
    let mut parts = vec![];
    if t >= 0.01 * big {
        parts.push(format!("translation {}", dir(&mode.tip_displacement, t)));
    }
    if r >= 0.01 * big {
        parts.push(format!(
            "rotation {}",
            dir(&mode.tip_rotation, norm(&mode.tip_rotation))
        ));
    }
    parts.join(", ")
}

/// The `--json` document: the report and the reduced model used, if any.
#[derive(Debug, Serialize)]
pub struct ModesJson<'a> {
    #[serde(flatten)]
    pub report: &'a ModesReport,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    /// How the scenario lies outside what the model was trained on (`--extrapolate`), as
    /// `statics --json` records it.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub model_extrapolated: Vec<String>,
    /// How the result was made ([`crate::provenance`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub provenance: Option<&'a crate::provenance::Provenance>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn count_below_one_or_not_an_integer_is_refused_and_above_the_dof_count_is_clipped() {
        for bad in ["0", "-3", "2.5", "ten", ""] {
            assert!(
                matches!(parse_count(Some(bad), 5), Err(ModesError::Count { ref value, n_dof: 5 }) if value == bad),
                "{bad}"
            );
        }
        assert_eq!(parse_count(Some("3"), 5).unwrap(), (3, false));
        assert_eq!(parse_count(Some("5"), 5).unwrap(), (5, false));
        assert_eq!(parse_count(Some("9"), 5).unwrap(), (5, true));
        assert_eq!(parse_count(None, 50).unwrap(), (DEFAULT_COUNT, false));
        assert_eq!(parse_count(None, 4).unwrap(), (4, false));
    }

    #[test]
    fn a_tip_motion_off_the_axes_prints_a_component_that_rounds_to_zero_without_a_sign() {
        let mode = ModeReport {
            mode: 1,
            frequency_hz: 1.0,
            period_s: Some(1.0),
            omega_squared: 1.0,
            omega_squared_imag: 0.0,
            dominant_strain: "bend_y",
            strain_energy_share: [0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
            shape: vec![],
            tip_displacement: [-0.7, -1e-9, -0.71],
            tip_rotation: [0.0; 3],
            strain: vec![],
            centerline_shape: vec![],
        };
        assert_eq!(tip_motion(&mode, 1.0), "translation [-0.70, 0.00, -0.71]");
    }
}
