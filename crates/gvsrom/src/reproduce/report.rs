//! A case's report: tables, findings, notes and figures, written as `results.json` (every number),
//! `summary.md` (rendered from the same values: no number typed twice) and SVG + PNG figures, all in
//! one gvsrom output directory `<out>/<case>/`.

use super::step::StepRecord;
use crate::output::OutputDir;
use crate::plot::{self, Figure};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};

/// How a number is printed: `Sig(n)` significant digits, `Fixed(n)` decimals.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
pub enum Digits {
    Sig(usize),
    Fixed(usize),
}

/// A table cell: text, or a number with its printing precision (`null` in JSON when not finite).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum Cell {
    Num { value: Option<f64>, digits: Digits },
    Text(String),
}

impl Cell {
    pub fn num(value: f64, digits: Digits) -> Cell {
        Cell::Num {
            value: value.is_finite().then_some(value),
            digits,
        }
    }
    pub fn sig(value: f64, n: usize) -> Cell {
        Cell::num(value, Digits::Sig(n))
    }
    pub fn fixed(value: f64, n: usize) -> Cell {
        Cell::num(value, Digits::Fixed(n))
    }
    pub fn int(value: usize) -> Cell {
        Cell::num(value as f64, Digits::Fixed(0))
    }
    pub fn text(s: impl Into<String>) -> Cell {
        Cell::Text(s.into())
    }
    /// The cell as printed in `summary.md` and `index.html`.
    pub fn render(&self) -> String {
        match self {
            Cell::Text(s) => s.clone(),
            Cell::Num { value: None, .. } => "–".into(),
            Cell::Num {
                value: Some(v),
                digits,
            } => format_number(*v, *digits),
        }
    }
}

/// `v` printed with `digits` (significant digits switch to scientific notation below 1e-3 and from
/// 1e6).
pub fn format_number(v: f64, digits: Digits) -> String {
    match digits {
        Digits::Fixed(n) => format!("{v:.n$}"),
        Digits::Sig(n) => {
            if v == 0.0 {
                return "0".into();
            }
            let mag = v.abs().log10().floor() as i32;
            if !(-3..6).contains(&mag) {
                format!("{:.*e}", n.saturating_sub(1), v)
            } else {
                let decimals = (n as i32 - 1 - mag).max(0) as usize;
                format!("{v:.decimals$}")
            }
        }
    }
}

/// A table of the report.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Table {
    pub id: String,
    pub title: String,
    pub columns: Vec<String>,
    pub rows: Vec<Vec<Cell>>,
    /// What the numbers are (units, how measured).
    pub note: String,
}

/// One of the paper's qualitative conclusions, as measured.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Finding {
    pub claim: String,
    pub holds: bool,
    pub evidence: String,
}

/// A figure of the report: files `<stem>.svg` and `<stem>.png`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct FigureRef {
    pub stem: String,
    pub caption: String,
}

/// Everything a case reports (this is `results.json`, with `values` holding the raw measurements).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CaseReport {
    pub case: String,
    pub title: String,
    /// The setup used, one line each (scenario, overrides, data, training, test inputs).
    pub setup: Vec<String>,
    pub tables: Vec<Table>,
    pub findings: Vec<Finding>,
    /// Where and why our results differ from the paper's.
    pub notes: Vec<String>,
    pub figures: Vec<FigureRef>,
    pub steps: Vec<StepRecord>,
    /// The case's settings (sizes, epochs, seeds), as passed to its steps.
    pub settings: serde_json::Value,
    /// Every measured number, structured (per model, per test input).
    pub values: serde_json::Value,
    pub quick: bool,
    pub crate_version: String,
    pub wall_time_s: f64,
    /// How the report was made: the version, the command line and the start time (the steps'
    /// own settings and keys are in `settings` and `steps`).
    #[serde(default)]
    pub provenance: Option<crate::provenance::Provenance>,
}

impl CaseReport {
    /// `summary.md`: title, setup, tables (ours beside the paper's), findings, notes, figures, steps.
    pub fn markdown(&self) -> String {
        let mut s = String::new();
        s.push_str(&format!("# {} — {}\n\n", self.case, self.title));
        if self.quick {
            s.push_str("**Quick run** (`--quick`: reduced sizes): the numbers show the trend, not the paper's values.\n\n");
        }
        s.push_str("## Setup\n\n");
        for l in &self.setup {
            s.push_str(&format!("- {l}\n"));
        }
        for t in &self.tables {
            s.push_str(&format!("\n## {}\n\n", t.title));
            // a `|` inside a cell (|ξ − ξ*|) would end it: Markdown's escape keeps it
            let escape = |c: &str| c.replace('|', "\\|");
            let columns: Vec<String> = t.columns.iter().map(|c| escape(c)).collect();
            s.push_str(&format!("| {} |\n", columns.join(" | ")));
            s.push_str(&format!("|{}\n", "---|".repeat(t.columns.len())));
            for row in &t.rows {
                let cells: Vec<String> = row.iter().map(|c| escape(&c.render())).collect();
                s.push_str(&format!("| {} |\n", cells.join(" | ")));
            }
            if !t.note.is_empty() {
                s.push_str(&format!("\n{}\n", t.note));
            }
        }
        if !self.findings.is_empty() {
            s.push_str("\n## The paper's conclusions, as measured\n\n");
            for f in &self.findings {
                s.push_str(&format!(
                    "- **{}** {} — {}\n",
                    if f.holds { "holds:" } else { "does not hold:" },
                    f.claim,
                    f.evidence
                ));
            }
        }
        if !self.notes.is_empty() {
            s.push_str("\n## Differences from the paper\n\n");
            for n in &self.notes {
                s.push_str(&format!("- {n}\n"));
            }
        }
        if !self.figures.is_empty() {
            s.push_str("\n## Figures\n\n");
            for f in &self.figures {
                s.push_str(&format!(
                    "![{}]({}.png)\n\n*{}* ([SVG]({}.svg))\n\n",
                    f.stem, f.stem, f.caption, f.stem
                ));
            }
        }
        s.push_str("\n## Steps\n\n| step | wall time [s] | reused |\n|---|---|---|\n");
        for r in &self.steps {
            s.push_str(&format!(
                "| {} | {} | {} |\n",
                r.name,
                format_number(r.wall_time_s, Digits::Sig(3)),
                if r.reused { "yes" } else { "no" }
            ));
        }
        s
    }
}

/// A rendered figure waiting to be written.
pub struct RenderedFigure {
    pub stem: String,
    pub caption: String,
    pub svg: String,
    pub png: Vec<u8>,
}

/// Renders `fig` (`width × height` px).
pub fn figure(
    stem: &str,
    caption: &str,
    fig: &Figure,
    width: u32,
    height: u32,
) -> anyhow::Result<RenderedFigure> {
    let r = plot::render(fig, width, height)?;
    Ok(RenderedFigure {
        stem: stem.into(),
        caption: caption.into(),
        svg: r.svg,
        png: r.png,
    })
}

/// Writes the case directory `dir` (replacing an earlier report there): `results.json`,
/// `summary.md` and the figures. Returns its path.
pub fn write_case(
    dir: &Path,
    report: &mut CaseReport,
    figures: Vec<RenderedFigure>,
) -> anyhow::Result<PathBuf> {
    let mut out = OutputDir::create("--out", dir, "reproduce-case", true)?;
    report.figures = figures
        .iter()
        .map(|f| FigureRef {
            stem: f.stem.clone(),
            caption: f.caption.clone(),
        })
        .collect();
    for f in &figures {
        out.write_file(&format!("{}.svg", f.stem), |w| {
            w.write_all(f.svg.as_bytes())
        })?;
        out.write_file(&format!("{}.png", f.stem), |w| w.write_all(&f.png))?;
    }
    let json = serde_json::to_string_pretty(report)?;
    out.write_file("results.json", |w| w.write_all(json.as_bytes()))?;
    let md = report.markdown();
    out.write_file("summary.md", |w| w.write_all(md.as_bytes()))?;
    Ok(out.commit(serde_json::json!({ "case": report.case, "quick": report.quick }))?)
}

/// "ours / paper" as a cell (three significant digits), `–` when either is missing or zero.
pub fn ratio(ours: f64, paper: f64) -> Cell {
    if paper == 0.0 || !ours.is_finite() {
        Cell::num(f64::NAN, Digits::Sig(3))
    } else {
        Cell::sig(ours / paper, 3)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bar_inside_a_cell_is_escaped_and_does_not_split_the_markdown_row() {
        let mut r = super::super::new_report(super::super::Case::IvC2, "t");
        r.tables.push(Table {
            id: "t".into(),
            title: "T".into(),
            columns: vec!["r".into(), "max |ξ − ξ*|".into()],
            rows: vec![vec![Cell::int(7), Cell::text("|a|")]],
            note: String::new(),
        });
        let md = r.markdown();
        assert!(md.contains("| r | max \\|ξ − ξ*\\| |"), "{md}");
        assert!(md.contains("| 7 | \\|a\\| |"), "{md}");
        // every row has as many unescaped separators as the header
        let cells = |l: &str| l.replace("\\|", "").matches('|').count();
        let rows: Vec<&str> = md.lines().filter(|l| l.starts_with('|')).take(3).collect();
        assert!(rows.iter().all(|l| cells(l) == 3), "{rows:?}");
    }

    #[test]
    fn numbers_print_with_their_digits() {
        assert_eq!(format_number(0.038312, Digits::Sig(3)), "0.0383");
        assert_eq!(format_number(4.81, Digits::Sig(3)), "4.81");
        assert_eq!(format_number(127.4, Digits::Sig(3)), "127");
        assert_eq!(format_number(2.5e-5, Digits::Sig(2)), "2.5e-5");
        assert_eq!(format_number(1.5, Digits::Fixed(2)), "1.50");
        assert_eq!(Cell::num(f64::NAN, Digits::Sig(2)).render(), "–");
    }
}
