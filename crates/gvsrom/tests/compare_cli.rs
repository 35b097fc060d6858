//! `gvsrom compare` compares like with like: runs of another scenario, other physics, another
//! input or other sample times are refused with what differs (both values), unless
//! `--allow-different`, which prints the differences; a trajectory whose meta.json does not record
//! enough is undecided, not taken as equal; a zero or missing wall time prints "n/a", never a
//! non-finite number.

mod common;

use common::{expect_error, gvsrom, scratch};
use std::path::{Path, PathBuf};

/// `gvsrom simulate six-tendon --duration 0.1 --out <scratch name> EXTRA…` (a few hundredths of a
/// second of work); the trajectory directory.
fn simulate(name: &str, extra: &[&str]) -> PathBuf {
    simulate_for("0.1", name, extra)
}

/// [`simulate`] for `duration` seconds.
fn simulate_for(duration: &str, name: &str, extra: &[&str]) -> PathBuf {
    let dir = scratch(name);
    let mut args = vec![
        "simulate",
        "six-tendon",
        "--duration",
        duration,
        "--out",
        dir.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let out = gvsrom(&args);
    assert!(
        out.status.success(),
        "gvsrom {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `gvsrom compare REFERENCE RUN --allow-different`: its stdout (it must succeed).
fn compare_anyway(reference: &Path, run: &Path) -> String {
    let out = gvsrom(&["compare", path(reference), path(run), "--allow-different"]);
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// A copy of the trajectory `from` at scratch `name`, its meta.json changed by `edit`.
fn copy_with_meta(from: &Path, name: &str, edit: impl Fn(&mut serde_json::Value)) -> PathBuf {
    let to = scratch(name);
    std::fs::create_dir_all(&to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), to.join(entry.file_name())).unwrap();
    }
    let meta_path = to.join("meta.json");
    let mut meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&meta_path).unwrap()).unwrap();
    edit(&mut meta);
    std::fs::write(&meta_path, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
    // as written so (a writer's bug or an older build): the hashes match the edited metadata
    common::reseal::reseal(&to);
    to
}

#[test]
fn an_edited_trajectory_is_refused_naming_the_file() {
    let reference = simulate("cmp-edit-ref", &[]);
    let run = copy_with_meta(&reference, "cmp-edit-run", |_| {});
    let q = run.join("q.npy");
    let mut bytes = std::fs::read(&q).unwrap();
    let n = bytes.len();
    bytes[n - 2] ^= 0x10;
    std::fs::write(&q, &bytes).unwrap();
    expect_error(
        &["compare", path(&reference), path(&run)],
        &["q.npy", "differs from the hash", "edited trajectory"],
    );
}

#[test]
fn runs_with_another_input_physics_or_duration_are_refused_naming_what_differs() {
    let reference = simulate("cmp-ref", &[]);
    // the preset pulls tendon 0 at -10 N
    let other_tension = simulate("cmp-tension", &["--tension=-5,0,0,0,0,0"]);
    let e = expect_error(
        &["compare", path(&reference), path(&other_tension)],
        &[
            "RUN",
            "different inputs",
            "`tendons[0].tension` = -10.0 in REFERENCE, -5.0 in RUN",
            "--allow-different",
        ],
    );
    assert!(!e.contains("tendons[1]"), "only what differs: {e}");
    let other_signal = simulate("cmp-steps", &["--steps=-5,0,0.05"]);
    expect_error(
        &["compare", path(&reference), path(&other_signal)],
        &["`input.signal` = \"constant\" in REFERENCE, \"steps\" in RUN"],
    );
    let other_physics = simulate("cmp-damping", &["--set", "material.damping=5000"]);
    expect_error(
        &["compare", path(&reference), path(&other_physics)],
        &[
            "different physics",
            "`material.damping` = 10000.0 in REFERENCE, 5000.0 in RUN",
        ],
    );
    let longer = simulate_for("0.2", "cmp-longer", &[]);
    expect_error(
        &["compare", path(&reference), path(&longer)],
        &[
            "different sample times",
            "`--duration` = 0.1 s in REFERENCE, 0.2 s in RUN",
        ],
    );
    // the same run again is compared as before
    let again = simulate("cmp-again", &[]);
    let out = gvsrom(&["compare", path(&reference), path(&again)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("tip error  mean 0.000 %"), "{stdout}");
    assert!(!stdout.contains("differ"), "{stdout}");
    // --allow-different compares and says how the runs differ
    let stdout = compare_anyway(&reference, &other_tension);
    assert!(
        stdout.contains("differ     the runs have different inputs: `tendons[0].tension`"),
        "{stdout}"
    );
    assert!(stdout.contains("tip error"), "{stdout}");
}

#[test]
fn runs_that_start_apart_are_said_to_with_the_offset() {
    // the preset's equilibrium (tendon 0 at −10 N, under gravity) against the straight rod at rest
    let from_rest = simulate("cmp-start-rest", &[]);
    let settled = simulate("cmp-start-eq", &["--from-equilibrium"]);
    let stdout = compare_anyway(&from_rest, &settled);
    let tip = |text: &str, key: &str| -> f64 {
        let line = text.lines().find(|l| l.starts_with("tip error")).unwrap();
        let after = &line[line.find(key).unwrap() + key.len()..];
        after.split_whitespace().next().unwrap().parse().unwrap()
    };
    let note = stdout
        .lines()
        .find(|l| l.starts_with("note       the runs start "))
        .unwrap_or_else(|| panic!("no start note: {stdout}"));
    // the offset printed is the tip error at t = 0, which the max includes
    let start: f64 = note["note       the runs start ".len()..]
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        start > 10.0,
        "the equilibrium sags far from the straight rod: {note}"
    );
    assert!(start <= tip(&stdout, "max ") + 1e-3, "{stdout}");
    assert!(
        note.contains("with --from-equilibrium each starts at its own model's equilibrium"),
        "{note}"
    );
    // both from their equilibria: the advice is not to start them so, but what separates them
    let stiffer = simulate(
        "cmp-start-eq-stiffer",
        &["--from-equilibrium", "--set", "material.youngs_modulus=2e6"],
    );
    let both = compare_anyway(&settled, &stiffer);
    let note = (both.lines())
        .find(|l| l.starts_with("note       the runs start "))
        .unwrap_or_else(|| panic!("no start note: {both}"));
    assert!(
        note.contains("each run starts at its own model's equilibrium")
            && !note.contains("with --from-equilibrium"),
        "{note}"
    );
    // the JSON report holds it too
    let json = scratch("cmp-start.json");
    let out = gvsrom(&[
        "compare",
        path(&from_rest),
        path(&settled),
        "--allow-different",
        "--json",
        path(&json),
    ]);
    assert!(out.status.success());
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let tip_start = report["comparison"]["tip_start"].as_f64().unwrap();
    assert!(
        (tip_start - start).abs() < 1e-3,
        "{tip_start} against {start}"
    );
    // runs from one state: no note
    let again = simulate("cmp-start-again", &[]);
    let stdout = compare_anyway(&from_rest, &again);
    assert!(!stdout.contains("the runs start"), "{stdout}");
}

#[test]
fn a_zero_or_missing_wall_time_prints_n_a_never_inf() {
    let reference = simulate("cmp-wall-ref", &[]);
    let zero = copy_with_meta(&reference, "cmp-wall-zero", |m| {
        m["wall_time_s"] = serde_json::json!(0.0)
    });
    let missing = copy_with_meta(&reference, "cmp-wall-missing", |m| {
        m.as_object_mut().unwrap().remove("wall_time_s");
    });
    for (a, b) in [
        (&reference, &zero),
        (&zero, &reference),
        (&reference, &missing),
        (&zero, &zero),
    ] {
        let out = gvsrom(&["compare", path(a), path(b)]);
        let stdout = String::from_utf8_lossy(&out.stdout).to_string();
        assert!(
            out.status.success(),
            "{stdout}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(stdout.contains("n/a"), "{stdout}");
        // no word reads as inf or NaN ("inf× slower" before)
        let non_finite = stdout
            .split_whitespace()
            .map(|w| w.trim_matches(|c: char| "×%,;:()".contains(c)))
            .find(|w| w.parse::<f64>().is_ok_and(|v| !v.is_finite()));
        assert_eq!(non_finite, None, "a non-finite number printed: {stdout}");
    }
}

#[test]
fn a_trajectory_that_does_not_record_its_input_is_undecided_not_equal() {
    let reference = simulate("cmp-old-ref", &[]);
    // as written before gvsrom recorded the input and physics
    let old = copy_with_meta(&reference, "cmp-old", |m| {
        let m = m.as_object_mut().unwrap();
        m.remove("input");
        m.remove("physics");
    });
    expect_error(
        &["compare", path(&reference), path(&old)],
        &[
            "cannot tell whether the inputs are the same",
            "RUN's meta.json",
            "does not record",
            "--allow-different",
        ],
    );
    let stdout = compare_anyway(&reference, &old);
    assert!(
        stdout.contains("unknown    whether the physics are the same"),
        "{stdout}"
    );
    assert!(stdout.contains("tip error  mean 0.000 %"), "{stdout}");
}

#[test]
fn a_trajectory_without_or_with_a_damaged_reference_strain_is_read_as_written() {
    let reference = simulate("cmp-xistar-ref", &[]);
    // written before ξ* was recorded: the straight rod, the same run
    let old = copy_with_meta(&reference, "cmp-xistar-old", |meta| {
        meta["gvsrom"]["files"]
            .as_array_mut()
            .unwrap()
            .retain(|f| f != "strain_reference.npy");
    });
    std::fs::remove_file(old.join("strain_reference.npy")).unwrap();
    let out = gvsrom(&["compare", path(&reference), path(&old)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // a non-finite entry (resealed, as a writer's bug would leave it) is refused naming the file
    let bad = copy_with_meta(&reference, "cmp-xistar-nan", |_| {});
    let f = bad.join("strain_reference.npy");
    let mut bytes = std::fs::read(&f).unwrap();
    let n = bytes.len();
    bytes[n - 8..].copy_from_slice(&f64::NAN.to_le_bytes());
    std::fs::write(&f, &bytes).unwrap();
    common::reseal::reseal(&bad);
    expect_error(
        &["compare", path(&reference), path(&bad)],
        &["strain_reference.npy", "not a finite number"],
    );
}

/// A run written before gvsrom recorded content hashes is compared, with a warning that its files
/// could not be checked (an edited tip of such a run had been compared silently).
#[test]
fn a_run_without_content_hashes_is_compared_with_a_warning() {
    let reference = simulate("cmp-unhashed-ref", &[]);
    let old = scratch("cmp-unhashed-run");
    std::fs::create_dir_all(&old).unwrap();
    for entry in std::fs::read_dir(&reference).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), old.join(entry.file_name())).unwrap();
    }
    let meta_path = old.join("meta.json");
    let mut meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&meta_path).unwrap()).unwrap();
    let manifest = meta["gvsrom"].as_object_mut().unwrap();
    manifest.remove("sha256");
    manifest.remove("meta_sha256");
    std::fs::write(&meta_path, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
    let (stdout, stderr) = common::run_ok_with_stderr(&[
        "compare",
        reference.to_str().unwrap(),
        old.to_str().unwrap(),
    ]);
    assert!(stdout.contains("tip error"), "{stdout}");
    assert!(
        stderr.contains("warning: RUN `")
            && stderr.contains("written before gvsrom recorded content hashes"),
        "{stderr}"
    );
    // the hashed runs compare without one
    let (_, quiet) = common::run_ok_with_stderr(&[
        "compare",
        reference.to_str().unwrap(),
        reference.to_str().unwrap(),
    ]);
    assert!(!quiet.contains("warning"), "{quiet}");
}
