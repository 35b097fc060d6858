//! The one-line description of a built scenario printed by the summaries.

use super::Built;
use crate::scenario::{BasisKind, Scenario};
use gvs::error::fmt_value;
use gvs::loads::Frame;
use gvs::rod::Shape;
use gvs::strain::FemDegree;

/// A one-line description of the scenario as built (after `--set` and `--tension`), for the
/// summaries: `0.25 m tapered rod, gravity 9.81 m/s², 1 tendon (friction 0.88), 33-DOF Legendre
/// basis`. Derived from the model, never from the scenario's free-text `description`, so that it
/// cannot contradict the run.
pub fn describe(s: &Scenario, built: &Built) -> String {
    let m = &built.model;
    let g = &m.rod.divisions;
    // tapered within a division; a step in radius between uniform divisions is "stepped"
    let tapered = g.iter().any(|d| match &d.section {
        None => d.radius_start != d.radius_end,
        Some(s) => {
            s.width[0] != s.width[1]
                || s.height[0] != s.height[1]
                || s.inner_radius_at(0.0) != s.inner_radius_at(1.0)
        }
    });
    let stepped = g.windows(2).any(|w| {
        w[0].radius_end != w[1].radius_start
            || w[0].section.map(|s| std::mem::discriminant(&s.shape))
                != w[1].section.map(|s| std::mem::discriminant(&s.shape))
            || w[0]
                .section
                .map(|s| (s.width[1], s.height[1], s.inner_radius_at(1.0)))
                != w[1]
                    .section
                    .map(|s| (s.width[0], s.height[0], s.inner_radius_at(0.0)))
    });
    let shapes: Vec<Option<Shape>> = g.iter().map(|d| d.section.map(|s| s.shape)).collect();
    let kind = |s: &Option<Shape>| s.map(|s| std::mem::discriminant(&s));
    let shape = match shapes.first() {
        Some(first) if shapes.iter().all(|s| kind(s) == kind(first)) => match first {
            None => "",
            Some(Shape::Rectangle) => " rectangular",
            Some(Shape::Ellipse) => " elliptical",
            Some(Shape::Tube { .. }) => " tubular",
        },
        _ => " mixed-section",
    };
    // from the model, so that a reference strain given as the straight rod is not called one
    let precurved = (0..m.disc.n_sites()).any(|site| m.xi_star(site) != super::rod::STRAIGHT);
    let mut parts = vec![format!(
        "{} m {}{shape}{} rod{}",
        gvs::error::fmt_rounded(m.rod.length()),
        match (tapered, stepped) {
            (true, _) => "tapered",
            (false, true) => "stepped",
            (false, false) => "uniform",
        },
        if precurved { ", pre-strained" } else { "" },
        match g.len() {
            1 => String::new(),
            n => format!(" in {n} divisions"),
        }
    )];
    let gravity = built
        .loads
        .gravity
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt();
    parts.push(if gravity > 0.0 {
        format!("gravity {gravity} m/s²")
    } else {
        "no gravity".into()
    });
    let tendons = &m.tendons;
    parts.push(match tendons.len() {
        0 => "no tendons".into(),
        n => {
            let (lo, hi) = tendons
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| {
                    (lo.min(t.friction), hi.max(t.friction))
                });
            let friction = if lo == hi {
                format!("friction {lo}")
            } else {
                format!("friction {lo} to {hi}")
            };
            let routed = |kind: &str, count: usize| match (count, n) {
                (0, _) => String::new(),
                (h, n) if h == n => format!(", {kind}"),
                (h, _) => format!(", {h} {kind}"),
            };
            let helical = routed("helical", tendons.iter().filter(|t| t.turns != 0.0).count());
            let custom = routed(
                if n == 1 {
                    "on a custom path"
                } else {
                    "on custom paths"
                },
                tendons.iter().filter(|t| !t.path.is_empty()).count(),
            );
            format!(
                "{n} tendon{} ({friction}{helical}{custom})",
                if n == 1 { "" } else { "s" }
            )
        }
    });
    let (point, distributed) = wrench_frames(built);
    for (frames, what) in [(point, "point wrench"), (distributed, "distributed wrench")] {
        if !frames.is_empty() {
            parts.push(wrench_count(&frames, what));
        }
    }
    let bodies: Vec<_> = m.bodies().collect();
    if !bodies.is_empty() {
        let mass: f64 = bodies.iter().map(|b| b.mass).sum();
        parts.push(format!(
            "{} ({} kg)",
            match bodies.len() {
                1 => "1 rigid body".to_string(),
                n => format!("{n} rigid bodies"),
            },
            significant(mass)
        ));
    }
    let mut kinds: Vec<&str> = vec![];
    for d in &s.divisions {
        let kind = match (d.basis.kind, d.basis.degree) {
            (BasisKind::Legendre, _) => "Legendre",
            (BasisKind::Fem, Some(FemDegree::Quadratic)) => "quadratic FEM-like",
            (BasisKind::Fem, _) => "linear FEM-like",
        };
        if !kinds.contains(&kind) {
            kinds.push(kind);
        }
    }
    parts.push(format!("{}-DOF {} basis", m.n_dof(), kinds.join(" + ")));
    parts.join(", ")
}

/// The frames of the point and of the distributed wrenches of `built` (the pulse's: a follower).
pub fn wrench_frames(built: &Built) -> (Vec<Frame>, Vec<Frame>) {
    let l = &built.loads;
    (
        l.point.iter().map(|p| p.frame).collect(),
        l.distributed.iter().map(|d| d.peak_density().1).collect(),
    )
}

/// The rigid bodies fixed to the rod, one per line without a prefix: `0.02 kg at X = 0.25 m,
/// centre of mass [0.01, 0, 0] m, inertia [2e-6, 1.5e-6, 1.5e-6] kg·m²` (principal moments about
/// it; `inertia …` left out for a point mass). Empty without bodies.
pub fn body_lines(built: &Built) -> Vec<String> {
    let list = |v: &[f64]| {
        let parts: Vec<String> = v.iter().map(|x| significant(*x)).collect();
        format!("[{}]", parts.join(", "))
    };
    built
        .model
        .bodies()
        .map(|b| {
            let mut line = format!("{} kg at X = {} m", significant(b.mass), significant(b.x));
            if b.center != [0.0; 3] {
                line += &format!(", centre of mass {} m", list(&b.center));
            }
            let t = b.inertia;
            let diagonal = [t[0][1], t[0][2], t[1][2]].iter().all(|v| *v == 0.0);
            if t != [[0.0; 3]; 3] {
                line += &if diagonal {
                    format!(", inertia {} kg·m²", list(&[t[0][0], t[1][1], t[2][2]]))
                } else {
                    format!(
                        ", inertia tensor {} kg·m²",
                        list(&t.iter().flatten().copied().collect::<Vec<_>>())
                    )
                };
            }
            line
        })
        .collect()
}

/// `v` to 6 significant digits, trailing zeros dropped, in exponent form where [`fmt_value`] uses
/// it: `0.0600457`, `2e-6`, `1.5e-6` (a drawn mass, `0.0600457311465939`, is not printed whole).
pub fn significant(v: f64) -> String {
    let rounded = format!("{v:.5e}").parse::<f64>().unwrap_or(v);
    fmt_value(rounded)
}

/// How each tendon is driven, for a scenario with a displacement-driven tendon: `wound in 5 mm`,
/// `paid out 2 mm`, `held at its rest length` (with `(thread EA 200 N)` for an elastic thread), or
/// `u = -2 N` for a tension-driven one.
pub fn drive_words(built: &super::Built) -> Vec<String> {
    (built
        .u
        .iter()
        .zip(&built.displacement)
        .zip(&built.model.tendons))
    .map(|((u, d), t)| {
        let words = match d {
            Some(d) if *d > 0.0 => format!("wound in {} mm", significant(d * 1e3)),
            Some(d) if *d < 0.0 => format!("paid out {} mm", significant(-d * 1e3)),
            Some(_) => "held at its rest length".to_string(),
            None => return format!("u = {} N", significant(*u)),
        };
        // an elastic thread stretches under its tension (it matters only for a drive)
        match t.axial_stiffness {
            Some(ea) => format!("{words} (thread EA {} N)", significant(ea)),
            None => words,
        }
    })
    .collect()
}

/// `n` wrenches of kind `what` and how their components turn: `1 point wrench (follower)`,
/// `2 distributed wrenches (1 follower, 1 world-fixed)`, `0 point wrenches`. A follower wrench
/// (`frame = "local"`, the default) turns with its section; a world-fixed one (`"global"`), e.g.
/// a hanging weight, does not, and under large deflection the two bend a rod differently.
pub fn wrench_count(frames: &[Frame], what: &str) -> String {
    let n = frames.len();
    let plural = if n == 1 { "" } else { "es" };
    let local = frames.iter().filter(|f| **f == Frame::Local).count();
    let kinds = match (local, n - local) {
        (0, 0) => String::new(),
        (_, 0) => " (follower)".to_string(),
        (0, _) => " (world-fixed)".to_string(),
        (l, g) => format!(" ({l} follower, {g} world-fixed)"),
    };
    format!("{n} {what}{plural}{kinds}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrenches_are_counted_with_how_they_turn() {
        use Frame::{Global, Local};
        assert_eq!(wrench_count(&[], "point wrench"), "0 point wrenches");
        assert_eq!(
            wrench_count(&[Local], "point wrench"),
            "1 point wrench (follower)"
        );
        assert_eq!(
            wrench_count(&[Global, Global], "point wrench"),
            "2 point wrenches (world-fixed)"
        );
        assert_eq!(
            wrench_count(&[Global, Local, Local], "distributed wrench"),
            "3 distributed wrenches (2 follower, 1 world-fixed)"
        );
    }
}
