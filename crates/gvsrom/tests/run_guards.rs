//! Guards of a run's inputs and of its end: tolerances outside their range are refused naming the
//! option, value and range; SIGTERM stops a slow simulation within a step, not at its next sample,
//! and the partial trajectory is written; a FIFO, directory or device given as a file input fails
//! at once saying what it is (opening a FIFO would block); an input signal whose first row comes
//! after the run's start is refused. Every run here has a deadline, so a regression fails instead
//! of hanging.

mod common;

use common::{expect_error_within, fifo_at, gvsrom, scratch, spawn, wait_within};
use std::path::Path;
use std::time::{Duration, Instant};

/// Runs `args` with a 5 s deadline and expects a one-line user error containing every string of
/// `needles` ([`expect_error_within`]); returns the message.
fn expect_error_fast(args: &[&str], needles: &[&str]) -> String {
    expect_error_within(Duration::from_secs(5), args, needles)
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn tolerances_outside_their_range_are_refused_naming_option_value_and_range() {
    let sim = |extra: &[&str]| {
        let mut args = vec!["simulate", "single-tendon", "--duration", "0.01"];
        args.extend_from_slice(extra);
        args.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    for (extra, needles) in [
        (
            vec!["--rtol", "1e-30"],
            vec!["`--rtol`", "1e-30", "[1e-12, 0.1]"],
        ),
        (
            vec!["--method", "sdirk", "--rtol", "1e-13"],
            vec!["`--rtol`", "1e-13", "[1e-12, 0.1]"],
        ),
        (vec!["--rtol", "1"], vec!["`--rtol`", "[1e-12, 0.1]"]),
        (vec!["--rtol", "nan"], vec!["`--rtol`", "NaN"]),
        (
            vec!["--atol", "1e-30"],
            vec!["`--atol`", "1e-30", "[1e-14, 1e-2]"],
        ),
        (
            vec!["--atol", "inf"],
            vec!["`--atol`", "inf", "[1e-14, 1e-2]"],
        ),
        (vec!["--atol", "0"], vec!["`--atol`", "[1e-14, 1e-2]"]),
        // looser than the coordinates themselves: the error test passes anything
        (
            vec!["--atol", "100"],
            vec!["`--atol`", "100", "[1e-14, 1e-2]"],
        ),
        (
            vec!["--rtol", "0.5"],
            vec!["`--rtol`", "0.5", "[1e-12, 0.1]"],
        ),
    ] {
        let args = sim(&extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        expect_error_fast(&args, &needles);
    }
    // the scenario's statics tolerances: below the residual's round-off or absurdly loose
    expect_error_fast(
        &["statics", "single-tendon", "--set", "solver.ftol=1e-30"],
        &["solver.ftol", "1e-30", "[1e-14, 1e-3]"],
    );
    expect_error_fast(
        &["statics", "single-tendon", "--set", "solver.ftol=0.5"],
        &["solver.ftol", "0.5", "[1e-14, 1e-3]"],
    );
    expect_error_fast(
        &["statics", "single-tendon", "--set", "solver.xtol=1e-300"],
        &["solver.xtol", "1e-300"],
    );
}

/// SDIRK4 at the tightest tolerances from rest, writing `dir`: thousands of steps per simulated
/// millisecond, so its sample at t = 1 s lies minutes away.
fn slow_simulation(dir: &Path) -> std::process::Child {
    spawn(&[
        "simulate",
        "single-tendon",
        "--duration",
        "10",
        "--sample-rate",
        "1",
        "--method",
        "sdirk",
        "--rtol",
        "1e-12",
        "--atol",
        "1e-14",
        "--out",
        path(dir),
    ])
}

#[test]
fn sigterm_stops_a_slow_simulation_within_a_step_and_writes_the_partial_trajectory() {
    // SDIRK4 at the tightest tolerances from rest: thousands of steps per simulated millisecond,
    // so the sample at t = 1 s lies minutes away; only a check at every step sees the signal
    let dir = scratch("sigterm-slow");
    let child = slow_simulation(&dir);
    std::thread::sleep(Duration::from_secs(1));
    let sent = Instant::now();
    // SAFETY: kill(2) on the pid of our own child, which has not been waited for yet
    assert_eq!(
        unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) },
        0
    );
    let out = wait_within(child, Duration::from_secs(4))
        .expect("gvsrom simulate did not stop within 4 s of SIGTERM");
    let status = out.status;
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!(
        "stopped {:.3} s after SIGTERM",
        sent.elapsed().as_secs_f64()
    );
    assert_eq!(status.code(), Some(128 + 15), "{stderr}");
    assert!(stderr.contains("interrupted by SIGTERM"), "{stderr}");
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("meta.json")).unwrap()).unwrap();
    assert_eq!(meta["complete"], false, "{meta}");
    assert_eq!(meta["reason"], "interrupted by SIGTERM", "{meta}");
    assert_eq!(meta["samples"], 1, "{meta}");
}

#[test]
fn a_fifo_or_directory_given_as_a_file_input_fails_at_once_saying_what_it_is() {
    // no writer ever opens it: reading it would block forever
    let pipe = scratch("input.fifo");
    fifo_at(&pipe);
    let pipe = path(&pipe);
    expect_error_fast(
        &["statics", pipe],
        &["SCENARIO", pipe, "a FIFO", "not a regular file"],
    );
    expect_error_fast(&["check", pipe], &["SCENARIO", "a FIFO"]);
    let sim = ["simulate", "single-tendon", "--duration", "0.01"];
    expect_error_fast(
        &[&sim[..], &["--input", pipe]].concat(),
        &["--input", pipe, "a FIFO"],
    );
    expect_error_fast(
        &[&sim[..], &["--load-schedule", pipe]].concat(),
        &["--load-schedule", "a FIFO"],
    );
    let dir = scratch("input-dir.csv");
    std::fs::create_dir_all(&dir).unwrap();
    expect_error_fast(
        &[&sim[..], &["--input", path(&dir)]].concat(),
        &["--input", "a directory", "not a regular file"],
    );
    expect_error_fast(
        &[&sim[..], &["--input", "/dev/zero"]].concat(),
        &["--input", "a character device"],
    );
    // a trajectory whose meta.json is a FIFO
    let traj = scratch("fifo-trajectory");
    std::fs::create_dir_all(&traj).unwrap();
    fifo_at(&traj.join("meta.json"));
    expect_error_fast(
        &["compare", path(&traj), path(&traj)],
        &["REFERENCE", "meta.json", "a FIFO"],
    );
}

#[test]
fn an_input_signal_starting_after_the_run_start_is_refused_with_its_first_time() {
    let late = scratch("late-start.csv");
    std::fs::write(&late, "t,u\n0.05,-1\n0.1,-2\n").unwrap();
    expect_error_fast(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "0.1",
            "--input",
            path(&late),
        ],
        &[
            "--input",
            "late-start.csv",
            "starts at t = 0.05 s",
            "start t = 0 s",
        ],
    );
    let schedule = scratch("late-schedule.csv");
    std::fs::write(&schedule, "0.02,1\n0.1,0\n").unwrap();
    expect_error_fast(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "0.1",
            "--load-schedule",
            path(&schedule),
        ],
        &[
            "--load-schedule",
            "late-schedule.csv",
            "starts at t = 0.02 s",
        ],
    );
    // a first row at t = 0 (or before) covers the start
    let ok = scratch("from-zero.csv");
    std::fs::write(&ok, "-1,-1\n0.05,-2\n").unwrap();
    let out = gvsrom(&[
        "simulate",
        "single-tendon",
        "--duration",
        "0.02",
        "--input",
        path(&ok),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_signal_sent_twice_at_once_is_one_request_and_the_partial_trajectory_is_written() {
    // `timeout` and batch schedulers signal the process and then its group: two SIGINTs within
    // microseconds. The second used to end the process at once, writing nothing.
    let dir = scratch("sigint-twice");
    let child = slow_simulation(&dir);
    std::thread::sleep(Duration::from_secs(1));
    for _ in 0..2 {
        // SAFETY: kill(2) on the pid of our own child, which has not been waited for yet
        assert_eq!(
            unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) },
            0
        );
        // apart enough for the first to be handled (two pending SIGINTs would merge into one)
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = wait_within(child, Duration::from_secs(4))
        .expect("gvsrom simulate did not stop within 4 s of SIGINT");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted by SIGINT"), "{stderr}");
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("meta.json")).unwrap()).unwrap();
    assert_eq!(meta["complete"], false, "{meta}");
}
