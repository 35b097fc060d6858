//! `gvsrom plot INPUT --out DIR`: figures of any gvsrom output, drawn with [`crate::plot`] and written
//! through [`crate::output`] as a directory output of format [`FIGURES_FORMAT`].
//!
//! The kind of INPUT is read from its manifest ([`detect`]): a `statics --json` file ([`statics`]), a
//! `simulate --out` trajectory ([`trajectory`]), a `dataset` directory ([`dataset`]), a `pod` /
//! `train` model ([`model`]), a `linearize --json` file ([`linearization`]) or a `modes --json`
//! file ([`modes`]). Each figure is written as SVG and/or PNG under a descriptive name
//! (`rod_3d.svg`, `strain.png`, …); a trajectory with centrelines also gets `rod_animation.gif`.
//! What cannot be drawn from the input (an older trajectory without centrelines, a model without
//! training curves) is skipped with a note, never an error; an input with nothing to draw is one.

pub mod dataset;
pub mod linearization;
pub mod model;
pub mod modes;
pub mod statics;
pub mod trajectory;
mod views;

use crate::output::{OutputDir, OutputError, MANIFEST_FILE, MANIFEST_KEY};
use crate::plot::{self, Figure, PlotError};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;
use thiserror::Error;

/// The manifest format of a figures directory.
pub const FIGURES_FORMAT: &str = "figures";

/// What `gvsrom plot` accepts, for error messages.
pub const ACCEPTED: &str = "a `gvsrom statics --json`, `gvsrom modes --json` or `gvsrom linearize --json` file, or a directory written by `gvsrom simulate --out`, `gvsrom dataset`, `gvsrom pod` or `gvsrom train`";

#[derive(Debug, Error)]
pub enum FiguresError {
    /// INPUT is missing, not a gvsrom output of a kind that can be plotted, or unreadable.
    #[error("INPUT `{path}`: {message}")]
    Input { path: PathBuf, message: String },
    #[error(transparent)]
    Plot(#[from] PlotError),
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// An input error naming `path`.
pub(crate) fn input_error(path: &Path, message: impl Into<String>) -> FiguresError {
    FiguresError::Input {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// An image format of the figures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum FigureFormat {
    Svg,
    Png,
}

/// The kinds of gvsrom output that can be plotted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum InputKind {
    Statics,
    Trajectory,
    Dataset,
    Model,
    Linearization,
    Modes,
}

impl InputKind {
    pub fn name(self) -> &'static str {
        match self {
            InputKind::Statics => "statics result",
            InputKind::Trajectory => "trajectory",
            InputKind::Dataset => "dataset",
            InputKind::Model => "reduced model",
            InputKind::Linearization => "linearization",
            InputKind::Modes => "modes",
        }
    }
}

/// A gvsrom JSON result at `path` (`statics`, `modes`, `linearize --json`) read as `T`, with its
/// origin (the file by the SHA-256 of the bytes read); `what` names the command in the error. A
/// result whose values no longer match the `meta_sha256` its manifest records is refused
/// ([`crate::output::json_file_edited`]): its figures would show what was never computed.
pub(crate) fn read_json_result<T: serde::de::DeserializeOwned>(
    path: &Path,
    what: &str,
) -> Result<(T, crate::provenance::DirOrigin), FiguresError> {
    let text = crate::output::read::read_regular_to_string(path)
        .map_err(|e| input_error(path, format!("cannot read it: {e}")))?;
    let not_readable = |e: serde_json::Error| {
        input_error(
            path,
            format!("not a `{what} --json` result the figures can read: {e}"),
        )
    };
    let value: serde_json::Value = serde_json::from_str(&text).map_err(not_readable)?;
    if crate::output::json_file_edited(&value) {
        return Err(input_error(
            path,
            format!(
                "its values no longer match the `meta_sha256` its manifest records: it was edited since `{what}` wrote it, and its figures would show what was never computed; compute it again"
            ),
        ));
    }
    let doc = serde_json::from_value(value).map_err(not_readable)?;
    Ok((
        doc,
        crate::provenance::DirOrigin::of_file(path, text.as_bytes()),
    ))
}

/// The figure titles' description of a run: its scenario, its tensions to the millinewton without
/// trailing zeros (`u = [-20, -2.5] N`) and the reduced model's directory name.
pub(crate) fn run_caption(scenario: &str, u: &[f64], model: Option<&str>) -> String {
    let mut s = scenario.to_string();
    if !u.is_empty() {
        let u: Vec<String> = (u.iter())
            .map(|v| format!("{}", (v * 1e3).round() / 1e3 + 0.0))
            .collect();
        s.push_str(&format!(", u = [{}] N", u.join(", ")));
    }
    if let Some(m) = model {
        let name = Path::new(m)
            .file_name()
            .map_or(m.to_string(), |n| n.to_string_lossy().into_owned());
        s.push_str(&format!(", model {name}"));
    }
    s
}

/// The manifest format of the gvsrom output at `path` (the `"gvsrom"` object of the JSON file, or
/// of `meta.json` in the directory).
fn manifest_format(path: &Path, json: &Path) -> Result<String, FiguresError> {
    let not_ours = |what: &str| input_error(path, format!("{what}; accepted: {ACCEPTED}"));
    let text = crate::output::read::read_regular_to_string(json).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => not_ours(&format!(
            "has no {MANIFEST_FILE} (not a gvsrom output directory)"
        )),
        std::io::ErrorKind::InvalidData => not_ours("is not a text (JSON) file"),
        _ => input_error(path, format!("cannot read {}: {e}", json.display())),
    })?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| not_ours(&format!("{} is not valid JSON ({e})", json.display())))?;
    value[MANIFEST_KEY]["format"]
        .as_str()
        .map(str::to_string)
        .ok_or_else(|| not_ours(&format!("{} has no gvsrom manifest", json.display())))
}

/// The kind of the gvsrom output at `path`, from its manifest.
pub fn detect(path: &Path) -> Result<InputKind, FiguresError> {
    let md = std::fs::metadata(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => input_error(path, "no such file or directory"),
        _ => input_error(path, format!("cannot read it: {e}")),
    })?;
    let format = if md.is_dir() {
        manifest_format(path, &path.join(MANIFEST_FILE))?
    } else if md.is_file() {
        manifest_format(path, path)?
    } else {
        return Err(input_error(
            path,
            format!("not a regular file or directory; accepted: {ACCEPTED}"),
        ));
    };
    match (format.as_str(), md.is_dir()) {
        ("statics", false) => Ok(InputKind::Statics),
        ("linearize", false) => Ok(InputKind::Linearization),
        ("modes", false) => Ok(InputKind::Modes),
        ("trajectory", true) => Ok(InputKind::Trajectory),
        ("dataset", true) => Ok(InputKind::Dataset),
        (crate::reduced_model::MODEL_FORMAT, true) => Ok(InputKind::Model),
        (f, _) => Err(input_error(
            path,
            format!(
                "a gvsrom output of format \"{f}\", which has no figures; accepted: {ACCEPTED}"
            ),
        )),
    }
}

/// One file written: its name and size.
#[derive(Debug, Clone, Serialize)]
pub struct Written {
    pub name: String,
    pub bytes: usize,
}

/// What [`plot_outputs`] did.
#[derive(Debug, Clone)]
pub struct PlotSummary {
    pub kind: InputKind,
    pub out: PathBuf,
    pub written: Vec<Written>,
    /// Figures left out and why (e.g. a trajectory without centrelines).
    pub notes: Vec<String>,
    pub wall_time_s: f64,
}

/// The figures directory being written: renders each figure in the requested formats.
pub(crate) struct Sink {
    dir: OutputDir,
    formats: Vec<FigureFormat>,
    written: Vec<Written>,
    pub notes: Vec<String>,
    /// The output drawn, as its loader read it (for the provenance).
    pub origin: Option<crate::provenance::DirOrigin>,
}

impl Sink {
    fn write(&mut self, name: &str, bytes: &[u8]) -> Result<(), FiguresError> {
        self.dir
            .write_file(name, |w| std::io::Write::write_all(w, bytes))
            .map_err(|e| self.dir.io_error(&format!("write {name}"), e))?;
        self.written.push(Written {
            name: name.to_string(),
            bytes: bytes.len(),
        });
        Ok(())
    }

    /// Renders `fig` at `size` pixels and writes `stem.svg` and/or `stem.png`.
    pub fn figure(
        &mut self,
        stem: &str,
        fig: &Figure,
        size: (u32, u32),
    ) -> Result<(), FiguresError> {
        let r = plot::render(fig, size.0, size.1)?;
        for f in self.formats.clone() {
            match f {
                FigureFormat::Svg => self.write(&format!("{stem}.svg"), r.svg.as_bytes())?,
                FigureFormat::Png => self.write(&format!("{stem}.png"), &r.png)?,
            }
        }
        Ok(())
    }

    /// Renders `frames` at `size` pixels into the looping GIF `stem.gif`.
    pub fn animation(
        &mut self,
        stem: &str,
        frames: &[Figure],
        size: (u32, u32),
        delay_ms: u32,
    ) -> Result<(), FiguresError> {
        let gif = plot::animation::render_gif(frames, size.0, size.1, delay_ms)?;
        self.write(&format!("{stem}.gif"), &gif)
    }

    /// Records that a figure was left out.
    pub fn note(&mut self, note: impl Into<String>) {
        self.notes.push(note.into());
    }
}

/// `meta.json` of a figures directory.
#[derive(Serialize)]
struct FiguresMeta<'a> {
    input: String,
    kind: InputKind,
    formats: &'a [FigureFormat],
    figures: &'a [Written],
    notes: &'a [String],
    crate_version: &'static str,
    /// How the figures were made: the command line, and the output drawn by its hashes as read.
    provenance: crate::provenance::Provenance,
}

/// Draws the figures of the gvsrom output `input` into the new directory `out` (`--force` replaces
/// an earlier gvsrom output there) in `formats` (SVG and PNG when empty).
pub fn plot_outputs(
    input: &Path,
    out: &Path,
    formats: &[FigureFormat],
    force: bool,
) -> Result<PlotSummary, FiguresError> {
    let t0 = Instant::now();
    let started = crate::provenance::rfc3339_utc(std::time::SystemTime::now());
    crate::output::refuse_overlap("--out", out, &[("INPUT", input)])?;
    let kind = detect(input)?;
    let mut formats: Vec<FigureFormat> = if formats.is_empty() {
        vec![FigureFormat::Svg, FigureFormat::Png]
    } else {
        formats.to_vec()
    };
    formats.dedup();
    let dir = OutputDir::create("--out", out, FIGURES_FORMAT, force)?;
    let mut sink = Sink {
        dir,
        formats,
        written: vec![],
        notes: vec![],
        origin: None,
    };
    match kind {
        InputKind::Statics => statics::figures(input, &mut sink)?,
        InputKind::Trajectory => trajectory::figures(input, &mut sink)?,
        InputKind::Dataset => dataset::figures(input, &mut sink)?,
        InputKind::Model => model::figures(input, &mut sink)?,
        InputKind::Linearization => linearization::figures(input, &mut sink)?,
        InputKind::Modes => modes::figures(input, &mut sink)?,
    }
    if sink.written.is_empty() {
        return Err(input_error(input, "nothing to plot"));
    }
    let Sink {
        dir,
        formats,
        written,
        notes,
        origin,
    } = sink;
    let mut provenance = crate::provenance::Provenance::of_command();
    provenance.started = started;
    if let Some(origin) = origin {
        provenance = provenance.plotted(origin);
    }
    let meta = FiguresMeta {
        input: input.display().to_string(),
        kind,
        formats: &formats,
        figures: &written,
        notes: &notes,
        crate_version: env!("CARGO_PKG_VERSION"),
        provenance,
    };
    let out = dir.commit(&meta)?;
    Ok(PlotSummary {
        kind,
        out,
        written,
        notes,
        wall_time_s: t0.elapsed().as_secs_f64(),
    })
}
