//! `gvsrom reproduce` end to end at test sizes (`--test-sizes`): the reports exist and parse, every
//! number of summary.md's tables is a number of results.json, a second run reuses every step, a run
//! killed with SIGKILL resumes without recomputing its finished steps, SIGINT stops it within
//! seconds keeping what is finished, and the run directory refuses what gvsrom did not create.

mod common;
use common::{expect_error, gvsrom, scratch};
use serde_json::Value;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn run(out: &Path, cases: &[&str]) -> String {
    let mut args = vec!["reproduce"];
    args.extend_from_slice(cases);
    let out_s = out.to_str().unwrap();
    args.extend_from_slice(&["--test-sizes", "--jobs", "2", "--out", out_s]);
    let o = gvsrom(&args);
    let stdout = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        o.status.success(),
        "gvsrom {args:?} failed: {}\n{stdout}",
        String::from_utf8_lossy(&o.stderr)
    );
    stdout
}

/// `(steps, reused)` of each `done in … (N steps, M reused)` line.
fn step_counts(stdout: &str) -> Vec<(usize, usize)> {
    stdout
        .lines()
        .filter_map(|l| {
            let inner = l.split('(').nth(1)?.split(')').next()?;
            let mut it = inner.split(", ");
            let steps = it.next()?.strip_suffix(" steps")?.parse().ok()?;
            let reused = it.next()?.strip_suffix(" reused")?.parse().ok()?;
            Some((steps, reused))
        })
        .collect()
}

/// Every number in `v`, recursively.
fn numbers(v: &Value, into: &mut Vec<f64>) {
    match v {
        Value::Number(n) => into.extend(n.as_f64()),
        Value::Array(a) => a.iter().for_each(|x| numbers(x, into)),
        Value::Object(m) => m.values().for_each(|x| numbers(x, into)),
        _ => {}
    }
}

/// The numeric cells of the markdown tables of `md` (the `Steps` table included), as printed.
fn table_numbers(md: &str) -> Vec<String> {
    md.lines()
        .filter(|l| l.starts_with('|') && !l.starts_with("|---"))
        .flat_map(|l| l.trim_matches('|').split('|').map(|c| c.trim().to_string()))
        .filter(|c| c.parse::<f64>().is_ok())
        .collect()
}

/// Whether the printed `token` is `v` rounded to the digits it shows.
fn shows(token: &str, v: f64) -> bool {
    let t: f64 = token.parse().unwrap();
    let half_ulp = match token.split_once(['e', 'E']) {
        Some((mant, exp)) => {
            let decimals = mant.split_once('.').map_or(0, |(_, d)| d.len()) as i32;
            0.5 * 10f64.powi(exp.parse::<i32>().unwrap() - decimals)
        }
        None => {
            let decimals = token.split_once('.').map_or(0, |(_, d)| d.len()) as i32;
            0.5 * 10f64.powi(-decimals)
        }
    };
    (t - v).abs() <= half_ulp * (1.0 + 1e-9)
}

fn check_case(dir: &Path, case: &str) {
    let d = dir.join(case);
    let results: Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("results.json")).unwrap())
            .expect("results.json parses");
    assert_eq!(results["case"], case);
    let md = std::fs::read_to_string(d.join("summary.md")).unwrap();
    let mut nums = vec![];
    numbers(&results["tables"], &mut nums);
    numbers(&results["steps"], &mut nums);
    let cells = table_numbers(&md);
    assert!(cells.len() > 10, "{case}: too few numbers in summary.md");
    for c in &cells {
        assert!(
            nums.iter().any(|&v| shows(c, v)),
            "{case}: summary.md shows {c}, which is no number of results.json's tables"
        );
    }
    let figures = results["figures"].as_array().unwrap();
    assert!(!figures.is_empty(), "{case}: no figure");
    for f in figures {
        let stem = f["stem"].as_str().unwrap();
        let png = std::fs::read(d.join(format!("{stem}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{case}/{stem}.png");
        let svg = std::fs::read_to_string(d.join(format!("{stem}.svg"))).unwrap();
        assert!(svg.contains("<svg"), "{case}/{stem}.svg");
    }
    assert!(!results["findings"].as_array().unwrap().is_empty());
    assert!(results["setup"].as_array().unwrap().len() >= 2);
    // how the report was made: this version and the command that ran it
    let p = &results["provenance"];
    assert_eq!(
        p["gvsrom_version"],
        env!("CARGO_PKG_VERSION"),
        "{case}: {p}"
    );
    let command: Vec<&str> = p["command"]
        .as_array()
        .unwrap_or_else(|| panic!("{case}: no provenance command: {p}"))
        .iter()
        .filter_map(Value::as_str)
        .collect();
    assert!(
        command.get(1) == Some(&"reproduce") && command.contains(&case),
        "{case}: {command:?}"
    );
    assert!(
        p["started"].as_str().is_some_and(|t| t.ends_with('Z')),
        "{p}"
    );
}

#[test]
fn a_case_runs_end_to_end_reports_only_its_numbers_and_a_second_run_reuses_every_step() {
    let out = scratch("reproduce-e2e");
    let first = run(&out, &["iv-a", "v"]);
    let counts = step_counts(&first);
    assert_eq!(counts.len(), 2, "{first}");
    assert_eq!(counts[0].1, 0, "a fresh run reuses nothing: {first}");
    assert_eq!(
        counts[1].0,
        counts[1].1 + 1,
        "v reuses IV-A's data and models, evaluates anew: {first}"
    );
    check_case(&out, "iv-a");
    check_case(&out, "v");
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(index.contains("Table I (top)") && index.contains("data:image/png;base64,"));
    assert!(
        !index.contains("src=\"http"),
        "the page loads nothing from the network"
    );

    let again = run(&out, &["iv-a", "v"]);
    for (steps, reused) in step_counts(&again) {
        assert_eq!(steps, reused, "the second run recomputed a step: {again}");
    }
    // the same numbers: the second run's report is the first one's
    let r1: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("iv-a/results.json")).unwrap())
            .unwrap();
    assert_eq!(r1["tables"], {
        let _ = run(&out, &["iv-a"]);
        let r2: Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("iv-a/results.json")).unwrap())
                .unwrap();
        r2["tables"].clone()
    });
}

/// The step records of run directory `out` (`steps/<case>/<step>.step.json`).
fn records(out: &Path) -> usize {
    let Ok(cases) = std::fs::read_dir(out.join("steps")) else {
        return 0;
    };
    cases
        .filter_map(Result::ok)
        .filter_map(|c| std::fs::read_dir(c.path()).ok())
        .flat_map(|d| d.filter_map(Result::ok))
        .filter(|e| e.file_name().to_string_lossy().ends_with(".step.json"))
        .count()
}

fn start(out: &Path) -> std::process::Child {
    common::command()
        .args([
            "reproduce",
            "iv-a",
            "--test-sizes",
            "--jobs",
            "1",
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits until `out/steps/*/` holds at least `n` step records (or the child ends).
fn wait_for_records(child: &mut std::process::Child, out: &Path, n: usize) -> usize {
    let t0 = Instant::now();
    loop {
        let k = records(out);
        if k >= n || child.try_wait().unwrap().is_some() || t0.elapsed() > Duration::from_secs(120)
        {
            return k;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn a_killed_run_resumes_without_recomputing_its_finished_steps() {
    let out = scratch("reproduce-kill");
    let mut child = start(&out);
    let done_before = wait_for_records(&mut child, &out, 3);
    let _ = child.kill(); // SIGKILL
    let _ = child.wait();
    let done_before = done_before.max(records(&out));
    assert!(done_before >= 1, "no step finished before the kill");
    let stdout = run(&out, &["iv-a"]);
    let (steps, reused) = step_counts(&stdout)[0];
    assert!(
        reused >= done_before.min(steps),
        "{done_before} steps were finished before the kill, {reused} reused: {stdout}"
    );
    check_case(&out, "iv-a");
    // nothing half-written is visible: every hidden entry left is a staging, a set-aside old output
    // or a lock file of the killed run
    for e in std::fs::read_dir(out.join("steps/iv-a"))
        .unwrap()
        .filter_map(Result::ok)
    {
        let name = e.file_name().to_string_lossy().into_owned();
        assert!(
            !name.starts_with('.')
                || name.contains(".gvsrom-staging-")
                || name.contains(".gvsrom-old-")
                || name.ends_with(".gvsrom-lock"),
            "unexpected entry {name}"
        );
    }
}

#[test]
fn sigint_stops_a_run_within_seconds_and_keeps_the_finished_steps() {
    let out = scratch("reproduce-sigint");
    let mut child = start(&out);
    let before = wait_for_records(&mut child, &out, 2);
    assert!(before >= 2, "the run ended before two steps");
    let t0 = Instant::now();
    let ok = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap()
        .success();
    assert!(ok);
    let status = child.wait().unwrap();
    let waited = t0.elapsed();
    assert!(
        waited < Duration::from_secs(10),
        "SIGINT took {waited:?} to stop the run"
    );
    let mut stderr = String::new();
    use std::io::Read;
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut stderr)
        .unwrap();
    // either interrupted (130) or it had just finished (0)
    match status.code() {
        Some(130) => assert!(stderr.contains("interrupted"), "{stderr}"),
        Some(0) => {}
        other => panic!("exit {other:?}: {stderr}"),
    }
    assert!(records(&out) >= before, "finished steps were lost");
    let stdout = run(&out, &["iv-a"]);
    assert!(step_counts(&stdout)[0].1 >= before, "{stdout}");
}

#[test]
fn a_directory_gvsrom_did_not_create_is_refused_as_the_run_directory() {
    let out = scratch("reproduce-foreign");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    common::expect_error(
        &[
            "reproduce",
            "iv-a",
            "--test-sizes",
            "--out",
            out.to_str().unwrap(),
        ],
        &["--out", "not a gvsrom run directory"],
    );
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine"
    );
    common::expect_error(
        &[
            "reproduce",
            "iv-a",
            "--jobs",
            "0",
            "--out",
            out.to_str().unwrap(),
        ],
        &["--jobs 0"],
    );
}

#[test]
fn a_noise_level_no_case_reads_is_refused_before_anything_is_written() {
    // `--noise` is the noise study's: with IV-A alone it was ignored without a word
    let out = scratch("repro-noise-ignored");
    let _ = std::fs::remove_dir_all(&out);
    expect_error(
        &[
            "reproduce",
            "iv-a",
            "--quick",
            "--noise",
            "0.05",
            "--out",
            out.to_str().unwrap(),
        ],
        &[
            "--noise 0.05: only the noise study reads it",
            "(iv-a) do not",
        ],
    );
    assert!(!out.exists());
}
