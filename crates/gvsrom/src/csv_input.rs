//! CSV signals (`simulate --input FILE`, `--load-schedule FILE`): rows `t, v_1, …, v_n` read into a
//! [`Signal`], and the largest |value| per column of a signal.
//!
//! Format: blank lines and lines starting with `#` are skipped. The delimiter is detected from the
//! first data row — `,`, `;`, a tab, or runs of spaces — and every row must use the same one; a row
//! mixing `,`, `;` and tabs is refused (a decimal comma is not supported). A header is recognised only
//! as the first non-blank, non-comment line, and only when none of its cells is a number. Every error
//! names the file, the line (1-based) and, for a cell, its column (1-based).

use crate::error::ScenarioError;
use gvs::inputs::{Interpolation, Signal};
use std::path::Path;

/// A column delimiter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Delimiter {
    Comma,
    Semicolon,
    Tab,
    /// Runs of spaces (or tabs and spaces without any other delimiter).
    Whitespace,
}

impl Delimiter {
    fn describe(self) -> &'static str {
        match self {
            Delimiter::Comma => "`,`",
            Delimiter::Semicolon => "`;`",
            Delimiter::Tab => "a tab",
            Delimiter::Whitespace => "spaces",
        }
    }

    fn split(self, line: &str) -> Vec<&str> {
        match self {
            Delimiter::Comma => line.split(',').map(str::trim).collect(),
            Delimiter::Semicolon => line.split(';').map(str::trim).collect(),
            Delimiter::Tab => line.split('\t').map(str::trim).collect(),
            Delimiter::Whitespace => line.split_whitespace().collect(),
        }
    }
}

/// The delimiter of one (trimmed) line: `Ok(None)` for a single cell; an error text when it mixes
/// `,`, `;` and tabs.
fn detect(line: &str) -> Result<Option<Delimiter>, String> {
    let found: Vec<Delimiter> = [
        (',', Delimiter::Comma),
        (';', Delimiter::Semicolon),
        ('\t', Delimiter::Tab),
    ]
    .into_iter()
    .filter(|(c, _)| line.contains(*c))
    .map(|(_, d)| d)
    .collect();
    match found.as_slice() {
        [] if line.split_whitespace().count() > 1 => Ok(Some(Delimiter::Whitespace)),
        [] => Ok(None),
        [d] => Ok(Some(*d)),
        // tabs padding a `,`/`;` file are whitespace, not a second delimiter
        [d, Delimiter::Tab] if *d != Delimiter::Tab => Ok(Some(*d)),
        [Delimiter::Comma, Delimiter::Semicolon, ..] => Err(
            "mixes `,` and `;` delimiters (one delimiter per file; a decimal comma is not supported, write `0.5`)"
                .into(),
        ),
        _ => Err("mixes delimiters".into()),
    }
}

/// Reads a CSV signal with `n_values` columns after `t` (see the module doc), times ascending,
/// every number finite; a time given twice is a step when `interpolation` is linear and refused
/// when it is a hold ([`Signal::repeated_time`]). `field` names the file where it cannot be read
/// (`--input`); a line's error names the file and line.
pub fn read_csv_signal(
    field: &str,
    path: &Path,
    n_values: usize,
    interpolation: Interpolation,
) -> Result<Signal, ScenarioError> {
    let file = path.display().to_string();
    let text = crate::output::read_regular_to_string(path).map_err(|e| {
        crate::scenario::read_error(field, path, e, |e| {
            ScenarioError::invalid(field, format!("cannot read the input file `{file}`: {e}"))
        })
    })?;
    let expected = n_values + 1;
    let mut times: Vec<f64> = vec![];
    let mut values = vec![];
    // the delimiter and the line it was detected on
    let mut delimiter: Option<(Option<Delimiter>, usize)> = None;
    let mut first_line = true;
    let mut header = false;
    let mut last_line = 0;
    // the line of each row
    let mut lines = vec![];
    for (i, raw) in text.lines().enumerate() {
        let ln = i + 1;
        let line = raw.trim_start_matches('\u{feff}').trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let at = format!("{file}:{ln}");
        let d = detect(line).map_err(|m| ScenarioError::invalid(&at, m))?;
        if std::mem::take(&mut first_line) {
            let cells = d.map_or(vec![line], |d| d.split(line));
            if cells.iter().all(|c| c.parse::<f64>().is_err()) {
                header = true;
                continue;
            }
        }
        let d = match delimiter {
            None => {
                delimiter = Some((d, ln));
                d
            }
            Some((first, first_ln)) => {
                if d.is_some() && first.is_some() && d != first {
                    return Err(ScenarioError::invalid(
                        &at,
                        format!(
                            "the delimiter is {}, line {first_ln} (the first data row) uses {}; use one delimiter in the whole file",
                            d.map_or("none", Delimiter::describe),
                            first.map_or("none", Delimiter::describe),
                        ),
                    ));
                }
                first.or(d)
            }
        };
        let cells = d.map_or(vec![line], |d| d.split(line));
        if cells.len() != expected {
            return Err(ScenarioError::invalid(
                &at,
                format!(
                    "{} columns, expected {expected} (t and {n_values} value{} per row, delimited by {})",
                    cells.len(),
                    if n_values == 1 { "" } else { "s" },
                    d.map_or("`,`", Delimiter::describe)
                ),
            ));
        }
        let mut row = Vec::with_capacity(expected);
        for (c, cell) in cells.iter().enumerate() {
            let field = format!("{at} column {}", c + 1);
            let v: f64 = cell.parse().map_err(|_| {
                let what = if cell.is_empty() {
                    "the cell is empty".to_string()
                } else {
                    format!("`{cell}` is not a number")
                };
                ScenarioError::invalid(&field, what)
            })?;
            if !v.is_finite() {
                return Err(ScenarioError::value(field, v, "a finite number"));
            }
            row.push(v);
        }
        if let Some(&prev) = times.last() {
            if row[0] < prev {
                return Err(ScenarioError::invalid(
                    format!("{at} column 1"),
                    format!(
                        "t = {} (times[{}]) is before t = {prev} on line {last_line}: times must be in ascending order",
                        row[0],
                        times.len()
                    ),
                ));
            }
        }
        last_line = ln;
        lines.push(ln);
        times.push(row[0]);
        values.push(row[1..].to_vec());
    }
    if times.is_empty() {
        return Err(ScenarioError::invalid(
            &file,
            if header {
                "the file holds a header but no data rows"
            } else {
                "the file holds no data rows"
            },
        ));
    }
    let s = Signal {
        times,
        values,
        interpolation,
    };
    if let Some(k) = (1..s.times.len()).find(|&k| s.repeated_time(k).is_some()) {
        let why = s.repeated_time(k).unwrap_or_default();
        let others = match s.times.get(k.wrapping_sub(2)) == Some(&s.times[k]) {
            true => format!("lines {} and {} have it too", lines[k - 2], lines[k - 1]),
            false => format!("line {} has it too", lines[k - 1]),
        };
        return Err(ScenarioError::invalid(
            format!("{file}:{} column 1", lines[k]),
            format!("{why} ({others})"),
        ));
    }
    s.validate(&file, n_values).map_err(ScenarioError::from)?;
    Ok(s)
}

/// The SHA-256 of the file at `path` (option `field`), in hex: what a trajectory records of its
/// CSV input, so that two runs can be told to have had the same input.
pub fn file_sha256(field: &str, path: &Path) -> Result<String, ScenarioError> {
    let bytes = crate::output::read_regular(path).map_err(|e| {
        crate::scenario::read_error(field, path, e, |e| {
            ScenarioError::invalid(field, format!("cannot read `{}`: {e}", path.display()))
        })
    })?;
    Ok(crate::output::integrity::sha256_hex(&bytes))
}

/// The largest |value| of each channel over the signal's knots: `max_k |values[k][j]|`, which is
/// also its maximum over time (held or linearly interpolated between knots). Empty without channels.
pub fn max_abs_per_column(signal: &Signal) -> Vec<f64> {
    let mut out = vec![0.0f64; signal.channels()];
    for row in &signal.values {
        for (m, v) in out.iter_mut().zip(row) {
            *m = m.max(v.abs());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The folder of the files `read` writes (made once per process, shared by the tests).
    fn csv_dir() -> std::path::PathBuf {
        static DIR: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();
        DIR.get_or_init(|| crate::output::test_util::sandbox("csv", "files"))
            .clone()
    }

    /// Writes `text` to a file unique to `name` and reads it with `n` value columns.
    fn read(name: &str, text: &str, n: usize) -> Result<Signal, String> {
        let path = csv_dir().join(name);
        std::fs::write(&path, text).unwrap();
        read_csv_signal("--input", &path, n, Interpolation::Hold).map_err(|e| e.to_string())
    }

    fn rows(s: &Signal) -> Vec<(f64, Vec<f64>)> {
        s.times
            .iter()
            .copied()
            .zip(s.values.iter().cloned())
            .collect()
    }

    #[test]
    fn a_time_given_twice_names_both_lines_when_held_and_is_a_step_when_linear() {
        let text = "t,u\n0,0\n# the step\n1,0\n1,4\n2,4\n";
        let e = read("twice.csv", text, 1).unwrap_err();
        assert!(
            e.contains("twice.csv:5 column 1") && e.contains("line 4 has it too"),
            "{e}"
        );
        let dir = csv_dir();
        let linear =
            read_csv_signal("--input", &dir.join("twice.csv"), 1, Interpolation::Linear).unwrap();
        assert_eq!(linear.times, vec![0.0, 1.0, 1.0, 2.0]);
        let thrice = "0,0\n1,0\n1,2\n1,4\n";
        read("thrice.csv", thrice, 1).unwrap_err();
        let path = dir.join("thrice.csv");
        let e = read_csv_signal("--input", &path, 1, Interpolation::Linear)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("thrice.csv:4 column 1")
                && e.contains("third knot")
                && e.contains("lines 2 and 3 have it too"),
            "{e}"
        );
    }

    #[test]
    fn every_delimiter_reads_the_same_rows() {
        let expected = vec![(0.0, vec![-1.0, 2.0]), (0.5, vec![-2.5, 3.0])];
        for (name, text) in [
            ("comma.csv", "0,-1,2\n0.5,-2.5,3\n"),
            ("comma-spaced.csv", "0, -1, 2\n0.5, -2.5, 3\n"),
            ("semicolon.csv", "0;-1;2\n0.5;-2.5;3\n"),
            ("tab.csv", "0\t-1\t2\n0.5\t-2.5\t3\n"),
            ("spaces.csv", "0   -1  2\n  0.5 -2.5 3  \n"),
            ("crlf.csv", "t;u0;u1\r\n0;-1;2\r\n0.5;-2.5;3\r\n"),
            ("bom.csv", "\u{feff}0,-1,2\n0.5,-2.5,3\n"),
        ] {
            let s = read(name, text, 2).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(rows(&s), expected, "{name}");
        }
    }

    #[test]
    fn a_header_is_only_a_first_line_without_numbers() {
        // `;`-delimited with a header: the header is skipped and every data row kept
        let s = read("header.csv", "# comment\n\nt;u\n0;-1\n1;-2\n", 1).unwrap();
        assert_eq!(rows(&s), vec![(0.0, vec![-1.0]), (1.0, vec![-2.0])]);
        // a `;` file without a header keeps its first data row
        let s = read("noheader.csv", "0;-1\n1;-2\n", 1).unwrap();
        assert_eq!(s.times, vec![0.0, 1.0]);
        // a first line with one number is a data row: its other cell is named
        let e = read("half.csv", "0;u\n1;-2\n", 1).unwrap_err();
        assert!(
            e.contains("half.csv:1 column 2") && e.contains("`u` is not a number"),
            "{e}"
        );
        // a header after the first data row is not a header
        let e = read("late.csv", "0,1\nt,u\n", 1).unwrap_err();
        assert!(
            e.contains("late.csv:2 column 1") && e.contains("`t` is not a number"),
            "{e}"
        );
        let e = read("only-header.csv", "t,u\n", 1).unwrap_err();
        assert!(e.contains("a header but no data rows"), "{e}");
        let e = read("empty.csv", "# nothing\n\n", 1).unwrap_err();
        assert!(e.contains("empty.csv") && e.contains("no data rows"), "{e}");
    }

    #[test]
    fn mixed_or_inconsistent_delimiters_are_refused_with_the_line() {
        let e = read("mixed.csv", "0;-1,5\n", 1).unwrap_err();
        assert!(
            e.contains("mixed.csv:1")
                && e.contains("mixes `,` and `;`")
                && e.contains("decimal comma"),
            "{e}"
        );
        let e = read("switch.csv", "0,-1\n0.5;-2\n", 1).unwrap_err();
        assert!(
            e.contains("switch.csv:2")
                && e.contains("the delimiter is `;`, line 1")
                && e.contains("uses `,`"),
            "{e}"
        );
        let e = read("switch-ws.csv", "0;-1\n0.5 -2\n", 1).unwrap_err();
        assert!(e.contains("switch-ws.csv:2") && e.contains("spaces"), "{e}");
    }

    #[test]
    fn bad_cells_name_line_and_column() {
        let e = read("cols.csv", "t,u0\n0,-1\n0.5,-2,3\n", 1).unwrap_err();
        assert!(
            e.contains("cols.csv:3") && e.contains("3 columns, expected 2"),
            "{e}"
        );
        let e = read("nan.csv", "0,-1\n0.5,nan\n", 1).unwrap_err();
        assert!(
            e.contains("nan.csv:2 column 2") && e.contains("finite"),
            "{e}"
        );
        let e = read("blank-cell.csv", "0,,1\n", 2).unwrap_err();
        assert!(
            e.contains("blank-cell.csv:1 column 2") && e.contains("empty"),
            "{e}"
        );
        let e = read("order.csv", "0,-1\n0.5,-2\n\n0.2,-3\n", 1).unwrap_err();
        assert!(
            e.contains("order.csv:4 column 1")
                && e.contains("times[2]")
                && e.contains("on line 2")
                && e.contains("ascending"),
            "{e}"
        );
        let e = read_csv_signal(
            "--input",
            Path::new("/nonexistent/in.csv"),
            1,
            Interpolation::Hold,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("/nonexistent/in.csv") && e.contains("cannot read") && e.contains("--input"),
            "{e}"
        );
    }

    #[test]
    fn a_directory_or_device_is_refused_before_it_is_read() {
        let dir = crate::output::test_util::sandbox("csv", "a-directory");
        let e = read_csv_signal("--input", &dir, 1, Interpolation::Hold)
            .unwrap_err()
            .to_string();
        assert!(e.contains("a directory, not a regular file"), "{e}");
        let e = read_csv_signal("--input", Path::new("/dev/zero"), 1, Interpolation::Hold)
            .unwrap_err()
            .to_string();
        assert!(e.contains("a character device"), "{e}");
        let e = file_sha256("--input", Path::new("/dev/zero"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--input") && e.contains("a character device"),
            "{e}"
        );
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_fifo_is_refused_naming_it_without_waiting_for_a_writer() {
        let pipe = crate::output::test_util::sandbox("csv", "fifo").join("in.csv");
        crate::output::test_util::fifo(&pipe);
        // no writer ever opens it: a reader that opened it plainly would block this test forever
        let e = read_csv_signal("--input", &pipe, 1, Interpolation::Hold)
            .unwrap_err()
            .to_string();
        let shown = format!(
            "`{}` is a FIFO (named pipe), not a regular file",
            pipe.display()
        );
        assert!(e.contains(&shown), "{e}");
        let e = file_sha256("--input", &pipe).unwrap_err().to_string();
        assert!(e.contains("--input") && e.contains(&shown), "{e}");
    }

    #[test]
    fn max_abs_per_column_takes_the_largest_magnitude() {
        let s = Signal {
            times: vec![0.0, 1.0, 2.0],
            values: vec![vec![1.0, -0.5], vec![-7.0, 0.25], vec![3.0, 0.0]],
            interpolation: Interpolation::Linear,
        };
        assert_eq!(max_abs_per_column(&s), vec![7.0, 0.5]);
        let steps = gvs::inputs::random_steps(2, -15.0, 0.0, 1.0, 10.0, 7);
        let m = max_abs_per_column(&steps);
        assert_eq!(m.len(), 2);
        assert!(m.iter().all(|&v| v > 0.0 && v <= 15.0), "{m:?}");
    }
}
