//! Figure pieces shared by the output kinds: the names and units of the strain components, strain
//! profiles along the rod in a curvature panel and a stretch/shear panel, and side views of rods and
//! paths on equal scales.

use crate::plot::{Figure, LineChart, Series, Series3, SeriesStyle};

/// Component names in the engine's order `[torsion, bend-y, bend-z, elongation, shear-y, shear-z]`
/// (as a dataset's `components` spells them).
pub(crate) const NAMES: [&str; 6] = [
    "torsion",
    "bend_y",
    "bend_z",
    "elongation",
    "shear_y",
    "shear_z",
];

/// The legend label of component `c` as plotted, the deviation `ξ − ξ*` (so the elongation is
/// `ν₁ − 1`).
pub(crate) fn component_label(c: usize) -> &'static str {
    [
        "torsion κ₁",
        "bend-y κ₂",
        "bend-z κ₃",
        "elongation ν₁ − 1",
        "shear-y ν₂",
        "shear-z ν₃",
    ][c.min(5)]
}

/// The unit of component `c`: 1/m for the curvatures, dimensionless for stretch and shears.
pub(crate) fn component_unit(c: usize) -> &'static str {
    if c < 3 {
        "1/m"
    } else {
        "–"
    }
}

/// The engine index of the component named `name` (a dataset's or model's `components` entry).
pub(crate) fn component_index(name: &str) -> Option<usize> {
    NAMES.iter().position(|n| *n == name)
}

/// Whether any of `values` differs from zero by more than round-off of their scale.
pub(crate) fn nonzero(values: impl IntoIterator<Item = f64>) -> bool {
    values.into_iter().any(|v| v.is_finite() && v.abs() > 1e-12)
}

/// Strain profiles along the rod: a curvature panel (torsion, bend-y, bend-z [1/m]) and a stretch
/// and shear panel ([–]) of the deviations `dev(c, j)` at abscissae `x` (point j). A panel shows its
/// components that are nonzero somewhere, or all of them when every one is zero (then its title
/// says so).
pub(crate) fn strain_panels(x: &[f64], dev: impl Fn(usize, usize) -> f64) -> Vec<Figure> {
    let groups = [
        ("Curvatures", "curvature κ [1/m]", 0..3),
        ("Stretch and shears", "stretch, shear ν − ν* [–]", 3..6),
    ];
    groups
        .into_iter()
        .map(|(title, y_label, comps)| {
            let profile = |c: usize| -> Vec<f64> { (0..x.len()).map(|j| dev(c, j)).collect() };
            let active: Vec<usize> = comps.clone().filter(|&c| nonzero(profile(c))).collect();
            let (shown, title) = if active.is_empty() {
                (comps.collect(), format!("{title} (zero everywhere)"))
            } else {
                (active, title.to_string())
            };
            Figure::Line(LineChart {
                title,
                x_label: "X [m]".into(),
                y_label: y_label.into(),
                series: shown
                    .into_iter()
                    .map(|c| {
                        Series::new(
                            component_label(c),
                            x.to_vec(),
                            profile(c),
                            SeriesStyle::Line,
                        )
                        .with_color(crate::plot::palette::EXTRA[c])
                    })
                    .collect(),
                log_y: false,
                equal_aspect: false,
            })
        })
        .collect()
}

/// Axis names of the world frame.
pub(crate) const AXES: [&str; 3] = ["x [m]", "y [m]", "z [m]"];

/// A side view of `series` on the world axes `a` (horizontal) and `b` (vertical), equal scales. An
/// invisible `Bounds` series spans `bounds` (e.g. the extent over every frame of an animation) and
/// gives each axis at least a quarter of the other's span, so a planar rod seen edge-on stays a
/// readable line rather than a speck on a huge axis.
pub(crate) fn side_view(
    title: &str,
    series: &[Series3],
    (a, b): (usize, usize),
    bounds: &[[f64; 3]],
) -> LineChart {
    let mut lines: Vec<Series> = series
        .iter()
        .map(|s| Series {
            label: s.label.clone(),
            x: s.points.iter().map(|p| p[a]).collect(),
            y: s.points.iter().map(|p| p[b]).collect(),
            style: s.style,
            color: s.color,
        })
        .collect();
    let all = || series.iter().flat_map(|s| &s.points).chain(bounds);
    let extent = |k: usize| crate::plot::extent(all().map(|p| p[k])).unwrap_or((0.0, 0.0));
    let ((a0, a1), (b0, b1)) = (extent(a), extent(b));
    let (ca, cb) = (0.5 * (a0 + a1), 0.5 * (b0 + b1));
    let span = (a1 - a0).max(b1 - b0);
    let (ha, hb) = (
        (0.5 * (a1 - a0)).max(0.125 * span),
        (0.5 * (b1 - b0)).max(0.125 * span),
    );
    if span > 0.0 {
        lines.push(Series::new(
            "",
            vec![ca - ha, ca + ha],
            vec![cb - hb, cb + hb],
            SeriesStyle::Bounds,
        ));
    }
    LineChart {
        title: title.into(),
        x_label: AXES[a].into(),
        y_label: AXES[b].into(),
        series: lines,
        log_y: false,
        equal_aspect: true,
    }
}

/// The side views x–z and x–y of `series` side by side under `title`.
pub(crate) fn side_views(title: &str, series: &[Series3], bounds: &[[f64; 3]]) -> Figure {
    Figure::Grid {
        title: title.into(),
        cols: 2,
        panels: vec![
            Figure::Line(side_view("Side view x–z", series, (0, 2), bounds)),
            Figure::Line(side_view("Top view x–y", series, (0, 1), bounds)),
        ],
    }
}

/// `n` indices spread evenly over `0..len` (first and last included), without repeats.
pub(crate) fn spread(len: usize, n: usize) -> Vec<usize> {
    if len == 0 || n == 0 {
        return vec![];
    }
    if n == 1 || len == 1 {
        return vec![len - 1];
    }
    let mut v: Vec<usize> = (0..n)
        .map(|k| ((k * (len - 1)) as f64 / (n - 1) as f64).round() as usize)
        .collect();
    v.dedup();
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_keeps_ends_and_never_repeats() {
        assert_eq!(spread(10, 4), vec![0, 3, 6, 9]);
        assert_eq!(spread(3, 5), vec![0, 1, 2]);
        assert_eq!(spread(1, 3), vec![0]);
        assert!(spread(0, 3).is_empty());
    }

    #[test]
    fn edge_on_side_view_gets_a_readable_vertical_span() {
        // a rod along x in the x–z plane, seen from above (x–y): y is zero everywhere
        let rod = Series3::new(
            "rod",
            (0..5)
                .map(|i| [0.05 * i as f64, 0.0, -0.01 * i as f64])
                .collect(),
            SeriesStyle::Line,
        );
        let top = side_view("top", &[rod], (0, 1), &[]);
        let b = top.series.last().unwrap();
        assert_eq!(b.style, SeriesStyle::Bounds);
        // the vertical half-span is an eighth of the horizontal span (0.2 m)
        assert!((b.y[1] - b.y[0] - 0.05).abs() < 1e-12, "{:?}", b.y);
    }

    #[test]
    fn zero_groups_are_drawn_flat_and_named() {
        let x = [0.0, 0.1, 0.2];
        let panels = strain_panels(&x, |c, j| if c == 1 { j as f64 } else { 0.0 });
        let Figure::Line(k) = &panels[0] else {
            panic!()
        };
        assert_eq!(k.series.len(), 1);
        assert_eq!(k.series[0].label, "bend-y κ₂");
        let Figure::Line(e) = &panels[1] else {
            panic!()
        };
        assert_eq!(e.series.len(), 3);
        assert!(e.title.contains("zero everywhere"));
    }
}
