//! stderr is best effort: a warning, a progress line or the final error written to a stderr whose
//! reader went away (a pipe closed early: `gvsrom … 2>&1 | head -1`) is dropped. The work goes on
//! and the exit code is the one the run earned — never the abort of a panic in `eprintln!`,
//! whose own message to the same stderr panics again.

mod common;

use common::{rust_files, s, scratch, with_stderr_gone};
use std::fs;
use std::path::Path;

/// A user error still ends with exit code 1 (before: SIGABRT, the process killed by the panic in
/// the panic hook's own `eprintln!`).
#[test]
fn a_user_error_to_a_stderr_whose_reader_is_gone_still_exits_with_code_1() {
    let missing = scratch("stderr-gone").join("no-such-scenario.toml");
    let o = with_stderr_gone(common::command().args(["statics", s(&missing)]));
    assert_eq!(o.status.code(), Some(1), "{:?}", o.status);
}

/// The rule that test and `train_init.rs`'s warning and progress tests check at their call sites, for every other one: no code of the
/// crates (their `src/`, test files excepted) writes with `eprint!`/`eprintln!` — which panic when
/// the write fails — rather than `gvsrom::progress::stderr_line` or a `let _ = writeln!`.
#[test]
fn no_source_writes_to_stderr_with_a_macro_that_panics_on_a_failed_write() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut offenders = Vec::new();
    for krate in ["gvs", "rom", "gvsrom", "gvsrom-py"] {
        let mut files = Vec::new();
        rust_files(&crates.join(krate).join("src"), &mut files);
        for f in files {
            let name = f.file_name().unwrap().to_string_lossy().into_owned();
            if name.starts_with("tests") {
                continue;
            }
            let text = fs::read_to_string(&f).unwrap();
            for (i, line) in text.lines().enumerate() {
                let code = line.trim_start();
                if code.starts_with("//") {
                    continue;
                }
                if code.contains("eprintln!(") || code.contains("eprint!(") {
                    offenders.push(format!("{}:{}: {}", f.display(), i + 1, code));
                }
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "use gvsrom::progress::stderr_line (best effort) instead:\n{}",
        offenders.join("\n")
    );
}
