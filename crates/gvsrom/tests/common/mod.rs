//! Helpers shared by the command-line tests: run the binary (and expect success), scratch paths,
//! small single-tendon sweep datasets, and the check of a one-line user error; and a dynamics run
//! through the library into memory ([`run_to_buffer`]).
#![allow(dead_code)]

pub mod reseal;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The binary, with no periodic progress lines on its stderr (`GVSROM_PROGRESS_SECONDS`: a slow
/// machine must not change what a test reads there).
pub fn command() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_gvsrom"));
    c.env("GVSROM_PROGRESS_SECONDS", "1e9");
    c
}

pub fn gvsrom(args: &[&str]) -> Output {
    command()
        .args(args)
        .output()
        .expect("the gvsrom binary runs")
}

/// Runs `cmd` with its stderr a pipe whose reader is gone before the first line (a log reader
/// that exited, `2>&1 | head`): every write there fails with a broken pipe. Returns the output
/// (stdout read whole; stderr empty).
pub fn with_stderr_gone(cmd: &mut Command) -> Output {
    cmd.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = cmd.spawn().expect("the gvsrom binary runs");
    drop(child.stderr.take());
    child.wait_with_output().unwrap()
}

/// A test path as the `&str` of a command-line argument (scratch paths are UTF-8).
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs `gvsrom args`, expects success (panics with its stderr otherwise); returns stdout.
pub fn run_ok(args: &[&str]) -> String {
    run_ok_with_stderr(args).0
}

/// [`run_ok`] that also returns stderr (warnings): `(stdout, stderr)`.
pub fn run_ok_with_stderr(args: &[&str]) -> (String, String) {
    let out = gvsrom(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "gvsrom {args:?} failed: {stderr}");
    (String::from_utf8_lossy(&out.stdout).into_owned(), stderr)
}

/// The JSON document of the file at `path`.
pub fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Runs `gvsrom CMD ARGS --json FILE` with FILE the fresh scratch path `NAME.json`, expects
/// success; returns stdout and the JSON document.
pub fn run_json(cmd: &str, name: &str, args: &[&str]) -> (String, serde_json::Value) {
    let file = scratch(&format!("{name}.json"));
    let mut all = vec![cmd];
    all.extend_from_slice(args);
    all.extend(["--json", s(&file)]);
    let out = gvsrom(&all);
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "gvsrom {all:?} failed: {}{stdout}",
        String::from_utf8_lossy(&out.stderr)
    );
    (stdout, json(&file))
}

/// A JSON array of numbers.
pub fn f64s(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// Shape and values of a little-endian f64 `.npy` file (read with npyz, as numpy would).
pub fn npy(path: &Path) -> (Vec<usize>, Vec<f64>) {
    let bytes = std::fs::read(path).unwrap();
    let file = npyz::NpyFile::new(&bytes[..]).unwrap();
    let shape = file.shape().iter().map(|&d| d as usize).collect();
    (shape, file.into_vec::<f64>().unwrap())
}

/// `gvsrom dataset single-tendon --sweep tendons.0.tension=RANGE --samples SAMPLES --out DIR` at
/// the fresh scratch path `name` (`range` is `LO:HI` in N); returns DIR. A file that uses one
/// sweep in several tests caches it in its own `OnceLock`.
pub fn sweep_dataset(name: &str, range: &str, samples: usize) -> PathBuf {
    let dir = scratch(name);
    run_ok(&[
        "dataset",
        "single-tendon",
        "--sweep",
        &format!("tendons.0.tension={range}"),
        "--samples",
        &samples.to_string(),
        "--out",
        s(&dir),
    ]);
    dir
}

/// A scratch path unique to one test (files of all tests share one folder), cleared of what an
/// earlier run of the test left there: gvsrom refuses to replace outputs without `--force`.
pub fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("gvsrom-cli-tests");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    if path.is_dir() {
        std::fs::remove_dir_all(&path).unwrap();
    } else if path.exists() {
        std::fs::remove_file(&path).unwrap();
    }
    path
}

/// Runs `args`, expects a user error (exit code 1, one stderr line starting with `error:`, no
/// panic) containing every string of `needles`; returns the message.
pub fn expect_error(args: &[&str], needles: &[&str]) -> String {
    user_error(args, &gvsrom(args), needles)
}

/// Starts `gvsrom args` (stdin empty, stdout and stderr captured).
pub fn spawn(args: &[&str]) -> Child {
    command()
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the gvsrom binary runs")
}

/// Waits for `child` up to `limit` and returns its output; past the deadline kills it (SIGKILL)
/// and returns `None`.
pub fn wait_within(mut child: Child, limit: Duration) -> Option<Output> {
    let start = Instant::now();
    while child.try_wait().expect("waiting for gvsrom").is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    Some(child.wait_with_output().expect("gvsrom exits"))
}

/// [`expect_error`] with a deadline: a run still going after `limit` is killed and the test fails
/// (e.g. a reader waiting on a FIFO that no one writes), instead of hanging the test suite.
pub fn expect_error_within(limit: Duration, args: &[&str], needles: &[&str]) -> String {
    let out = wait_within(spawn(args), limit)
        .unwrap_or_else(|| panic!("gvsrom {args:?} did not finish within {limit:?} (killed)"));
    user_error(args, &out, needles)
}

/// Checks that `out` of `gvsrom args` is a user error (see [`expect_error`]); returns the message.
fn user_error(args: &[&str], out: &Output, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(
        out.status.code(),
        Some(1),
        "gvsrom {args:?}: expected exit code 1, got {:?}; stderr: {stderr}",
        out.status.code()
    );
    assert!(
        !stderr.contains("panicked") && !stderr.contains("internal error"),
        "gvsrom {args:?} panicked: {stderr}"
    );
    assert_eq!(
        stderr.trim_end().lines().count(),
        1,
        "gvsrom {args:?}: expected a one-line error, got: {stderr}"
    );
    assert!(stderr.starts_with("error: "), "{stderr}");
    for n in needles {
        assert!(
            stderr.contains(n),
            "gvsrom {args:?}: error lacks `{n}`: {stderr}"
        );
    }
    stderr
}

/// Replaces the file at `path` (if any) by a FIFO that no process writes: opening it for reading
/// waits forever.
pub fn fifo_at(path: &Path) {
    if path.symlink_metadata().is_ok() {
        std::fs::remove_file(path).unwrap();
    }
    let made = Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(made.success(), "mkfifo {path:?}");
}

/// A copy of a gvsrom directory output (flat) at the fresh scratch path `name`.
pub fn copy_dir(from: &std::path::Path, name: &str) -> PathBuf {
    let to = scratch(name);
    std::fs::create_dir_all(&to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
    to
}

/// Runs `gvsrom args`, sends it SIGINT after `after` and returns its output once it exits.
pub fn interrupted(args: &[&str], after: Duration) -> Output {
    let child = spawn(args);
    std::thread::sleep(after);
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(sent.success(), "SIGINT could not be sent");
    child.wait_with_output().expect("gvsrom exits")
}

/// The strain snapshots of a dataset as a matrix (rows: samples), read from its files.
pub fn snapshots(dir: &Path) -> nalgebra::DMatrix<f64> {
    let (shape, v) = npy(&dir.join("strain.npy"));
    let features: usize = shape[1..].iter().product();
    nalgebra::DMatrix::from_row_slice(shape[0], features, &v)
}

/// Asserts that the first `k` squared singular values a POD model at `model` stored
/// (`singular_values.npy`) are the `k` largest eigenvalues of the Gram matrix `gram` (a symmetric
/// eigensolver, not an SVD), within `rel` of the largest.
pub fn assert_sigma_squared_are_eigenvalues(
    model: &Path,
    gram: &nalgebra::DMatrix<f64>,
    k: usize,
    rel: f64,
) {
    let mut eig: Vec<f64> = gram.symmetric_eigenvalues().iter().copied().collect();
    eig.sort_by(|p, q| q.total_cmp(p));
    let sigma = npy(&model.join("singular_values.npy")).1;
    for i in 0..k {
        assert!(
            (sigma[i] * sigma[i] - eig[i]).abs() <= rel * eig[0],
            "σ_{i}² = {} against the eigenvalue {}",
            sigma[i] * sigma[i],
            eig[i]
        );
    }
}

/// A dynamics run of `built` through the library (`simulate::prepare`, `run_into`), its samples in
/// memory; the run must complete.
pub fn run_to_buffer(
    built: &gvsrom::Built,
    request: gvsrom::simulate::Request,
) -> gvsrom::simulate::TrajectoryBuffer {
    use gvsrom::simulate;
    let prepared = simulate::prepare(built, request).expect("the run is planned");
    let mut buffer = simulate::TrajectoryBuffer::new(built);
    let outcome = simulate::run_into(
        built,
        &prepared.plan,
        &prepared.opts.integrator,
        Some(&mut buffer),
        &mut |_| std::ops::ControlFlow::Continue(()),
    )
    .expect("the run starts");
    assert_eq!(outcome.ending, simulate::Ending::Complete);
    buffer
}

/// Every `.rs` file under `dir`, recursively (source-reading tests).
pub fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}
