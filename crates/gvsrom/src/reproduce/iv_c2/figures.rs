//! IV-C2's figures: Fig. 9 (error and wall time per DOF, and the inset's tip traces) and, beyond
//! the paper, the tip traces of either arm with the AE trained with the strain-rate term.

use super::super::report::{figure, RenderedFigure};
use super::super::sim_test::SimRun;
use super::kinetic_dofs::KineticDof;
use super::rate_weights::LossWeights;
use super::Dof;
use crate::compare::Trajectory;
use crate::plot::{palette, Figure, LineChart, Series, SeriesStyle};

/// The trajectories of the inset (HOM, AE-r, POD-r).
pub(super) struct Inset {
    pub(super) r: usize,
    pub(super) hom: Trajectory,
    pub(super) ae: Trajectory,
    pub(super) pod: Trajectory,
}

/// Fig. 9: mean tip error and wall time against the DOF for both ROMs (and the HOM's time), and the
/// inset's tip traces: the tip's path seen along the arm (y–z) and its coordinates over time.
pub(super) fn fig9(
    dofs: &[Dof],
    hom: &SimRun,
    inset: &Inset,
    kinetic: Option<&[KineticDof]>,
) -> anyhow::Result<RenderedFigure> {
    let r: Vec<f64> = dofs.iter().map(|d| d.r as f64).collect();
    let over_r = |label: &str, f: &dyn Fn(&Dof) -> f64, color, style| Series {
        label: label.into(),
        x: r.clone(),
        y: dofs.iter().map(f).collect(),
        style,
        color: Some(color),
    };
    // partial runs are drawn as separate black markers so that they are not read as complete
    let partial = |f: &dyn Fn(&SimRun) -> f64| {
        let (mut x, mut y) = (vec![], vec![]);
        for d in dofs {
            for run in [&d.ae_run, &d.pod_run, &d.pod_energy_run] {
                if !run.complete {
                    x.push(d.r as f64);
                    y.push(f(run));
                }
            }
        }
        for k in kinetic.unwrap_or_default() {
            if !k.run.complete {
                x.push(k.r as f64);
                y.push(f(&k.run));
            }
        }
        Series {
            label: "stopped early".into(),
            x,
            y,
            style: SeriesStyle::Markers,
            color: Some(crate::plot::Rgb(0, 0, 0)),
        }
    };
    let mut error_series = vec![
        over_r(
            "AE-ROM",
            &|d| d.ae_run.tip_mean(),
            palette::AE,
            SeriesStyle::LineMarkers,
        ),
        over_r(
            "POD-ROM",
            &|d| d.pod_run.tip_mean(),
            palette::POD,
            SeriesStyle::LineMarkers,
        ),
        over_r(
            "POD-ROM, energy norm",
            &|d| d.pod_energy_run.tip_mean(),
            palette::POD_ALT,
            SeriesStyle::LineMarkers,
        ),
    ];
    let mut time_series = vec![
        over_r(
            "AE-ROM",
            &|d| d.ae_run.wall_time_s,
            palette::AE,
            SeriesStyle::LineMarkers,
        ),
        over_r(
            "POD-ROM",
            &|d| d.pod_run.wall_time_s,
            palette::POD,
            SeriesStyle::LineMarkers,
        ),
        over_r(
            "POD-ROM, energy norm",
            &|d| d.pod_energy_run.wall_time_s,
            palette::POD_ALT,
            SeriesStyle::LineMarkers,
        ),
        over_r(
            "HOM",
            &|_| hom.wall_time_s,
            palette::HOM,
            SeriesStyle::Dashed,
        ),
    ];
    // beyond the paper: the AE-ROMs of the kinetic-energy norm, purple
    if let Some(k) = kinetic {
        let of = |f: &dyn Fn(&SimRun) -> f64| Series {
            label: "AE-ROM, rate term + kinetic norm".into(),
            x: k.iter().map(|d| d.r as f64).collect(),
            y: k.iter().map(|d| f(&d.run)).collect(),
            style: SeriesStyle::LineMarkers,
            color: Some(palette::EXTRA[2]),
        };
        error_series.push(of(&SimRun::tip_mean));
        time_series.push(of(&|x| x.wall_time_s));
    }
    let stopped = partial(&SimRun::tip_mean);
    if !stopped.x.is_empty() {
        error_series.push(stopped);
        time_series.push(partial(&|x| x.wall_time_s));
    }
    // a log axis labels the powers of ten only: used when at least two lie within the values
    let spans_decade = |series: &[Series]| {
        let v = series.iter().flat_map(|s| s.y.iter().copied());
        let (lo, hi) = v
            .filter(|y| y.is_finite() && *y > 0.0)
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), y| {
                (lo.min(y), hi.max(y))
            });
        hi.log10().floor() - lo.log10().ceil() >= 1.0
    };
    let (error_log, time_log) = (spans_decade(&error_series), spans_decade(&time_series));
    let mut panels = vec![
        Figure::Line(LineChart {
            title: "mean tip error over the test".into(),
            x_label: "DOF r".into(),
            y_label: "mean tip error [% L]".into(),
            series: error_series,
            log_y: error_log,
            equal_aspect: false,
        }),
        Figure::Line(LineChart {
            title: format!("wall time of the {} s test", hom.t_reached),
            x_label: "DOF r".into(),
            y_label: "wall time [s]".into(),
            series: time_series,
            log_y: time_log,
            equal_aspect: false,
        }),
    ];
    panels.extend(trace_panels(inset, [1, 2], None));
    figure(
        "fig9-dof",
        &format!("Fig. 9: mean tip error (% of the length) and wall time of the {d} s test against the number of DOFs for the AE-ROM (gold), the POD-ROM (red) and, beyond the paper, the POD-ROM of the autoencoders' strain-energy norm (blue){kinetic}, the HOM's time as the green dashed line (log scales where the values span two powers of ten; black dots: runs that stopped early, measured up to where they stopped); the tip traces of the HOM, AE-{r} and POD-{r} (r = {r}, the paper's inset): the path seen along the arm (y–z, gravity along −z) and the tip's x, y, z over time", r = inset.r, d = hom.t_reached, kinetic = match kinetic {
            Some(_) => " and the AE-ROMs trained with the strain-rate term, the kinetic-energy norm and a decaying rate (purple; table \"Fig. 9 with the AE-ROMs trained with…\")",
            None => "",
        }),
        &Figure::Grid {
            title: "IV-C2: six-tendon manipulator dynamics, ROMs against the HOM".into(),
            cols: 3,
            panels,
        },
        1800,
        1050,
    )
}

/// The inset's tip traces: the path seen along the arm (world axes `path[0]`–`path[1]`, across the
/// unloaded arm), then the tip's x, y and z over time; HOM, AE-r and POD-r, and `extra` (a label
/// and a trajectory, in blue) if given.
fn trace_panels(
    inset: &Inset,
    path: [usize; 2],
    extra: Option<(String, &Trajectory)>,
) -> Vec<Figure> {
    let mut models = vec![
        (
            "HOM".to_string(),
            &inset.hom,
            palette::HOM,
            SeriesStyle::Line,
        ),
        (
            format!("AE-{}", inset.r),
            &inset.ae,
            palette::AE,
            SeriesStyle::Dashed,
        ),
        (
            format!("POD-{}", inset.r),
            &inset.pod,
            palette::POD,
            SeriesStyle::Dashed,
        ),
    ];
    if let Some((label, t)) = extra {
        models.push((label, t, palette::AE_ALT, SeriesStyle::Dashed));
    }
    let trace = |x_of: &dyn Fn(&Trajectory, usize) -> f64, axis: usize| -> Vec<Series> {
        models
            .iter()
            .map(|(label, t, color, style)| Series {
                label: label.clone(),
                x: (0..t.samples()).map(|k| x_of(t, k)).collect(),
                y: (0..t.samples()).map(|k| t.tip[3 * k + axis]).collect(),
                style: *style,
                color: Some(*color),
            })
            .collect()
    };
    const NAME: [&str; 3] = ["x", "y", "z"];
    let mut panels = vec![Figure::Line(LineChart {
        title: format!("tip path seen along the arm, r = {}", inset.r),
        x_label: format!("tip {} [m]", NAME[path[0]]),
        y_label: format!("tip {} [m]", NAME[path[1]]),
        series: trace(&|t, k| t.tip[3 * k + path[0]], path[1]),
        log_y: false,
        equal_aspect: true,
    })];
    panels.extend((0..3).map(|axis| {
        Figure::Line(LineChart {
            title: format!("tip {} over time, r = {}", NAME[axis], inset.r),
            x_label: "t [s]".into(),
            y_label: format!("tip {} [m]", NAME[axis]),
            series: trace(&|t, k| t.t[k], axis),
            log_y: false,
            equal_aspect: false,
        })
    }));
    panels
}

/// The arm of a trace figure: the paper's horizontal cantilever or the arm hanging along gravity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Arm {
    Horizontal,
    Hanging,
}

impl Arm {
    /// The figure's id, its subject in the caption, its title, and the world axes across the
    /// unloaded arm (the path seen along it).
    fn describe(self) -> (&'static str, &'static str, &'static str, [usize; 2]) {
        match self {
            Arm::Horizontal => (
                "horizontal-trace",
                "the paper's six-tendon arm (preset six-tendon, a horizontal cantilever along +x), the tip traces of the HOM, AE-{r} and POD-{r} of Fig. 9",
                "IV-C2 on the paper's arm: ROMs against the HOM",
                [1, 2],
            ),
            Arm::Hanging => (
                "hanging-trace",
                "the six-tendon arm hanging along gravity (preset six-tendon-hanging), the tip traces of the HOM, AE-{r} and POD-{r} (trained on the hanging arm's babbling)",
                "IV-C2 on the hanging arm: ROMs against the HOM",
                [0, 1],
            ),
        }
    }
}

/// An arm's tip traces on the paper's test input (beyond the paper): HOM, AE-r and POD-r, and the
/// AE-r trained with the strain-rate term and the loss weights `rated.0` (the kinetic-energy norm
/// too, if `kappa`) on the data `rated.1` says (empty: the paper's), if given; the path seen along
/// the arm and x, y, z over time.
pub(super) fn trace_figure(
    arm: Arm,
    inset: &Inset,
    rated: Option<&(LossWeights, String, Trajectory)>,
    test_s: f64,
) -> anyhow::Result<RenderedFigure> {
    let r = inset.r;
    let (id, subject, title, path) = arm.describe();
    let subject = subject.replace("{r}", &r.to_string());
    let extra = rated.map(|(w, _, t)| {
        let (beta, kappa) = (w.beta, w.kappa);
        let label = match kappa {
            Some(k) => format!("AE-{r}, rate term β = {beta}, kinetic norm κ = {k}"),
            None => format!("AE-{r}, rate term β = {beta}"),
        };
        (label, t)
    });
    let with = match rated {
        Some((w, data, _)) => format!(
            " and, blue, the AE-{r} trained with the strain-rate term (`--rate-weight {}`){}{data}",
            w.beta,
            w.kappa.map_or(String::new(), |k| format!(
                " and the kinetic-energy norm (`--kinetic-weight {k}`)"
            ))
        ),
        None => String::new(),
    };
    const NAME: [&str; 3] = ["x", "y", "z"];
    figure(
        id,
        &format!("Beyond the paper: {subject}{with} on the paper's {test_s} s test input: the path seen along the arm ({}–{}) and the tip's x, y, z over time", NAME[path[0]], NAME[path[1]]),
        &Figure::Grid {
            title: title.into(),
            cols: 2,
            panels: trace_panels(inset, path, extra),
        },
        1400,
        1050,
    )
}
