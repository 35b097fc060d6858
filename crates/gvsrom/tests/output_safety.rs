//! Nothing the user owns is ever removed or modified (issue 6): every data-loss case found against
//! `simulate --out` and `statics --json`, run through the binary.

mod common;

use common::{expect_error, gvsrom, scratch};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_gvsrom");

/// A fresh directory for one test, holding a user file `own.txt`.
fn sandbox(name: &str) -> PathBuf {
    let dir = scratch(name);
    fs::create_dir_all(&dir).unwrap();
    fs::write(dir.join("own.txt"), "the user's data").unwrap();
    dir
}

/// Every entry of `dir` (names, sorted), recursively as `a/b`.
fn tree(dir: &Path) -> Vec<String> {
    let mut out = vec![];
    for e in fs::read_dir(dir).unwrap() {
        let e = e.unwrap();
        let name = e.file_name().to_string_lossy().into_owned();
        if e.file_type().unwrap().is_dir() {
            out.push(format!("{name}/"));
            out.extend(tree(&e.path()).into_iter().map(|s| format!("{name}/{s}")));
        } else {
            out.push(name);
        }
    }
    out.sort();
    out
}

fn run_in(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(BIN)
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn spawn_in(dir: &Path, args: &[&str]) -> Child {
    Command::new(BIN)
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn meta(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&fs::read_to_string(dir.join("meta.json")).unwrap()).unwrap()
}

/// Rows of a `.npy` file, read from its header by hand (independently of the writer).
fn npy_rows(path: &Path) -> usize {
    let bytes = fs::read(path).unwrap();
    assert_eq!(&bytes[..6], b"\x93NUMPY", "{}", path.display());
    let hl = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + hl]).unwrap();
    let shape = header.split("'shape': (").nth(1).unwrap();
    let dims: Vec<usize> = shape
        .split(')')
        .next()
        .unwrap()
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().unwrap())
        .collect();
    let values: usize = dims.iter().product();
    assert_eq!(
        bytes.len() - 10 - hl,
        8 * values,
        "{} data size",
        path.display()
    );
    dims[0]
}

/// A complete gvsrom trajectory: manifest, `complete`, every listed array with `samples` rows.
fn assert_complete_trajectory(dir: &Path) {
    let m = meta(dir);
    assert_eq!(m["gvsrom"]["format"], "trajectory");
    assert_eq!(m["complete"], true, "{m}");
    let samples = m["samples"].as_u64().unwrap() as usize;
    for f in m["gvsrom"]["files"].as_array().unwrap() {
        let f = f.as_str().unwrap();
        // the per-point arrays have a row per point, not per sample
        if f != "strain_x.npy" && f != "strain_reference.npy" {
            assert_eq!(npy_rows(&dir.join(f)), samples, "{f}");
        }
    }
}

const SHORT: &[&str] = &["simulate", "six-tendon", "--duration", "0.02"];

#[test]
fn out_into_an_existing_user_directory_is_refused_and_its_files_kept() {
    let dir = sandbox("safety-userdir");
    let user = dir.join("userdir");
    fs::create_dir(&user).unwrap();
    fs::write(user.join("notes.txt"), "mine").unwrap();
    for force in [false, true] {
        let mut args = SHORT.to_vec();
        args.extend(["--out", "userdir"]);
        if force {
            args.push("--force");
        }
        let out = run_in(&dir, &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains("not a gvsrom output"), "{err}");
        assert!(
            !String::from_utf8_lossy(&out.stdout).contains("simulated"),
            "refused before computing"
        );
    }
    assert_eq!(fs::read_to_string(user.join("notes.txt")).unwrap(), "mine");
    assert_eq!(tree(&dir), ["own.txt", "userdir/", "userdir/notes.txt"]);
}

#[test]
fn out_dot_dotdot_root_and_cwd_are_refused_and_nothing_is_touched() {
    let dir = sandbox("safety-dots");
    let inner = dir.join("inner");
    fs::create_dir(&inner).unwrap();
    fs::write(inner.join("data.csv"), "1,2").unwrap();
    let before = tree(&dir);
    for target in [".", "..", "/", "./", "../inner", "sub/.."] {
        let mut args = SHORT.to_vec();
        args.extend(["--out", target]);
        let out = run_in(&inner, &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "--out {target}: {err}");
        assert!(err.starts_with("error: --out"), "--out {target}: {err}");
    }
    assert_eq!(tree(&dir), before);
}

#[test]
fn staging_never_touches_an_unrelated_partial_directory() {
    let dir = sandbox("safety-partial");
    fs::create_dir(dir.join("results.partial")).unwrap();
    fs::write(dir.join("results.partial/keep.txt"), "keep").unwrap();
    let mut args = SHORT.to_vec();
    args.extend(["--out", "results.v2"]);
    let out = run_in(&dir, &args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        fs::read_to_string(dir.join("results.partial/keep.txt")).unwrap(),
        "keep"
    );
    assert_complete_trajectory(&dir.join("results.v2"));
    // no staging, lock or aside left behind
    let hidden: Vec<_> = tree(&dir)
        .into_iter()
        .filter(|f| f.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
}

#[test]
fn replacing_needs_force_and_a_previous_output_holding_only_its_own_files() {
    let dir = sandbox("safety-force");
    let mut args = SHORT.to_vec();
    args.extend(["--out", "run"]);
    assert!(run_in(&dir, &args).status.success());
    let first = meta(&dir.join("run"));
    // without --force: refused, the previous output untouched
    let out = run_in(&dir, &args);
    assert!(String::from_utf8_lossy(&out.stderr).contains("pass --force"));
    assert_eq!(meta(&dir.join("run")), first);
    // with --force: replaced by the new run
    let mut forced = vec![
        "simulate",
        "six-tendon",
        "--duration",
        "0.03",
        "--out",
        "run",
        "--force",
    ];
    assert!(run_in(&dir, &forced).status.success());
    assert_eq!(meta(&dir.join("run"))["t_requested"], 0.03);
    assert_complete_trajectory(&dir.join("run"));
    // a file the user added makes it theirs: refused even with --force
    fs::write(dir.join("run/notes.txt"), "mine").unwrap();
    forced[3] = "0.02";
    let out = run_in(&dir, &forced);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("did not write (`notes.txt`)"), "{err}");
    assert_eq!(meta(&dir.join("run"))["t_requested"], 0.03);
    assert_eq!(
        fs::read_to_string(dir.join("run/notes.txt")).unwrap(),
        "mine"
    );
    let hidden: Vec<_> = tree(&dir)
        .into_iter()
        .filter(|f| f.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
}

#[test]
fn an_output_edited_after_gvsrom_wrote_it_is_not_replaced_even_with_force() {
    let dir = sandbox("safety-edited");
    let run = |args: &[&str]| run_in(&dir, args);
    let sim = [
        "simulate",
        "single-tendon",
        "--duration",
        "0.02",
        "--out",
        "run",
        "--force",
    ];
    assert!(run(&sim).status.success());
    // an edited array: refused, naming the file, and kept as the user left it
    fs::write(dir.join("run/q.npy"), "my edited analysis").unwrap();
    let err = String::from_utf8_lossy(&run(&sim).stderr).into_owned();
    assert!(
        err.contains("was changed after gvsrom wrote it") && err.contains("q.npy"),
        "{err}"
    );
    assert_eq!(
        fs::read_to_string(dir.join("run/q.npy")).unwrap(),
        "my edited analysis"
    );
    // an edited meta.json value: refused too
    fs::remove_dir_all(dir.join("run")).unwrap();
    assert!(run(&sim).status.success());
    let mut m = meta(&dir.join("run"));
    m["my_notes"] = "mine".into();
    fs::write(
        dir.join("run/meta.json"),
        serde_json::to_string(&m).unwrap(),
    )
    .unwrap();
    let err = String::from_utf8_lossy(&run(&sim).stderr).into_owned();
    assert!(err.contains("was changed after gvsrom wrote it"), "{err}");
    assert_eq!(meta(&dir.join("run"))["my_notes"], "mine");
    // a JSON file output records the hash of its values: a key added by hand makes it the user's
    let statics = ["statics", "single-tendon", "--json", "eq.json", "--force"];
    assert!(run(&statics).status.success());
    let mut eq: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(dir.join("eq.json")).unwrap()).unwrap();
    // re-indented with the same values it is still gvsrom's, and replaced
    fs::write(
        dir.join("eq.json"),
        serde_json::to_string_pretty(&eq).unwrap(),
    )
    .unwrap();
    assert!(run(&statics).status.success());
    eq["my_notes"] = "mine".into();
    fs::write(dir.join("eq.json"), serde_json::to_string(&eq).unwrap()).unwrap();
    let err = String::from_utf8_lossy(&run(&statics).stderr).into_owned();
    assert!(
        err.contains("--json `eq.json`: was changed after gvsrom wrote it"),
        "{err}"
    );
    assert!(fs::read_to_string(dir.join("eq.json"))
        .unwrap()
        .contains("my_notes"));
}

#[test]
fn a_second_writer_of_the_same_out_is_refused_while_the_first_runs() {
    let dir = sandbox("safety-concurrent");
    let mut first = spawn_in(
        &dir,
        &[
            "simulate",
            "single-tendon",
            // long enough to still hold its lock when the second run, started on a loaded
            // machine, looks for it (1 s was not always)
            "--duration",
            "4",
            "--out",
            "shared",
        ],
    );
    // wait for the first run's lock
    let t0 = Instant::now();
    while !dir.join(".shared.gvsrom-lock").exists() {
        assert!(
            t0.elapsed() < Duration::from_secs(20),
            "the first run never took its lock"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    let out = run_in(
        &dir,
        &[
            "simulate",
            "six-tendon",
            "--duration",
            "0.02",
            "--out",
            "shared",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("another gvsrom process is writing it"),
        "{err}"
    );
    let status = first.wait().unwrap();
    assert!(status.success());
    // the result is the first run's alone
    let m = meta(&dir.join("shared"));
    assert_eq!(m["scenario"], "single-tendon");
    assert_complete_trajectory(&dir.join("shared"));
    assert!(
        !dir.join(".shared.gvsrom-lock").exists(),
        "the lock file is removed"
    );
}

fn signal(child: &Child, sig: &str) {
    let ok = Command::new("kill")
        .args([sig, &child.id().to_string()])
        .status()
        .unwrap()
        .success();
    assert!(ok);
}

/// Waits until the run has written at least one sample into its staging directory.
fn wait_for_samples(dir: &Path) {
    let t0 = Instant::now();
    loop {
        let staged = fs::read_dir(dir).unwrap().any(|e| {
            let e = e.unwrap();
            e.file_name().to_string_lossy().contains("gvsrom-staging")
                && fs::metadata(e.path().join("t.npy.rows"))
                    .map(|m| m.len() >= 16)
                    .unwrap_or(false)
        });
        if staged {
            return;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "no samples were written"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn sigint_or_sigterm_mid_run_writes_the_samples_so_far_marked_partial() {
    for (sig, code, name) in [("-INT", 130, "SIGINT"), ("-TERM", 143, "SIGTERM")] {
        let dir = sandbox(&format!("safety-{name}"));
        let child = spawn_in(
            &dir,
            &[
                "simulate",
                "single-tendon",
                "--duration",
                "1000",
                "--out",
                "long",
            ],
        );
        wait_for_samples(&dir);
        signal(&child, sig);
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "{err}");
        assert!(
            err.contains(&format!("interrupted by {name}")) && err.contains("marked partial"),
            "{err}"
        );
        let m = meta(&dir.join("long"));
        assert_eq!(m["complete"], false);
        assert_eq!(m["reason"], format!("interrupted by {name}"));
        let samples = m["samples"].as_u64().unwrap() as usize;
        assert!(samples >= 2, "{m}");
        let t_reached = m["t_reached"].as_f64().unwrap();
        assert!(t_reached > 0.0 && t_reached < 1000.0);
        for f in [
            "t.npy",
            "q.npy",
            "qd.npy",
            "u.npy",
            "tip_position.npy",
            "tip_rotation.npy",
            "strain.npy",
        ] {
            assert_eq!(npy_rows(&dir.join("long").join(f)), samples, "{f}");
        }
        let hidden: Vec<_> = tree(&dir)
            .into_iter()
            .filter(|f| f.starts_with('.'))
            .collect();
        assert!(hidden.is_empty(), "{hidden:?}");
    }
}

#[test]
fn kill_at_any_moment_of_a_forced_replace_never_leaves_a_broken_output() {
    // SIGKILL cannot be handled: whatever the moment, `run` is either the old or the new complete
    // output, or (only between the two renames) absent with the old one set aside intact.
    let dir = sandbox("safety-kill");
    let args = [
        "simulate",
        "six-tendon",
        "--duration",
        "0.05",
        "--out",
        "run",
        "--force",
    ];
    assert!(run_in(&dir, &args[..6]).status.success());
    let mut delay_ms = 0;
    for _ in 0..12 {
        let mut child = spawn_in(&dir, &args);
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = child.kill();
        let _ = child.wait();
        delay_ms += 15;
        let run = dir.join("run");
        if run.exists() {
            assert_complete_trajectory(&run);
        } else {
            let aside: Vec<_> = fs::read_dir(&dir)
                .unwrap()
                .map(|e| e.unwrap().path())
                .filter(|p| p.to_string_lossy().contains(".run.gvsrom-old-"))
                .collect();
            assert_eq!(aside.len(), 1, "{:?}", tree(&dir));
            assert_complete_trajectory(&aside[0]);
            fs::rename(&aside[0], &run).unwrap();
        }
        // a killed run's staging is hidden and never taken for a result; clear it for the next round
        for e in fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            if name.starts_with(".run.gvsrom-staging-") {
                fs::remove_dir_all(&p).unwrap();
            } else if name == ".run.gvsrom-lock" {
                fs::remove_file(&p).unwrap();
            }
        }
        assert_eq!(
            fs::read_to_string(dir.join("own.txt")).unwrap(),
            "the user's data"
        );
    }
}

#[test]
fn statics_json_refuses_links_special_files_and_foreign_files() {
    let dir = sandbox("safety-json");
    let run = |target: &str, force: bool| {
        let mut args = vec!["statics", "six-tendon", "--json", target];
        if force {
            args.push("--force");
        }
        run_in(&dir, &args)
    };
    // a symlink stays a symlink, its target untouched
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink("own.txt", dir.join("link.json")).unwrap();
        let out = run("link.json", true);
        assert!(String::from_utf8_lossy(&out.stderr).contains("symbolic link"));
        assert!(fs::symlink_metadata(dir.join("link.json"))
            .unwrap()
            .file_type()
            .is_symlink());
        let out = run("/dev/null", true);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("special file"), "{err}");
    }
    // a file gvsrom did not write: refused even with --force
    fs::write(dir.join("mine.json"), "{\"a\": 1}").unwrap();
    let err = String::from_utf8_lossy(&run("mine.json", true).stderr).into_owned();
    assert!(err.contains("not a gvsrom output"), "{err}");
    assert_eq!(
        fs::read_to_string(dir.join("mine.json")).unwrap(),
        "{\"a\": 1}"
    );
    assert_eq!(
        fs::read_to_string(dir.join("own.txt")).unwrap(),
        "the user's data"
    );
    // a path ending in `/` names a directory: no file `newdir` is written for it
    let err = String::from_utf8_lossy(&run("newdir/", false).stderr).into_owned();
    assert!(
        err.contains("ends in `/`") && err.contains("--json"),
        "{err}"
    );
    assert!(!dir.join("newdir").exists());
    // its own earlier output: refused without --force, replaced with it
    assert!(run("sol.json", false).status.success());
    assert!(String::from_utf8_lossy(&run("sol.json", false).stderr).contains("pass --force"));
    assert!(run("sol.json", true).status.success());
    let v: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(dir.join("sol.json")).unwrap()).unwrap();
    assert_eq!(v["gvsrom"]["format"], "statics");
    assert_eq!(v["scenario"], "six-tendon");
    let hidden: Vec<_> = tree(&dir)
        .into_iter()
        .filter(|f| f.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
}

#[test]
fn an_unwritable_output_path_fails_before_the_computation() {
    let dir = sandbox("safety-early");
    // a path below a regular file can never be created
    let t0 = Instant::now();
    let out = run_in(
        &dir,
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "1000",
            "--out",
            "own.txt/run",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.starts_with("error: --out `own.txt/run`"), "{err}");
    assert!(
        t0.elapsed() < Duration::from_secs(10),
        "failed only after computing"
    );
    let out = run_in(
        &dir,
        &["statics", "six-tendon", "--json", "own.txt/sol.json"],
    );
    assert!(!String::from_utf8_lossy(&out.stdout).contains("solved"));
}

#[test]
fn run_lengths_and_steps_are_bounded_with_errors_naming_the_option() {
    expect_error(
        &["simulate", "six-tendon", "--duration", "1e308"],
        &["--duration", "samples (accepted <= 10000000)"],
    );
    expect_error(
        &[
            "simulate",
            "six-tendon",
            "--duration",
            "1",
            "--fixed-step",
            "1e-9",
        ],
        &["--fixed-step", "1.00e9 steps"],
    );
    expect_error(
        &[
            "simulate",
            "six-tendon",
            "--duration",
            "1e4",
            "--steps=-1,0,1e-9",
        ],
        &["--steps period", "input switches"],
    );
    let out = scratch("safety-huge");
    expect_error(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "99999",
            "--out",
            out.to_str().unwrap(),
        ],
        &["--out", "GB", "lower --duration or --sample-rate"],
    );
    assert!(!out.exists());
    // absurd tensions, from the option and from an input file, name the load
    expect_error(
        &[
            "simulate",
            "six-tendon",
            "--duration",
            "1",
            "--tension=1e300",
        ],
        &["].tension = 1e300 N", "elastic range"],
    );
    let csv = scratch("safety-huge.csv");
    fs::write(&csv, "0,-1e300\n").unwrap();
    expect_error(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "1",
            "--input",
            csv.to_str().unwrap(),
        ],
        &["tendons[0].tension", "elastic range"],
    );
}

#[test]
fn the_last_sample_is_at_duration_even_between_sample_periods() {
    let out = scratch("safety-last-sample");
    let o = gvsrom(&[
        "simulate",
        "six-tendon",
        "--duration",
        "1.5",
        "--sample-rate",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bytes = fs::read(out.join("t.npy")).unwrap();
    let hl = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let t: Vec<f64> = bytes[10 + hl..]
        .chunks(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(t, [0.0, 1.0, 1.5]);
}
