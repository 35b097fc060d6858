//! Input paths (a scenario file, a `--input` CSV) that must be regular files: the error naming
//! the field, the path and what it is instead (a FIFO, a directory, …).

use crate::error::ScenarioError;
use std::path::Path;

/// The error of `path` (given as `field`, e.g. `SCENARIO` or `--input`) that is `kind` ("a FIFO
/// (named pipe)", "a directory", …: [`crate::output::read::file_kind`]) instead of a regular file.
fn not_a_regular_file(field: &str, path: &Path, kind: &str) -> ScenarioError {
    ScenarioError::invalid(
        field,
        format!("`{}` is {kind}, not a regular file", path.display()),
    )
}

/// An error of [`crate::output::read`] reading the input `path` (given as `field`) as a scenario
/// error: a path that is not a regular file is refused naming `field`, the path and what it is; any
/// other error (missing, no permission, not UTF-8) goes through `other`.
pub fn read_error(
    field: &str,
    path: &Path,
    e: std::io::Error,
    other: impl FnOnce(std::io::Error) -> ScenarioError,
) -> ScenarioError {
    match crate::output::read::not_regular_kind(&e) {
        Some(kind) => not_a_regular_file(field, path, kind),
        None => other(e),
    }
}

/// Refuses `path` (given as `field`) if it is something other than a regular file (or a link to
/// one); the error says what it is. A path whose metadata cannot be read (missing, no permission)
/// passes: the reader reports that itself. A check before opening leaves a window in which the path
/// can be replaced: read with [`crate::output::read`] (and [`read_error`]) instead, which also
/// checks the opened file.
pub fn check_regular_file(field: &str, path: &Path) -> Result<(), ScenarioError> {
    match std::fs::metadata(path) {
        Ok(meta) if !meta.is_file() => Err(not_a_regular_file(
            field,
            path,
            crate::output::read::file_kind(&meta.file_type()),
        )),
        _ => Ok(()),
    }
}
