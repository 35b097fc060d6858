//! `index.html`: one self-contained page (no network: figures inline as PNG data URIs, no scripts)
//! with every case's setup, tables, findings, notes, figures, settings and step times.

use super::report::{format_number, CaseReport, Cell, Digits};
use anyhow::Context;
use base64::Engine;
use std::path::Path;

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Report prose as HTML: escaped, with each pair of backticks (Markdown's inline code, as the
/// reports write commands, options and presets) made a `<code>` span; an unpaired backtick stays.
fn prose(s: &str) -> String {
    let parts: Vec<&str> = s.split('`').collect();
    let mut h = String::new();
    for (i, part) in parts.iter().enumerate() {
        // odd parts follow an opening backtick; paired when another backtick follows them
        if i % 2 == 0 {
            h.push_str(&esc(part));
        } else if i + 1 < parts.len() {
            h.push_str(&format!("<code>{}</code>", esc(part)));
        } else {
            h.push('`');
            h.push_str(&esc(part));
        }
    }
    h
}

/// The page over `reports`, reading each case's figures from `<dir>/<case>/<stem>.png` (regular
/// files only: [`crate::output::read`]).
pub fn index(reports: &[CaseReport], dir: &Path) -> anyhow::Result<String> {
    let mut h = String::new();
    h.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>gvsrom — the paper reproduced</title>\n<style>\n");
    h.push_str(CSS);
    h.push_str("</style></head><body>\n<h1>gvsrom — <i>Structure-Preserving Model Order Reduction of Slender Soft Robots via Autoencoder-Parameterized Strain</i>, reproduced</h1>\n");
    let quick = reports.iter().any(|r| r.quick);
    h.push_str(&format!(
        "<p class=\"meta\">gvsrom {} · {} case{}{}</p>\n",
        esc(env!("CARGO_PKG_VERSION")),
        reports.len(),
        if reports.len() == 1 { "" } else { "s" },
        if quick {
            " · <b>quick run</b> (reduced sizes: trends, not the paper's values)"
        } else {
            ""
        }
    ));
    h.push_str("<nav><ul>");
    for r in reports {
        h.push_str(&format!(
            "<li><a href=\"#{0}\">{0}: {1}</a></li>",
            esc(&r.case),
            esc(&r.title)
        ));
    }
    h.push_str("</ul></nav>\n");
    for r in reports {
        h.push_str(&format!(
            "<section id=\"{}\"><h2>{} — {}</h2>\n",
            esc(&r.case),
            esc(&r.case),
            esc(&r.title)
        ));
        h.push_str(&format!(
            "<p class=\"meta\">wall time {} s{}</p>\n",
            format_number(r.wall_time_s, Digits::Sig(3)),
            if r.quick { " · quick run" } else { "" }
        ));
        h.push_str("<h3>Setup</h3><ul>");
        for l in &r.setup {
            h.push_str(&format!("<li>{}</li>", prose(l)));
        }
        h.push_str("</ul>\n");
        if !r.findings.is_empty() {
            h.push_str("<h3>The paper's conclusions, as measured</h3><ul class=\"findings\">");
            for f in &r.findings {
                h.push_str(&format!(
                    "<li class=\"{}\"><b>{}</b> {} — {}</li>",
                    if f.holds { "holds" } else { "fails" },
                    if f.holds { "holds:" } else { "does not hold:" },
                    prose(&f.claim),
                    prose(&f.evidence)
                ));
            }
            h.push_str("</ul>\n");
        }
        for t in &r.tables {
            h.push_str(&format!("<h3>{}</h3><table><thead><tr>", prose(&t.title)));
            for c in &t.columns {
                h.push_str(&format!("<th>{}</th>", esc(c)));
            }
            h.push_str("</tr></thead><tbody>");
            for row in &t.rows {
                h.push_str("<tr>");
                for c in row {
                    let class = if matches!(c, Cell::Num { .. }) {
                        " class=\"n\""
                    } else {
                        ""
                    };
                    h.push_str(&format!("<td{class}>{}</td>", esc(&c.render())));
                }
                h.push_str("</tr>");
            }
            h.push_str("</tbody></table>\n");
            if !t.note.is_empty() {
                h.push_str(&format!("<p class=\"note\">{}</p>\n", prose(&t.note)));
            }
        }
        if !r.notes.is_empty() {
            h.push_str("<h3>Differences from the paper</h3><ul>");
            for n in &r.notes {
                h.push_str(&format!("<li>{}</li>", prose(n)));
            }
            h.push_str("</ul>\n");
        }
        for f in &r.figures {
            let path = dir.join(&r.case).join(format!("{}.png", f.stem));
            let png = crate::output::read_regular(&path).with_context(|| {
                format!("{}: cannot read the figure (a PNG file)", path.display())
            })?;
            h.push_str(&format!(
                "<figure><img alt=\"{}\" src=\"data:image/png;base64,{}\"><figcaption>{}</figcaption></figure>\n",
                esc(&f.stem),
                base64::engine::general_purpose::STANDARD.encode(&png),
                esc(&f.caption)
            ));
        }
        h.push_str("<details><summary>Steps and settings</summary><table><thead><tr><th>step</th><th>key</th><th>wall time [s]</th><th>reused</th></tr></thead><tbody>");
        for s in &r.steps {
            h.push_str(&format!(
                "<tr><td>{}</td><td><code>{}</code></td><td class=\"n\">{}</td><td>{}</td></tr>",
                esc(&s.name),
                esc(&s.key),
                format_number(s.wall_time_s, Digits::Sig(3)),
                if s.reused { "yes" } else { "no" }
            ));
        }
        h.push_str("</tbody></table>");
        h.push_str(&format!(
            "<pre>{}</pre></details></section>\n",
            esc(&serde_json::to_string_pretty(&r.settings)?)
        ));
    }
    h.push_str("</body></html>\n");
    Ok(h)
}

const CSS: &str = "body{font-family:'DejaVu Sans',Helvetica,Arial,sans-serif;max-width:1400px;margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
h1{font-size:1.5em}h2{border-bottom:2px solid #2a7;padding-bottom:.2em;margin-top:2em}
h3{margin-top:1.4em}nav ul{columns:2}.meta{color:#666}
table{border-collapse:collapse;margin:.5em 0}th,td{border:1px solid #ccc;padding:.25em .6em}
th{background:#f2f5f3}td.n{text-align:right;font-variant-numeric:tabular-nums}
.note{font-size:.9em;color:#555;max-width:70em}
.findings li.holds b{color:#1a7f37}.findings li.fails b{color:#c62828}
figure{margin:1em 0}figure img{max-width:100%;border:1px solid #ddd}
figcaption{font-size:.9em;color:#444}code{background:#f2f2f2;padding:0 .2em;border-radius:3px;font-size:.92em}pre{background:#f6f6f6;padding:.5em;overflow:auto;font-size:.8em}
";

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::super::report::FigureRef;
    use super::super::{new_report, Case};
    use super::*;

    #[test]
    fn a_figure_that_is_a_fifo_is_an_error_naming_it_not_a_wait() {
        let dir = crate::output::test_util::sandbox("html", "fifo-figure");
        let mut report = new_report(Case::EVERY[0], "t");
        report.figures.push(FigureRef {
            stem: "fig".into(),
            caption: "c".into(),
        });
        let case_dir = dir.join(&report.case);
        std::fs::create_dir_all(&case_dir).unwrap();
        let pipe = case_dir.join("fig.png");
        crate::output::test_util::fifo(&pipe);
        // no writer ever opens it: a plain read would block this test forever
        let e = format!("{:#}", index(&[report], &dir).unwrap_err());
        assert!(
            e.contains(&pipe.display().to_string()) && e.contains("a FIFO (named pipe)"),
            "{e}"
        );
    }
}

#[cfg(test)]
mod prose_tests {
    use super::prose;

    #[test]
    fn backtick_pairs_become_code_and_the_rest_is_escaped() {
        assert_eq!(
            prose("run `gvsrom pod --norm energy` on <data> & `x`"),
            "run <code>gvsrom pod --norm energy</code> on &lt;data&gt; &amp; <code>x</code>"
        );
        assert_eq!(prose("no code"), "no code");
        assert_eq!(prose("`a<b`"), "<code>a&lt;b</code>");
        // an unpaired backtick is kept as text
        assert_eq!(prose("a `b` c ` d"), "a <code>b</code> c ` d");
        assert_eq!(prose("`"), "`");
    }
}
