//! Figures of a `gvsrom simulate --out` trajectory: the tip's path in 3-D (`tip_path_3d`) and in side
//! views (`tip_path_side`), the tip's coordinates over time (`tip_position`), the strain over time
//! at a few points along the rod (`strain_time`), the tendons' tensions over time (`tensions`,
//! from `u.npy`, when they vary), how far each tendon is pulled in over time
//! (`tendon_lengths`, from `tendon_lengths.npy` and the rest lengths), and, when the trajectory
//! stores its centrelines
//! (`centerline.npy`, shape `[samples, N, 3]`, with `centerline_x` in `meta.json`), the rod at a
//! few instants (`rod_3d`, `rod_side`) and an animation of it (`rod_animation.gif`).

use super::views::{self, AXES};
use super::{input_error, FiguresError, Sink};
use crate::compare::Trajectory;
use crate::plot::{palette, Figure, Line3, LineChart, Series, Series3, SeriesStyle};
use std::path::Path;

/// The file of per-sample centrelines in a trajectory.
pub const CENTERLINE_FILE: &str = "centerline.npy";

/// Frames of the animation at most.
pub const MAX_FRAMES: usize = 36;

/// Rod shapes drawn in `rod_3d` and `rod_side`.
const SNAPSHOTS: usize = 6;

/// Points along the rod whose strain `strain_time` follows.
const STRAIN_POINTS: usize = 4;

/// The centrelines of a trajectory: abscissae and, per sample, the points.
#[derive(Debug, Clone)]
pub struct Centerlines {
    pub x: Vec<f64>,
    /// `samples`, each `x.len()` points \[m\].
    pub shapes: Vec<Vec<[f64; 3]>>,
    /// `samples`, each the tendons' threads at `x` clamped to their spans \[m\] (none in a
    /// trajectory written before they were recorded, or without tendons).
    pub tendons: Vec<Vec<Vec<[f64; 3]>>>,
    /// `samples`, each the rigid bodies' sections and centres of mass \[m\] (none without
    /// `[[bodies]]` or in a trajectory written before they were recorded).
    pub bodies: Vec<Vec<[[f64; 3]; 2]>>,
}

/// The centrelines `Trajectory::load` read (and checked against their recorded hash): `None` for
/// an older trajectory without `centerline.npy`; an error naming the file when it is there but
/// `meta.json` gives no `centerline_x` to read it by.
pub fn centerlines(tr: &Trajectory) -> Result<Option<Centerlines>, FiguresError> {
    let (Some(x), Some(v)) = (&tr.centerline_x, &tr.centerline) else {
        let file = tr.dir.join(CENTERLINE_FILE);
        if file.exists() {
            return Err(input_error(
                &tr.dir.join(crate::output::MANIFEST_FILE),
                format!("{CENTERLINE_FILE} is there but `centerline_x` (at least 2 abscissae [m]) is missing"),
            ));
        }
        return Ok(None);
    };
    let shapes = v
        .chunks_exact(3 * x.len())
        .map(|s| s.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect())
        .collect();
    let tendons = match &tr.tendon_paths {
        Some((na, v)) if *na > 0 => v
            .chunks_exact(na * 3 * x.len())
            .map(|sample| {
                sample
                    .chunks_exact(3 * x.len())
                    .map(|t| t.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect())
                    .collect()
            })
            .collect(),
        _ => vec![],
    };
    let bodies = match &tr.body_positions {
        Some((nb, v)) if *nb > 0 => v
            .chunks_exact(6 * nb)
            .map(|sample| {
                sample
                    .chunks_exact(6)
                    .map(|b| [[b[0], b[1], b[2]], [b[3], b[4], b[5]]])
                    .collect()
            })
            .collect(),
        _ => vec![],
    };
    Ok(Some(Centerlines {
        x: x.clone(),
        shapes,
        tendons,
        bodies,
    }))
}

/// The tip position of sample `k`.
fn tip(tr: &Trajectory, k: usize) -> [f64; 3] {
    [tr.tip[3 * k], tr.tip[3 * k + 1], tr.tip[3 * k + 2]]
}

/// All figures of the trajectory in `dir`.
pub(crate) fn figures(dir: &Path, sink: &mut Sink) -> Result<(), FiguresError> {
    let tr = Trajectory::load(dir, "INPUT").map_err(|e| input_error(dir, e.to_string()))?;
    sink.origin = Some(tr.origin.clone());
    let n = tr.samples();
    if n == 0 {
        return Err(input_error(dir, "the trajectory has no samples"));
    }
    let caption = format!(
        "{}, t = {:.3}–{:.3} s{}",
        tr.scenario,
        tr.t[0],
        tr.t[n - 1],
        if tr.complete { "" } else { " (incomplete run)" }
    );
    let centerlines = centerlines(&tr)?;
    tip_figures(&tr, &caption, sink)?;
    strain_time(&tr, &caption, sink)?;
    tensions(&tr, &caption, sink)?;
    tendon_lengths(&tr, &caption, sink)?;
    match &centerlines {
        Some(c) => rod_figures(&tr, c, &caption, sink)?,
        None => sink.note(format!(
            "rod_3d, rod_side, rod_animation: the trajectory has no {CENTERLINE_FILE} (written by an earlier gvsrom); only the tip is drawn"
        )),
    }
    Ok(())
}

/// `tip_path_3d`, `tip_path_side` and `tip_position`.
fn tip_figures(tr: &Trajectory, caption: &str, sink: &mut Sink) -> Result<(), FiguresError> {
    let n = tr.samples();
    let path: Vec<[f64; 3]> = (0..n).map(|k| tip(tr, k)).collect();
    let series = vec![
        Series3::new("tip path", path.clone(), SeriesStyle::Line).with_color(palette::POD_ALT),
        Series3::new("start", vec![path[0]], SeriesStyle::Markers).with_color(palette::HOM),
        Series3::new("end", vec![path[n - 1]], SeriesStyle::Markers).with_color(palette::POD),
    ];
    let fig = Figure::Line3(Line3 {
        title: format!("Tip path — {caption}"),
        labels: AXES.map(String::from),
        series: series.clone(),
        equal_aspect: true,
    });
    sink.figure("tip_path_3d", &fig, (900, 700))?;
    let side = views::side_views(&format!("Tip path — {caption}"), &series, &[]);
    sink.figure("tip_path_side", &side, (1400, 600))?;
    let panels = (0..3)
        .map(|i| {
            Figure::Line(LineChart {
                title: String::new(),
                x_label: if i == 2 {
                    "t [s]".into()
                } else {
                    String::new()
                },
                y_label: format!("tip {}", AXES[i]),
                series: vec![Series::new(
                    "",
                    tr.t.clone(),
                    path.iter().map(|p| p[i]).collect(),
                    SeriesStyle::Line,
                )
                .with_color(palette::EXTRA[i])],
                log_y: false,
                equal_aspect: false,
            })
        })
        .collect();
    let fig = Figure::Grid {
        title: format!("Tip position — {caption}"),
        cols: 1,
        panels,
    };
    sink.figure("tip_position", &fig, (1000, 900))
}

/// `tensions`: each tendon's tension \[N\] at the samples, drawn as held from one sample to the
/// next (a step of the input, a controller's period; a switch between samples shows at the next
/// one) unless the input was interpolated linearly or is a function of time; the value of the
/// last sample, which drives no step of a held input, is left out of the steps. Nothing without
/// tendons, a note naming the values when no tension varies.
fn tensions(tr: &Trajectory, caption: &str, sink: &mut Sink) -> Result<(), FiguresError> {
    let Some((na, u)) = &tr.tensions else {
        return Ok(());
    };
    let n = tr.samples();
    let varies = (0..*na).any(|j| (1..n).any(|k| u[k * na + j] != u[j]));
    if !varies {
        let values: Vec<String> = (0..*na).map(|j| format!("{} N", u[j])).collect();
        sink.note(format!(
            "tensions: held at {} over the run (not drawn)",
            values.join(", ")
        ));
        return Ok(());
    }
    let input = tr.input.as_ref();
    let smooth = input.is_some_and(|i| i["interpolation"] == "linear" || i["signal"] == "function");
    // a tendon driven by its displacement: its tension follows the motion, no held input
    let driven = |j: usize| {
        input.is_some_and(|i| {
            (i["displacement_channels"].as_array())
                .is_some_and(|d| d.iter().any(|k| k.as_u64() == Some(j as u64)))
        })
    };
    let series = (0..*na)
        .map(|j| {
            let at = |k: usize| u[k * na + j];
            let (t, y): (Vec<f64>, Vec<f64>) = match smooth || driven(j) {
                true => (tr.t.clone(), (0..n).map(at).collect()),
                // held: a corner where the value changes, then on to the last sample
                false => {
                    let mut pts = vec![(tr.t[0], at(0))];
                    for k in 1..n.saturating_sub(1) {
                        if at(k) != at(k - 1) {
                            pts.extend([(tr.t[k], at(k - 1)), (tr.t[k], at(k))]);
                        }
                    }
                    pts.push((tr.t[n - 1], at(n.saturating_sub(2))));
                    pts.into_iter().unzip()
                }
            };
            Series::new(format!("tendon {j}"), t, y, SeriesStyle::Line)
                .with_color(palette::EXTRA[j % palette::EXTRA.len()])
        })
        .collect();
    let fig = Figure::Line(LineChart {
        title: format!("Tendon tensions — {caption}"),
        x_label: "t [s]".into(),
        y_label: "tension u [N] (negative pulls)".into(),
        series,
        log_y: false,
        equal_aspect: false,
    });
    sink.figure("tensions", &fig, (1000, 600))
}

/// `tendon_lengths`: each tendon's pull-in `ℓ_rest − ℓ(t)` \[mm\] over time (its length if the
/// rest lengths are not recorded); nothing without recorded lengths.
fn tendon_lengths(tr: &Trajectory, caption: &str, sink: &mut Sink) -> Result<(), FiguresError> {
    let Some((na, lengths)) = &tr.tendon_lengths else {
        return Ok(());
    };
    let rest = (tr.tendon_rest_lengths.len() == *na).then_some(&tr.tendon_rest_lengths);
    let series = (0..*na)
        .map(|j| {
            let y = (0..tr.samples())
                .map(|k| match rest {
                    Some(r) => 1e3 * (r[j] - lengths[k * na + j]),
                    None => 1e3 * lengths[k * na + j],
                })
                .collect();
            Series::new(format!("tendon {j}"), tr.t.clone(), y, SeriesStyle::Line)
                .with_color(palette::EXTRA[j % palette::EXTRA.len()])
        })
        .collect();
    let (title, y_label) = match rest {
        Some(_) => ("Tendons pulled in", "rest length − length [mm]"),
        None => ("Tendon lengths", "length [mm]"),
    };
    let fig = Figure::Line(LineChart {
        title: format!("{title} — {caption}"),
        x_label: "t [s]".into(),
        y_label: y_label.into(),
        series,
        log_y: false,
        equal_aspect: false,
    });
    sink.figure("tendon_lengths", &fig, (1000, 600))
}

/// `strain_time`: each strain component that moves, at a few points along the rod, over time.
fn strain_time(tr: &Trajectory, caption: &str, sink: &mut Sink) -> Result<(), FiguresError> {
    let (n, p) = (tr.samples(), tr.strain_x.len());
    if p == 0 {
        sink.note("strain_time: the trajectory has no computational points");
        return Ok(());
    }
    let dev = |k: usize, j: usize, c: usize| tr.deviation(k, j, c);
    let active: Vec<usize> = (0..6)
        .filter(|&c| {
            views::nonzero(
                (0..n)
                    .flat_map(|k| (0..p).map(move |j| (k, j)))
                    .map(|(k, j)| dev(k, j, c)),
            )
        })
        .collect();
    if active.is_empty() {
        sink.note("strain_time: the rod stays at its reference strain (every strain deviation ξ − ξ* is zero)");
        return Ok(());
    }
    let points = views::spread(p, STRAIN_POINTS);
    let panels: Vec<Figure> = active
        .iter()
        .map(|&c| {
            Figure::Line(LineChart {
                title: views::component_label(c).into(),
                x_label: "t [s]".into(),
                y_label: format!("ξ − ξ* [{}]", views::component_unit(c)),
                series: points
                    .iter()
                    .enumerate()
                    .map(|(i, &j)| {
                        Series::new(
                            format!("X = {:.3} m", tr.strain_x[j]),
                            tr.t.clone(),
                            (0..n).map(|k| dev(k, j, c)).collect(),
                            SeriesStyle::Line,
                        )
                        .with_color(palette::EXTRA[i % palette::EXTRA.len()])
                    })
                    .collect(),
                log_y: false,
                equal_aspect: false,
            })
        })
        .collect();
    let cols = if panels.len() > 1 { 2 } else { 1 };
    let rows = panels.len().div_ceil(cols) as u32;
    let fig = Figure::Grid {
        title: format!("Strain over time — {caption}"),
        cols,
        panels,
    };
    sink.figure("strain_time", &fig, (700 * cols as u32, 60 + 450 * rows))
}

/// The corners of the box holding every centreline and tip of the run.
fn run_bounds(tr: &Trajectory, c: &Centerlines) -> Vec<[f64; 3]> {
    let all = || {
        c.shapes
            .iter()
            .flatten()
            .copied()
            .chain((0..tr.samples()).map(|k| tip(tr, k)))
            .chain(c.bodies.iter().flatten().map(|b| b[1]))
    };
    let ext = |i: usize| crate::plot::extent(all().map(|p| p[i])).unwrap_or((0.0, 0.0));
    let (x, y, z) = (ext(0), ext(1), ext(2));
    vec![[x.0, y.0, z.0], [x.1, y.1, z.1]]
}

/// `rod_3d`, `rod_side` (the rod at a few instants) and `rod_animation.gif`.
fn rod_figures(
    tr: &Trajectory,
    c: &Centerlines,
    caption: &str,
    sink: &mut Sink,
) -> Result<(), FiguresError> {
    let n = tr.samples();
    let shots = views::spread(n, SNAPSHOTS);
    let mut series: Vec<Series3> = shots
        .iter()
        .enumerate()
        .map(|(i, &k)| {
            Series3::new(
                format!("t = {:.3} s", tr.t[k]),
                c.shapes[k].clone(),
                SeriesStyle::Line,
            )
            .with_color(palette::EXTRA[i % palette::EXTRA.len()])
        })
        .collect();
    // each body at each instant, in the instant's colour
    for (i, &k) in shots.iter().enumerate() {
        let color = palette::EXTRA[i % palette::EXTRA.len()];
        series.extend(body_marks(c.bodies.get(k), color));
    }
    let fig = Figure::Line3(Line3 {
        title: format!("Rod shapes — {caption}"),
        labels: AXES.map(String::from),
        series: series.clone(),
        equal_aspect: true,
    });
    sink.figure("rod_3d", &fig, (900, 700))?;
    let side = views::side_views(&format!("Rod shapes — {caption}"), &series, &[]);
    sink.figure("rod_side", &side, (1400, 600))?;

    let bounds = run_bounds(tr, c);
    let frames_at = views::spread(n, MAX_FRAMES);
    let frames: Vec<Figure> = frames_at
        .iter()
        .map(|&k| animation_frame(tr, c, k, &bounds))
        .collect();
    // about real time, between 50 ms and 250 ms a frame
    let dt = if frames_at.len() > 1 {
        (tr.t[n - 1] - tr.t[0]) / (frames_at.len() - 1) as f64
    } else {
        0.0
    };
    let delay_ms = (dt * 1000.0).clamp(50.0, 250.0).round() as u32;
    sink.animation("rod_animation", &frames, (960, 440), delay_ms)
}

/// Unnamed series of one sample's bodies ([`super::statics::body_series`]).
fn body_marks(bodies: Option<&Vec<[[f64; 3]; 2]>>, color: crate::plot::Rgb) -> Vec<Series3> {
    let each = bodies.into_iter().flatten();
    super::statics::body_series(each.map(|&[s, c]| (String::new(), s, c)), color)
}

/// One frame: the rod at sample `k` (with its tendons, blue, when the trajectory records them) in
/// 3-D and seen from the side (with the tip's path so far), on the axes of the whole run.
fn animation_frame(tr: &Trajectory, c: &Centerlines, k: usize, bounds: &[[f64; 3]]) -> Figure {
    let rod = Series3::new("", c.shapes[k].clone(), SeriesStyle::Line).with_color(palette::HOM);
    let trace = Series3::new(
        "",
        (0..=k).map(|i| tip(tr, i)).collect(),
        SeriesStyle::Dashed,
    )
    .with_color(palette::EXTRA[6]);
    let tip_now = Series3::new("", vec![tip(tr, k)], SeriesStyle::Markers).with_color(palette::POD);
    let box3 = Series3::new("", bounds.to_vec(), SeriesStyle::Bounds);
    let mut series = vec![trace];
    for path in c.tendons.get(k).into_iter().flatten() {
        series.push(Series3::new("", path.clone(), SeriesStyle::Line).with_color(palette::POD_ALT));
    }
    series.extend([rod, tip_now]);
    series.extend(body_marks(c.bodies.get(k), palette::EXTRA[7]));
    let mut in_3d = series.clone();
    in_3d.push(box3);
    Figure::Grid {
        title: format!("{} — t = {:.3} s", tr.scenario, tr.t[k]),
        cols: 2,
        panels: vec![
            Figure::Line3(Line3 {
                title: String::new(),
                labels: AXES.map(String::from),
                series: in_3d,
                equal_aspect: true,
            }),
            Figure::Line(views::side_view("", &series, (0, 2), bounds)),
        ],
    }
}
