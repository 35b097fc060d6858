//! `gvsrom.plot(output, out)`: the figures of a gvsrom output, as `gvsrom plot` draws them
//! ([`gvsrom::figures::plot_outputs`]).

use crate::errors::{self, invalid};
use gvsrom::figures::{self, FigureFormat};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// Draws the figures of a gvsrom output into a new directory, as ``gvsrom plot`` does: a
/// ``statics``, ``modes`` or ``linearize`` JSON file, or a trajectory, dataset or model
/// directory. Each figure is written as SVG and/or PNG (fonts embedded), with ``meta.json``
/// recording how they were made.
///
/// Parameters
/// ----------
/// output : str or os.PathLike
///     The gvsrom output to draw.
/// out : str or os.PathLike
///     New directory for the figures (an earlier gvsrom output there only with ``force``).
/// formats : str or list of str, optional
///     ``"svg"`` and/or ``"png"``; default (``None``) both.
/// force : bool
///     Replace ``out`` if it is an earlier gvsrom output (never anything else).
///
/// Returns
/// -------
/// dict
///     ``kind`` (what was drawn: ``"statics result"``, ``"trajectory"``, ``"dataset"``,
///     ``"reduced model"``, ``"linearization"`` or ``"modes"``), ``out`` (the directory),
///     ``figures`` (the files written), ``notes`` (figures left out and why), ``wall_time_s``.
///
/// Raises
/// ------
/// GvsromError
///     For an input that is not a gvsrom output with figures, an unknown format, or an ``out``
///     that is not ours to replace.
#[pyfunction]
#[pyo3(signature = (output, out, formats=None, force=false))]
pub fn plot<'py>(
    py: Python<'py>,
    output: PathBuf,
    out: PathBuf,
    formats: Option<&Bound<'_, PyAny>>,
    force: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let given = formats.is_some_and(|f| !f.is_none());
    let formats = crate::arrays::strings("formats", formats)?;
    if given && formats.is_empty() {
        return Err(invalid(
            "`formats`: an empty list draws nothing (accepted: \"svg\", \"png\", or both; None for both)",
        ));
    }
    let formats = (formats.iter())
        .map(|f| match f.as_str() {
            "svg" => Ok(FigureFormat::Svg),
            "png" => Ok(FigureFormat::Png),
            other => Err(invalid(format!(
                "`formats`: unknown image format `{other}` (accepted: \"svg\", \"png\")"
            ))),
        })
        .collect::<PyResult<Vec<_>>>()?;
    let summary = py
        .detach(|| figures::plot_outputs(&output, &out, &formats, force))
        .map_err(|e| invalid(errors::chain(&e)))?;
    let d = PyDict::new(py);
    d.set_item("kind", summary.kind.name())?;
    d.set_item("out", summary.out)?;
    let names: Vec<&str> = summary.written.iter().map(|w| w.name.as_str()).collect();
    d.set_item("figures", names)?;
    d.set_item("notes", summary.notes)?;
    d.set_item("wall_time_s", summary.wall_time_s)?;
    Ok(d)
}
