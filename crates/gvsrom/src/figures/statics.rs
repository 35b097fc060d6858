//! Figures of a `gvsrom statics --json` result: the rod's shape in 3-D (`rod_3d`) and in side views
//! x–z and x–y (`rod_side`), and the strain along the rod (`strain`: curvatures in 1/m, stretch and
//! shears dimensionless).

use super::views::{self, AXES};
use super::{input_error, FiguresError, Sink};
use crate::plot::{palette, Figure, Line3, Series3, SeriesStyle};
use serde::Deserialize;
use std::path::Path;

/// The fields of a `statics --json` document the figures use.
#[derive(Debug, Clone, Deserialize)]
pub struct StaticsDoc {
    pub scenario: String,
    #[serde(default)]
    pub u: Vec<f64>,
    pub tip_position: [f64; 3],
    pub centerline_x: Vec<f64>,
    pub centerline: Vec<[f64; 3]>,
    pub strain_x: Vec<f64>,
    /// ξ at the points, `[torsion, bend-y, bend-z, elongation, shear-y, shear-z]`.
    pub strain: Vec<[f64; 6]>,
    /// ξ* at the points (a result written before it was recorded: the straight rod,
    /// [`crate::compare::STRAIGHT_STRAIN`]).
    #[serde(default)]
    pub strain_reference: Option<Vec<[f64; 6]>>,
    /// World positions of each tendon at its points (results written before they were recorded,
    /// and rods without tendons, have none).
    #[serde(default)]
    pub tendon_paths: Vec<Vec<[f64; 3]>>,
    /// The rigid bodies (results without bodies, or written before they were recorded, have none).
    #[serde(default)]
    pub bodies: Vec<BodyDoc>,
    /// How each tendon was driven, when one was driven by its displacement (else none).
    #[serde(default)]
    pub drives: Vec<DriveDoc>,
    #[serde(default)]
    pub model: Option<String>,
    /// The file by the SHA-256 of the bytes read (what `plot` records of it).
    #[serde(skip)]
    pub origin: Option<crate::provenance::DirOrigin>,
}

/// How a tendon of a statics result was driven: slack ones are drawn dashed.
#[derive(Debug, Clone, Deserialize)]
pub struct DriveDoc {
    #[serde(default)]
    pub slack: bool,
}

/// A rigid body of a statics result: its mass, where its section is and its centre of mass.
#[derive(Debug, Clone, Deserialize)]
pub struct BodyDoc {
    pub mass: f64,
    pub section: [f64; 3],
    pub center: [f64; 3],
}

impl StaticsDoc {
    /// Reads and checks the document at `path`: sizes agree, something to draw.
    pub fn load(path: &Path) -> Result<StaticsDoc, FiguresError> {
        let (mut doc, origin): (StaticsDoc, _) = super::read_json_result(path, "statics")?;
        let mismatch = |what: &str, a: usize, b: usize| {
            input_error(path, format!("{what}: {a} abscissae but {b} values"))
        };
        if doc.centerline.len() != doc.centerline_x.len() {
            return Err(mismatch(
                "centerline",
                doc.centerline_x.len(),
                doc.centerline.len(),
            ));
        }
        if doc.strain.len() != doc.strain_x.len() {
            return Err(mismatch("strain", doc.strain_x.len(), doc.strain.len()));
        }
        if let Some(r) = &doc.strain_reference {
            if r.len() != doc.strain_x.len() {
                return Err(mismatch("strain_reference", doc.strain_x.len(), r.len()));
            }
        }
        if doc.centerline.len() < 2 {
            return Err(input_error(
                path,
                format!(
                    "centerline has {} points (at least 2 are needed to draw the rod)",
                    doc.centerline.len()
                ),
            ));
        }
        doc.origin = Some(origin);
        Ok(doc)
    }

    /// The figure titles' description of the solve: scenario, tensions and model.
    fn caption(&self) -> String {
        super::run_caption(&self.scenario, &self.u, self.model.as_deref())
    }
}

/// The rod's centreline, tendons and tip as 3-D series.
fn rod_series(doc: &StaticsDoc) -> Vec<Series3> {
    let mut series = vec![
        Series3::new("centreline", doc.centerline.clone(), SeriesStyle::Line)
            .with_color(palette::HOM),
    ];
    for (k, path) in doc.tendon_paths.iter().enumerate() {
        if path.len() >= 2 {
            let slack = doc.drives.get(k).is_some_and(|d| d.slack);
            let (name, style) = match slack {
                true => (format!("tendon {k} (slack)"), SeriesStyle::Dashed),
                false => (format!("tendon {k}"), SeriesStyle::Line),
            };
            series.push(Series3::new(name, path.clone(), style).with_color(palette::EXTRA[k % 6]));
        }
    }
    let bodies = doc.bodies.iter().enumerate().map(|(k, b)| {
        let name = format!("body {k} ({} kg)", gvs::error::fmt_value(b.mass));
        (name, b.section, b.center)
    });
    series.extend(body_series(bodies, palette::EXTRA[7]));
    series.push(
        Series3::new("base", vec![doc.centerline[0]], SeriesStyle::Markers)
            .with_color(palette::EXTRA[6]),
    );
    series.push(
        Series3::new("tip", vec![doc.tip_position], SeriesStyle::Markers).with_color(palette::POD),
    );
    series
}

/// Each body as a marker at its centre of mass, joined to its section by a line where the two
/// differ (an off-centre payload hangs from the rod by it).
/// `bodies` are `(name, section, centre)`; an empty name leaves both series out of the legend.
pub(crate) fn body_series(
    bodies: impl Iterator<Item = (String, [f64; 3], [f64; 3])>,
    color: crate::plot::Rgb,
) -> Vec<Series3> {
    let mut series = vec![];
    for (name, section, center) in bodies {
        if section != center {
            let line = match name.is_empty() {
                true => String::new(),
                false => format!("{name}: section to centre of mass"),
            };
            series.push(
                Series3::new(line, vec![section, center], SeriesStyle::Line).with_color(color),
            );
        }
        series.push(Series3::new(name, vec![center], SeriesStyle::Markers).with_color(color));
    }
    series
}

/// `rod_3d`, `rod_side` and `strain` of the statics result at `path`.
pub(crate) fn figures(path: &Path, sink: &mut Sink) -> Result<(), FiguresError> {
    let doc = StaticsDoc::load(path)?;
    sink.origin = doc.origin.clone();
    let caption = doc.caption();
    let rod = rod_series(&doc);
    let rod_3d = Figure::Line3(Line3 {
        title: format!("Rod at equilibrium — {caption}"),
        labels: AXES.map(String::from),
        series: rod.clone(),
        equal_aspect: true,
    });
    sink.figure("rod_3d", &rod_3d, (900, 700))?;
    let side = views::side_views(&format!("Rod at equilibrium — {caption}"), &rod, &[]);
    sink.figure("rod_side", &side, (1400, 600))?;
    if doc.strain.is_empty() {
        sink.note("strain: the result holds no computational points");
        return Ok(());
    }
    let reference = |j: usize| match &doc.strain_reference {
        Some(r) => r[j],
        None => crate::compare::STRAIGHT_STRAIN,
    };
    let panels = views::strain_panels(&doc.strain_x, |c, j| doc.strain[j][c] - reference(j)[c]);
    let strain = Figure::Grid {
        title: format!("Strain along the rod — {caption}"),
        cols: 1,
        panels,
    };
    sink.figure("strain", &strain, (1000, 900))
}
