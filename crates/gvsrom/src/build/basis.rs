//! Each division's strain basis (Legendre or FEM-like, with its active modes) and quadrature.

use super::fem_points;
use super::limits::*;
use crate::error::ScenarioError;
use crate::scenario::{BasisKind, DivisionSpec, StrainMode};
use gvs::discretize::{MagnusOrder, Quadrature};
use gvs::strain::{DivisionBasis, FemDegree};

/// The six active flags of a mode list; rejects an empty list and repeated modes.
pub(super) fn mode_flags(field: &str, modes: &[StrainMode]) -> Result<[bool; 6], ScenarioError> {
    if modes.is_empty() {
        return Err(ScenarioError::invalid(
            field,
            "the basis is empty: list at least one strain mode of torsion, bend_y, bend_z, elongation, shear_y, shear_z",
        ));
    }
    let mut flags = [false; 6];
    for m in modes {
        if flags[m.index()] {
            return Err(ScenarioError::invalid(
                field,
                format!("mode `{}` is listed twice", m.name()),
            ));
        }
        flags[m.index()] = true;
    }
    Ok(flags)
}

pub(super) fn basis(j: usize, d: &DivisionSpec) -> Result<DivisionBasis, ScenarioError> {
    let f = |n: &str| format!("divisions[{j}].basis.{n}");
    let b = &d.basis;
    let flags = mode_flags(&f("modes"), &b.modes)?;
    let not_for = |key: &str, kind: &str| {
        Err(ScenarioError::invalid(
            f(key),
            format!("not used by a {kind} basis (kind = \"{kind}\")"),
        ))
    };
    match b.kind {
        BasisKind::Legendre => {
            if b.elements.is_some() {
                return not_for("elements", "legendre");
            }
            if b.degree.is_some() {
                return not_for("degree", "legendre");
            }
            let mut ords = [0usize; 6];
            for m in StrainMode::ALL {
                let explicit = b.orders.get(m);
                if !flags[m.index()] {
                    if explicit.is_some() {
                        return Err(ScenarioError::invalid(
                            f(&format!("orders.{}", m.name())),
                            format!("mode `{}` is not in `modes`", m.name()),
                        ));
                    }
                    continue;
                }
                let (field, k) = match (explicit, b.order) {
                    (Some(k), _) => (f(&format!("orders.{}", m.name())), k),
                    (None, Some(k)) => (f("order"), k),
                    (None, None) => {
                        return Err(ScenarioError::invalid(
                            f("order"),
                            format!("missing: give `order` (all modes) or `orders.{}`", m.name()),
                        ))
                    }
                };
                if k > MAX_LEGENDRE_ORDER {
                    return Err(ScenarioError::value(
                        field,
                        k as f64,
                        format!("an integer in [0, {MAX_LEGENDRE_ORDER}]"),
                    ));
                }
                ords[m.index()] = k;
            }
            Ok(DivisionBasis::Legendre {
                modes: flags,
                orders: ords,
            })
        }
        BasisKind::Fem => {
            if b.order.is_some() {
                return not_for("order", "fem");
            }
            if let Some(m) = StrainMode::ALL
                .into_iter()
                .find(|&m| b.orders.get(m).is_some())
            {
                return not_for(&format!("orders.{}", m.name()), "fem");
            }
            let Some(elements) = b.elements else {
                return Err(ScenarioError::invalid(
                    f("elements"),
                    format!(
                        "missing: a fem basis needs `elements`, an integer in [1, {MAX_POINTS}]"
                    ),
                ));
            };
            if !(1..=MAX_POINTS).contains(&elements) {
                return Err(ScenarioError::value(
                    f("elements"),
                    elements as f64,
                    format!("an integer in [1, {MAX_POINTS}]"),
                ));
            }
            Ok(DivisionBasis::Fem {
                modes: flags,
                elements,
                degree: b.degree.unwrap_or(FemDegree::Linear),
            })
        }
    }
}

/// The division's quadrature. Defaults: Legendre of highest order `p` → SoRoSim's `p + 1` Gauss
/// points, at least 5 (gvs-spec §5.1), or `3(p + 1)` above order 3, the points Z4's kinematics
/// needs for such a basis ([`kinematics_resolution`]: SoRoSim's points leave a wavy strain, which
/// the build warns about); FEM → per element, 2 (linear) or 3 (quadratic) points.
pub(super) fn quadrature(
    j: usize,
    d: &DivisionSpec,
    basis: &DivisionBasis,
) -> Result<Quadrature, ScenarioError> {
    let q = d.quadrature.clone().unwrap_or_default();
    let quadrature = chosen_quadrature(j, &q, basis)?;
    resolves(j, &q, basis, &quadrature)?;
    Ok(quadrature)
}

/// Default Gauss points of a Legendre basis of highest order `p`: SoRoSim's `p + 1`, at least 5,
/// up to the degree Z4's two sub-points integrate exactly (3); above it `3(p + 1)`, which
/// [`kinematics_resolution`] asks for (a rod under an end moment, order 10: strain 1.8 % off on
/// SoRoSim's 11 points, 2.8e-4 on 33).
fn default_gauss_points(p: usize) -> usize {
    if p > 3 {
        3 * (p + 1)
    } else {
        (p + 1).max(5)
    }
}

/// Refuses a quadrature whose points do not determine the basis: the stiffness `Σ W Φᵀ Es Φ` is
/// then singular, so the equilibrium is not unique (zero-energy modes) and the solver returns one
/// of many, silently wrong (`single-tendon` with 8 Gauss points for its order-10 basis: tip 0.13 m
/// off; a 10-element FEM basis on 5 quadrature elements: the tip a rod's length off, at the
/// base). Legendre of highest order `p` needs `p + 1` points in all; a FEM basis, points
/// under which every combination of its functions keeps a tenth of its exact stiffness
/// ([`fem_points`]; `p + 1` per element when the quadrature's elements are the basis's).
fn resolves(
    j: usize,
    q: &crate::scenario::QuadratureSpec,
    basis: &DivisionBasis,
    quadrature: &Quadrature,
) -> Result<(), ScenarioError> {
    let points = weighted_points(quadrature);
    let field = match q.gauss {
        Some(_) => "gauss",
        None => "gauss_per_element",
    };
    match basis {
        DivisionBasis::Legendre { modes, orders } => {
            let p = highest_order(modes, orders);
            if points > p {
                return Ok(());
            }
            Err(ScenarioError::invalid(
                format!("divisions[{j}].quadrature.{field}"),
                format!(
                    "{points} points resolve too few functions: the basis's highest order {p} has {} Legendre functions per strain, so the stiffness would be singular (zero-energy modes) and the equilibrium not unique; accepted: at least {}",
                    p + 1,
                    p + 1
                ),
            ))
        }
        DivisionBasis::Fem {
            elements, degree, ..
        } => {
            let x = fem_points::points(quadrature);
            let Some(node) = fem_points::under_resolved(*elements, *degree, &x) else {
                return Ok(());
            };
            let d = match degree {
                FemDegree::Linear => 1,
                FemDegree::Quadratic => 2,
            };
            // the element of that node with the fewest points, to show where
            let e = [node.saturating_sub(1) / d, (node / d).min(elements - 1)]
                .into_iter()
                .min_by_key(|&e| fem_points::points_in_element(e, *elements, &x))
                .unwrap_or(0);
            let held = fem_points::points_in_element(e, *elements, &x);
            let how = match quadrature {
                Quadrature::Elements { .. } => format!(
                    "`elements` = {elements} (the basis's) and `gauss_per_element` ≥ {}",
                    d + 1
                ),
                Quadrature::Gauss { .. } => format!(
                    "per-element points: `elements` = {elements} (the basis's) and `gauss_per_element` ≥ {}",
                    d + 1
                ),
            };
            Err(ScenarioError::invalid(
                format!("divisions[{j}].quadrature"),
                format!(
                    "its {points} points do not resolve the {elements}-element FEM basis of degree {d} ({} functions per strain): a combination of the functions nearly vanishes at every point (near element {e}, X̄ in [{:.4}, {:.4}], which holds {held} of them) and keeps less than {} of its stiffness, a near zero-energy mode that leaves the equilibrium all but undetermined; accepted: points that resolve every function, e.g. {how}",
                    d * elements + 1,
                    e as f64 / *elements as f64,
                    (e + 1) as f64 / *elements as f64,
                    fem_points::TAU,
                ),
            ))
        }
    }
}

/// The quadrature `q` asks for (its defaults filled in), each count in range.
fn chosen_quadrature(
    j: usize,
    q: &crate::scenario::QuadratureSpec,
    basis: &DivisionBasis,
) -> Result<Quadrature, ScenarioError> {
    let f = |n: &str| format!("divisions[{j}].quadrature.{n}");
    let check = |field: String, v: usize, max: usize| {
        if (1..=max).contains(&v) {
            Ok(v)
        } else {
            Err(ScenarioError::value(
                field,
                v as f64,
                format!("an integer in [1, {max}]"),
            ))
        }
    };
    match (q.gauss, q.elements, q.gauss_per_element) {
        (None, None, None) => Ok(match basis {
            DivisionBasis::Fem {
                elements, degree, ..
            } => Quadrature::Elements {
                elements: *elements,
                gauss_per_element: match degree {
                    FemDegree::Linear => 2,
                    FemDegree::Quadratic => 3,
                },
            },
            DivisionBasis::Legendre { modes, orders } => {
                let max = highest_order(modes, orders);
                Quadrature::Gauss {
                    n: default_gauss_points(max),
                }
            }
        }),
        (Some(n), None, None) => Ok(Quadrature::Gauss {
            n: check(f("gauss"), n, MAX_POINTS)?,
        }),
        (None, elements, Some(g)) => {
            let elements = match (elements, basis) {
                (Some(e), _) => check(f("elements"), e, MAX_POINTS)?,
                (None, DivisionBasis::Fem { elements, .. }) => *elements,
                (None, DivisionBasis::Legendre { .. }) => {
                    return Err(ScenarioError::invalid(
                        f("elements"),
                        "missing: per-element quadrature on a Legendre basis needs `elements`",
                    ))
                }
            };
            Ok(Quadrature::Elements {
                elements,
                gauss_per_element: check(f("gauss_per_element"), g, MAX_GAUSS_PER_ELEMENT)?,
            })
        }
        (Some(_), _, _) => Err(ScenarioError::invalid(
            f("gauss"),
            "give either `gauss` (points over the whole division) or `gauss_per_element` (with optional `elements`), not both",
        )),
        (None, Some(_), None) => Err(ScenarioError::invalid(
            f("gauss_per_element"),
            "missing: `elements` needs `gauss_per_element`",
        )),
    }
}

/// Strain degree the Magnus rule between consecutive points integrates exactly: Z4's two Gauss
/// sub-points, 3; Z2's midpoint, 1.
fn magnus_exact_degree(magnus: MagnusOrder) -> usize {
    match magnus {
        MagnusOrder::Z4 => 3,
        MagnusOrder::Z2 => 1,
    }
}

/// A division whose basis the kinematics integrate less exactly than the stiffness (a finding of
/// 2026-12-06, docs/scenario-format.md "Enough points for the kinematics too"): the stiffness
/// `Σ W Φᵀ Es Φ` uses the Gauss weights, but the poses, and through `Jᵀ w` every load, integrate
/// the strain between consecutive points with the Magnus rule, exact only up to
/// [`magnus_exact_degree`]. A basis of higher degree then bends the rod with a strain field that
/// does not converge to the exact one as the basis is refined: a uniform rod under a follower end
/// moment (exact `k_y` constant), Legendre order 10 on SoRoSim's 11 points, is 1.8 % off in
/// strain with Z4 and 34 % with Z2; Z2 with quadratic elements does not converge under element
/// refinement at all (tip 4.4e-3 L at 10, 40 and 160 elements). One sentence, or `None`: Z4 with
/// degree ≤ 3 or with at least `3(p + 1)` points (strain 2.8e-4 off at order 10); Z2 with linear
/// strains.
pub(super) fn kinematics_resolution(
    j: usize,
    basis: &DivisionBasis,
    quadrature: &Quadrature,
    magnus: MagnusOrder,
) -> Option<String> {
    let degree = match basis {
        DivisionBasis::Legendre { modes, orders } => highest_order(modes, orders),
        DivisionBasis::Fem { degree, .. } => match degree {
            FemDegree::Linear => 1,
            FemDegree::Quadratic => 2,
        },
    };
    let exact = magnus_exact_degree(magnus);
    if degree <= exact {
        return None;
    }
    let points = weighted_points(quadrature);
    let enough = 3 * (degree + 1);
    let (name, fix) = match magnus {
        MagnusOrder::Z2 => (
            "Z2 (midpoint)",
            "use `magnus = \"z4\"` (exact to degree 3)".to_string(),
        ),
        MagnusOrder::Z4 if points >= enough => return None,
        MagnusOrder::Z4 => (
            "Z4 (two sub-points)",
            format!("give the division `quadrature = {{ gauss = {enough} }}` or more (3(p + 1))"),
        ),
    };
    Some(format!(
        "divisions[{j}]: the poses and loads integrate the strain between its {points} Gauss points with the Magnus {name} rule, exact for strains of degree ≤ {exact}, but its basis has degree {degree}: the strain field then does not converge to the exact one as the basis is refined (a rod under an end moment, order 10 on 11 points: 1.8 % off with Z4, 34 % with Z2); {fix}"
    ))
}

/// A fem basis under a quadrature whose points straddle its elements' ends, where its functions
/// have kinks: a Gauss rule is exact only for a smooth integrand, so the integrals converge
/// slowly with the points (a review's cantilever, 16 linear elements under a tip force: tip
/// 0.5 % off with 30 Gauss points over the division, 0.02 % with 64, exact with the default 2 per
/// element). One sentence, or `None` when the quadrature's elements subdivide the basis's.
pub(super) fn fem_alignment(
    j: usize,
    basis: &DivisionBasis,
    quadrature: &Quadrature,
) -> Option<String> {
    let DivisionBasis::Fem { elements, .. } = basis else {
        return None;
    };
    if *elements == 1 {
        return None; // one element: no kink inside the division
    }
    let rule = match *quadrature {
        Quadrature::Elements {
            elements: q_elements,
            ..
        } if q_elements % elements == 0 => return None,
        Quadrature::Elements {
            elements: q_elements,
            ..
        } => format!("over {q_elements} quadrature elements, which do not subdivide its elements: their Gauss points"),
        Quadrature::Gauss { n } => format!("by {n} Gauss points over the whole division, which"),
    };
    Some(format!(
        "divisions[{j}]: its fem basis of {elements} elements is integrated {rule} straddle the elements' ends, where the basis has kinks: a Gauss rule loses its order there, and the results converge slowly with the points (16 linear elements on 30 points: a tip 0.5 % off); omit `quadrature` (2 or 3 Gauss points per element of the basis) or give `gauss_per_element` with `elements` a multiple of {elements}"
    ))
}

/// The highest Legendre order over the active modes.
fn highest_order(modes: &[bool; 6], orders: &[usize; 6]) -> usize {
    (0..6)
        .filter(|&i| modes[i])
        .map(|i| orders[i])
        .max()
        .unwrap_or(0)
}

/// The weighted points (Gauss points) a quadrature lays out over its division.
fn weighted_points(quadrature: &Quadrature) -> usize {
    match *quadrature {
        Quadrature::Gauss { n } => n,
        Quadrature::Elements {
            elements,
            gauss_per_element,
        } => elements * gauss_per_element,
    }
}
