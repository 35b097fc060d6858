//! `gvsrom plot` end to end (issue 22): figures of a statics result, a trajectory (with and without
//! per-sample centrelines), a dataset, a POD model, an autoencoder, a linearization and modes. Every SVG must be well-formed
//! XML, every PNG must decode to a picture of several distinct colours, the rod animation must be a
//! GIF of more than one frame; bad inputs are one-line errors naming the file.
//!
//! The inputs are built once per run of this file with the CLI itself, as small as the commands
//! allow ([`OnceLock`]).

mod common;

use common::reseal::{reseal, reseal_json};
use common::{copy_dir, expect_error, json, run_ok, s, scratch, sweep_dataset};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// `statics single-tendon --tension=-4 --json F`.
fn statics_json() -> &'static Path {
    static F: OnceLock<PathBuf> = OnceLock::new();
    F.get_or_init(|| {
        let f = scratch("plot-statics.json");
        run_ok(&["statics", "single-tendon", "--tension=-4", "--json", s(&f)]);
        f
    })
}

/// A 0.2 s single-tendon trajectory under random steps (21 samples), as `simulate` writes it.
fn trajectory() -> &'static Path {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| {
        let d = scratch("plot-traj");
        run_ok(&[
            "simulate",
            "single-tendon",
            "--duration",
            "0.2",
            "--steps=-6,0,0.1",
            "--out",
            s(&d),
        ]);
        d
    })
}

/// [`trajectory`] as an older gvsrom wrote it, without `centerline.npy` and `centerline_x`
/// (resealed, so only the missing centreline differs).
fn trajectory_without_centerlines() -> &'static Path {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| {
        let d = copy_dir(trajectory(), "plot-traj-old");
        let mut meta = json(&d.join("meta.json"));
        std::fs::remove_file(d.join("centerline.npy")).unwrap();
        meta.as_object_mut().unwrap().remove("centerline_x");
        meta["gvsrom"]["files"]
            .as_array_mut()
            .unwrap()
            .retain(|f| f != "centerline.npy");
        std::fs::write(
            d.join("meta.json"),
            serde_json::to_string_pretty(&meta).unwrap(),
        )
        .unwrap();
        reseal(&d);
        d
    })
}

/// A 12-sample tension sweep.
fn dataset() -> &'static Path {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| sweep_dataset("plot-ds", "-6:3", 12))
}

fn pod() -> &'static Path {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| {
        let d = scratch("plot-pod");
        run_ok(&["pod", s(dataset()), "--modes", "2", "--out", s(&d)]);
        d
    })
}

fn autoencoder() -> &'static Path {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| {
        let d = scratch("plot-ae");
        run_ok(&[
            "train",
            s(dataset()),
            "--hidden-layers",
            "3",
            "--epochs",
            "20",
            "--lbfgs-iterations",
            "0",
            "--out",
            s(&d),
        ]);
        d
    })
}

/// Runs `gvsrom plot INPUT --out DIR extra…` and returns DIR and stdout.
fn plot(input: &Path, name: &str, extra: &[&str]) -> (PathBuf, String) {
    let out = scratch(name);
    let args = [&["plot", s(input), "--out", s(&out)][..], extra].concat();
    let stdout = run_ok(&args);
    (out, stdout)
}

/// Distinct colours of a decoded image.
fn colours(img: &image::RgbaImage) -> usize {
    img.pixels().map(|p| p.0).collect::<HashSet<_>>().len()
}

/// Checks every figure in `dir`: the listed ones are there (and printed), SVGs parse as XML with
/// text, PNGs decode to pictures of several colours, GIFs decode to several frames.
fn check_figures(dir: &Path, stdout: &str, expected: &[&str]) {
    let meta = json(&dir.join("meta.json"));
    assert_eq!(meta["gvsrom"]["format"], "figures");
    let files: Vec<String> = meta["gvsrom"]["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap().to_string())
        .collect();
    for e in expected {
        assert!(files.iter().any(|f| f == e), "{e} missing from {files:?}");
    }
    for f in &files {
        assert!(stdout.contains(f.as_str()), "stdout lacks {f}: {stdout}");
        let path = dir.join(f);
        let bytes = std::fs::read(&path).unwrap();
        match f.rsplit('.').next() {
            Some("svg") => {
                let text = String::from_utf8(bytes).unwrap();
                let doc = roxmltree::Document::parse(&text)
                    .unwrap_or_else(|e| panic!("{f} is not well-formed XML: {e}"));
                assert_eq!(doc.root_element().tag_name().name(), "svg", "{f}");
                let texts = doc
                    .descendants()
                    .filter(|n| n.tag_name().name() == "text")
                    .count();
                assert!(texts >= 5, "{f}: only {texts} text elements");
            }
            Some("png") => {
                let img = image::load_from_memory(&bytes)
                    .unwrap_or_else(|e| panic!("{f} does not decode: {e}"))
                    .to_rgba8();
                assert!(img.width() >= 600 && img.height() >= 400, "{f}");
                let n = colours(&img);
                assert!(n >= 8, "{f}: only {n} distinct colours (blank?)");
            }
            Some("gif") => {
                use image::AnimationDecoder;
                let dec = image::codecs::gif::GifDecoder::new(&bytes[..]).unwrap();
                let frames = dec.into_frames().collect_frames().unwrap();
                assert!(frames.len() > 1, "{f}: {} frame(s)", frames.len());
                assert!(colours(frames[0].buffer()) >= 8, "{f}: blank first frame");
                let (a, b) = (frames[0].buffer(), frames[frames.len() - 1].buffer());
                assert_ne!(a, b, "{f}: the first and last frames are the same");
            }
            other => panic!("unexpected figure file {f} ({other:?})"),
        }
    }
}

/// Both formats of each stem.
fn both(stems: &[&str]) -> Vec<String> {
    stems
        .iter()
        .flat_map(|s| [format!("{s}.svg"), format!("{s}.png")])
        .collect()
}

fn refs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

#[test]
fn statics_result_gives_rod_views_and_strain_profiles() {
    let (dir, stdout) = plot(statics_json(), "plot-out-statics", &[]);
    let expected = both(&["rod_3d", "rod_side", "strain"]);
    check_figures(&dir, &stdout, &refs(&expected));
    assert!(stdout.contains("statics result"), "{stdout}");
    // units on the strain panels
    let svg = std::fs::read_to_string(dir.join("strain.svg")).unwrap();
    assert!(
        svg.contains("[1/m]") && svg.contains("[–]"),
        "strain.svg lacks units"
    );
    // the tendon is drawn beside the centreline
    for view in ["rod_side.svg", "rod_3d.svg"] {
        let svg = std::fs::read_to_string(dir.join(view)).unwrap();
        assert!(svg.contains("tendon 0"), "{view} lacks the tendon");
    }
}

#[test]
fn linearization_gives_poles_and_a_static_gain_panel_per_output_point() {
    let f = scratch("plot-lin.json");
    run_ok(&[
        "linearize",
        "six-tendon",
        "--tension=-5,0,0,0,0,0",
        "--output-at",
        "0.3,0.6",
        "--json",
        s(&f),
    ]);
    let (dir, stdout) = plot(&f, "plot-out-lin", &[]);
    check_figures(&dir, &stdout, &refs(&both(&["poles", "static_gain"])));
    assert!(stdout.contains("linearization"), "{stdout}");
    let gain = std::fs::read_to_string(dir.join("static_gain.svg")).unwrap();
    for text in ["X = 0.3 m", "X = 0.6 m", "[mm/N]", "world z"] {
        assert!(gain.contains(text), "static_gain.svg lacks {text}");
    }
    assert!(!gain.contains("unstable"));
    let poles = std::fs::read_to_string(dir.join("poles.svg")).unwrap();
    assert!(poles.contains("damping ratio") && poles.contains("stable"));
    assert!(
        !poles.contains("unstable"),
        "the arm's equilibrium is stable"
    );
    // the arm standing against gravity (soft enough to buckle): its unstable poles apart, its gain
    // said to settle nowhere
    let up = scratch("plot-lin-up.json");
    run_ok(&[
        "linearize",
        "six-tendon-hanging",
        "--set",
        "loads.gravity=[0.0,0.0,9.81]",
        "--set",
        "material.youngs_modulus=1e5",
        "--tension",
        "0",
        "--json",
        s(&up),
    ]);
    assert!(json(&up)["unstable_poles"].as_u64().unwrap() > 0);
    let (dir, _) = plot(&up, "plot-out-lin-up", &["--format", "svg"]);
    let poles = std::fs::read_to_string(dir.join("poles.svg")).unwrap();
    assert!(poles.contains("unstable (Re λ &gt; 0)") || poles.contains("unstable (Re λ > 0)"));
    let gain = std::fs::read_to_string(dir.join("static_gain.svg")).unwrap();
    assert!(gain.contains("an unstable equilibrium"));
    // an undamped arm: its poles on the imaginary axis up to rounding (ζ ≈ ±1e-15) are stable,
    // as linearize counts them
    let undamped = scratch("plot-lin-undamped.json");
    run_ok(&[
        "linearize",
        "single-tendon",
        "--set",
        "material.damping=0.0",
        "--json",
        s(&undamped),
    ]);
    assert_eq!(json(&undamped)["unstable_poles"].as_u64(), Some(0));
    let (dir, _) = plot(&undamped, "plot-out-lin-undamped", &["--format", "svg"]);
    let poles = std::fs::read_to_string(dir.join("poles.svg")).unwrap();
    assert!(!poles.contains("unstable"), "rounding drawn as instability");
    // results with nothing to draw or of inconsistent sizes: one-line errors naming the file
    for (name, body, needle) in [
        (
            "plot-lin-nopoles.json",
            r#""n_actuators": 0, "poles": []"#,
            "no pole with a frequency above 0 Hz",
        ),
        (
            "plot-lin-nooutputs.json",
            r#""n_actuators": 1, "poles": [], "outputs": [], "static_gain": []"#,
            "outputs is empty",
        ),
        (
            "plot-lin-rows.json",
            r#""n_actuators": 2, "poles": [], "static_gain": [[1, 2], [1], [3, 4]]"#,
            "static_gain row 1 has 1 values; expected 2",
        ),
    ] {
        let f = scratch(name);
        let text = format!(r#"{{"gvsrom": {{"format": "linearize"}}, "scenario": "x", {body}}}"#);
        std::fs::write(&f, text).unwrap();
        let out = scratch(&format!("{name}-figs"));
        expect_error(&["plot", s(&f), "--out", s(&out)], &[s(&f), needle]);
    }
}

#[test]
fn modes_give_the_spectrum_and_the_shapes_in_the_views_they_move_in() {
    // the six-tendon arm moves in 3-D: both side views; the planar IV-A arm only in x–z
    for (scenario, views) in [
        ("six-tendon", &["(x–z)", "(x–y)"][..]),
        ("single-tendon", &["(x–z)"][..]),
    ] {
        let f = scratch(&format!("plot-modes-{scenario}.json"));
        run_ok(&["modes", scenario, "--count", "3", "--json", s(&f)]);
        let (dir, stdout) = plot(&f, &format!("plot-out-modes-{scenario}"), &[]);
        check_figures(&dir, &stdout, &refs(&both(&["frequencies", "mode_shapes"])));
        let shapes = std::fs::read_to_string(dir.join("mode_shapes.svg")).unwrap();
        for v in views {
            assert!(
                shapes.contains("mode 3: ") && shapes.contains(v),
                "{scenario}: {v}"
            );
        }
        if views.len() == 1 {
            assert!(
                !shapes.contains("(x–y)"),
                "{scenario}: a view across which nothing moves"
            );
        }
    }
}

#[test]
fn trajectory_with_centerlines_gives_tip_strain_rod_figures_and_animation() {
    let (dir, stdout) = plot(trajectory(), "plot-out-traj-cl", &[]);
    let mut expected = both(&[
        "tip_path_3d",
        "tip_path_side",
        "tip_position",
        "strain_time",
        "tensions",
        "tendon_lengths",
        "rod_3d",
        "rod_side",
    ]);
    expected.push("rod_animation.gif".into());
    check_figures(&dir, &stdout, &refs(&expected));
    // the random steps every 0.1 s, held between samples
    let svg = std::fs::read_to_string(dir.join("tensions.svg")).unwrap();
    assert!(
        svg.contains("Tendon tensions") && svg.contains("tension u [N]"),
        "tensions.svg"
    );
    // the tendon's pull-in from its rest length (`meta.json`), one line per tendon
    let svg = std::fs::read_to_string(dir.join("tendon_lengths.svg")).unwrap();
    assert!(
        svg.contains("Tendons pulled in") && svg.contains("rest length − length [mm]"),
        "tendon_lengths.svg"
    );
    let gif = std::fs::metadata(dir.join("rod_animation.gif"))
        .unwrap()
        .len();
    assert!(gif < 3_000_000, "rod_animation.gif is {gif} bytes");
}

#[test]
fn trajectory_without_centerlines_draws_the_tip_and_says_why_not_the_rod() {
    let (dir, stdout) = plot(trajectory_without_centerlines(), "plot-out-traj", &[]);
    let expected = both(&[
        "tip_path_3d",
        "tip_path_side",
        "tip_position",
        "strain_time",
    ]);
    check_figures(&dir, &stdout, &refs(&expected));
    assert!(
        stdout.contains("note:") && stdout.contains("centerline.npy"),
        "{stdout}"
    );
    assert!(!dir.join("rod_animation.gif").exists());
}

#[test]
fn a_precurved_rod_at_rest_is_drawn_against_its_reference_strain() {
    // the single-tendon arm pre-curved by 3 1/m in bend-y, no gravity, no tension: it rests on its
    // arc, and its strain deviations ξ − ξ* are zero (measured from the straight rod they would be
    // 3 1/m everywhere); the outputs record ξ*
    let set = [
        "--set",
        "divisions.0.reference_strain=[0, 3, 0, 1, 0, 0]",
        "--set",
        "loads.gravity=[0, 0, 0]",
        "--tension=0",
    ];
    let traj = scratch("plot-precurved-traj");
    let args = [
        &["simulate", "single-tendon", "--duration", "0.05"][..],
        &set,
        &["--out", s(&traj)],
    ]
    .concat();
    run_ok(&args);
    let (shape, xi_star) = common::npy(&traj.join("strain_reference.npy"));
    assert_eq!(shape[1], 6);
    for row in xi_star.chunks(6) {
        assert_eq!(row, [0.0, 3.0, 0.0, 1.0, 0.0, 0.0]);
    }
    let (_, stdout) = plot(&traj, "plot-out-precurved-traj", &[]);
    assert!(
        stdout.contains("strain_time: the rod stays at its reference strain"),
        "{stdout}"
    );
    let statics = scratch("plot-precurved.json");
    let args = [
        &["statics", "single-tendon"][..],
        &set,
        &["--json", s(&statics)],
    ]
    .concat();
    run_ok(&args);
    let doc = json(&statics);
    let rows = doc["strain_reference"]
        .as_array()
        .expect("strain_reference");
    assert_eq!(rows.len(), doc["strain"].as_array().unwrap().len());
    assert!(rows
        .iter()
        .all(|r| *r == serde_json::json!([0.0, 3.0, 0.0, 1.0, 0.0, 0.0])));
    // compare finds no difference of reference strains between a run and itself
    let stdout = run_ok(&["compare", s(&traj), s(&traj)]);
    assert!(!stdout.contains("reference strains"), "{stdout}");
}

#[test]
fn dataset_gives_input_coverage_strain_envelope_and_tip_workspace() {
    let (dir, stdout) = plot(dataset(), "plot-out-ds", &[]);
    let expected = both(&["input_coverage", "strain_envelope", "tip_workspace"]);
    check_figures(&dir, &stdout, &refs(&expected));
}

#[test]
fn pod_model_gives_spectrum_and_latent_coordinates() {
    let (dir, stdout) = plot(pod(), "plot-out-pod", &[]);
    let expected = both(&["pod_spectrum", "latent"]);
    check_figures(&dir, &stdout, &refs(&expected));
}

#[test]
fn autoencoder_gives_training_curves_and_latent_coordinates() {
    let (dir, stdout) = plot(autoencoder(), "plot-out-ae", &[]);
    let expected = both(&["training_curves", "latent"]);
    check_figures(&dir, &stdout, &refs(&expected));
}

#[test]
fn format_option_selects_the_image_formats() {
    let (dir, stdout) = plot(statics_json(), "plot-out-svg", &["--format", "svg"]);
    check_figures(&dir, &stdout, &["rod_3d.svg", "strain.svg"]);
    assert!(!dir.join("rod_3d.png").exists());
    let (dir, stdout) = plot(pod(), "plot-out-png", &["--format", "png"]);
    check_figures(&dir, &stdout, &["pod_spectrum.png"]);
    assert!(!dir.join("pod_spectrum.svg").exists());
}

#[test]
fn an_existing_output_is_replaced_only_with_force() {
    let (dir, _) = plot(statics_json(), "plot-out-force", &["--format", "svg"]);
    let args = [
        "plot",
        s(statics_json()),
        "--out",
        s(&dir),
        "--format",
        "png",
    ];
    expect_error(&args, &["--out", "--force"]);
    run_ok(&[&args[..], &["--force"]].concat());
    assert!(dir.join("rod_3d.png").exists() && !dir.join("rod_3d.svg").exists());
}

#[test]
fn bad_inputs_are_one_line_errors_naming_the_file() {
    let out = scratch("plot-out-bad");
    // missing
    let missing = scratch("plot-no-such-input");
    expect_error(
        &["plot", s(&missing), "--out", s(&out)],
        &["plot-no-such-input", "no such file"],
    );
    // a JSON file that is not a gvsrom output
    let foreign = scratch("plot-foreign.json");
    std::fs::write(&foreign, "{\"a\": 1}").unwrap();
    expect_error(
        &["plot", s(&foreign), "--out", s(&out)],
        &["plot-foreign.json", "accepted", "statics --json"],
    );
    // a binary file
    let binary = scratch("plot-binary.bin");
    std::fs::write(&binary, [0xff, 0xfe, 0x00, 0x01]).unwrap();
    expect_error(
        &["plot", s(&binary), "--out", s(&out)],
        &["plot-binary.bin"],
    );
    // a directory that is not a gvsrom output
    let plain = scratch("plot-plain-dir");
    std::fs::create_dir_all(&plain).unwrap();
    expect_error(
        &["plot", s(&plain), "--out", s(&out)],
        &["plot-plain-dir", "meta.json", "accepted"],
    );
    // a gvsrom output without figures: a figures directory itself
    let (figs, _) = plot(statics_json(), "plot-out-figs", &["--format", "svg"]);
    expect_error(
        &["plot", s(&figs), "--out", s(&out)],
        &["plot-out-figs", "\"figures\"", "accepted"],
    );
    // a statics result without its centreline
    let empty = scratch("plot-empty-statics.json");
    let mut v = json(statics_json());
    v["centerline"] = serde_json::json!([]);
    v["centerline_x"] = serde_json::json!([]);
    reseal_json(&mut v);
    std::fs::write(&empty, v.to_string()).unwrap();
    expect_error(
        &["plot", s(&empty), "--out", s(&out)],
        &["plot-empty-statics.json", "centerline"],
    );
    // a statics result edited after it was written: a 1 km rod drawn as if computed
    let edited = scratch("plot-edited-statics.json");
    let mut v = json(statics_json());
    v["tip_position"] = serde_json::json!([1e3, 0.0, 0.0]);
    std::fs::write(&edited, v.to_string()).unwrap();
    expect_error(
        &["plot", s(&edited), "--out", s(&out)],
        &["plot-edited-statics.json", "meta_sha256", "edited"],
    );
    // a centerline.npy of the wrong shape
    let bad = copy_dir(trajectory(), "plot-traj-bad-cl");
    let mut meta = json(&bad.join("meta.json"));
    meta["centerline_x"] = serde_json::json!([0.0, 0.25]);
    std::fs::write(bad.join("meta.json"), meta.to_string()).unwrap();
    reseal(&bad);
    expect_error(
        &["plot", s(&bad), "--out", s(&out)],
        &["centerline.npy", "shape"],
    );
    assert!(!out.exists(), "a failed plot wrote its output");
}

/// Writes the figures of every kind to /tmp/plot-samples/KIND/ for a person to look at, with the
/// first, middle and last frames of the rod animation as PNGs (`cargo test --test plot_cli --
/// --ignored`).
#[test]
#[ignore]
fn write_samples() {
    use image::AnimationDecoder;
    let root = Path::new("/tmp/plot-samples");
    let inputs: [(&str, &Path); 5] = [
        ("statics", statics_json()),
        ("trajectory", trajectory()),
        ("dataset", dataset()),
        ("pod", pod()),
        ("autoencoder", autoencoder()),
    ];
    for (kind, input) in inputs {
        let (dir, _) = plot(input, &format!("plot-samples-{kind}"), &[]);
        let to = root.join(kind);
        std::fs::create_dir_all(&to).unwrap();
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_str().unwrap().to_string();
            if name.ends_with(".png") || name.ends_with(".gif") {
                std::fs::copy(&p, to.join(&name)).unwrap();
            }
            if name.ends_with(".gif") {
                let bytes = std::fs::read(&p).unwrap();
                let dec = image::codecs::gif::GifDecoder::new(&bytes[..]).unwrap();
                let frames = dec.into_frames().collect_frames().unwrap();
                for (tag, k) in [
                    ("first", 0),
                    ("middle", frames.len() / 2),
                    ("last", frames.len() - 1),
                ] {
                    frames[k]
                        .buffer()
                        .save(to.join(format!("{name}.{tag}.png")))
                        .unwrap();
                }
            }
        }
    }
}

/// Rewrites the `.npy` file `f` (f64 data) with every value scaled by `k`: the same header, other
/// numbers (another process writing the file).
fn scale_npy(f: &Path, k: f64) {
    let mut bytes = std::fs::read(f).unwrap();
    let n = bytes.len();
    let shape = npyz::NpyFile::new(&bytes[..]).unwrap().shape().to_vec();
    let v = shape.iter().product::<u64>() as usize;
    for c in bytes[n - 8 * v..].chunks_exact_mut(8) {
        let x = f64::from_le_bytes(c.try_into().unwrap());
        c.copy_from_slice(&(k * x).to_le_bytes());
    }
    std::fs::write(f, bytes).unwrap();
}

#[test]
fn figures_draw_the_files_as_they_were_checked_not_a_second_read() {
    // a trajectory's centrelines are the ones its loader read and checked: a centerline.npy
    // rewritten afterwards (another process writing the directory) is not what is drawn
    let d = copy_dir(trajectory(), "plot-reread-traj");
    let tr = gvsrom::compare::Trajectory::load(&d, "INPUT").unwrap();
    let loaded = tr.centerline.clone().unwrap();
    scale_npy(&d.join("centerline.npy"), 10.0);
    let c = gvsrom::figures::trajectory::centerlines(&tr)
        .unwrap()
        .unwrap();
    let drawn: Vec<f64> = c.shapes.iter().flatten().flatten().copied().collect();
    assert_eq!(drawn, loaded);
    // a model's curves are read through the hashes it was loaded with: a train_loss.npy rewritten
    // after the load is refused, naming the file, not drawn
    let m = copy_dir(autoencoder(), "plot-reread-ae");
    let model = gvsrom::reduced_model::ReducedModel::load(&m).unwrap();
    let curve = gvsrom::figures::model::curve(&model, "train_loss.npy")
        .unwrap()
        .unwrap();
    assert!(!curve.is_empty());
    scale_npy(&m.join("train_loss.npy"), 2.0);
    let e = gvsrom::figures::model::curve(&model, "train_loss.npy")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("train_loss.npy") && e.contains("changed while"),
        "{e}"
    );
    // a curve the manifest does not list is not read at all
    assert_eq!(
        gvsrom::figures::model::curve(&model, "no_such.npy").unwrap(),
        None
    );
}

#[test]
fn figures_record_how_they_were_made_and_what_they_drew_by_its_hashes() {
    use sha2::{Digest, Sha256};
    // a directory: the hashes its manifest recorded when `plot` read it
    let (out, _) = plot(dataset(), "fig-prov-dataset", &[]);
    let p = &json(&out.join("meta.json"))["provenance"];
    let command: Vec<&str> = p["command"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_str().unwrap())
        .collect();
    assert_eq!(command[1..3], ["plot", s(dataset())], "{p}");
    assert!(p["started"].as_str().unwrap().ends_with('Z'), "{p}");
    let manifest = &json(&dataset().join("meta.json"))["gvsrom"];
    assert_eq!(p["plotted"]["meta_sha256"], manifest["meta_sha256"], "{p}");
    assert_eq!(p["plotted"]["sha256"], manifest["sha256"], "{p}");
    assert!(!p["plotted"]["sha256"].as_object().unwrap().is_empty());
    // a statics JSON file: the SHA-256 of its bytes
    let (out, _) = plot(statics_json(), "fig-prov-statics", &[]);
    let p = &json(&out.join("meta.json"))["provenance"];
    let bytes = std::fs::read(statics_json()).unwrap();
    let hex: String = Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    assert_eq!(
        p["plotted"]["sha256"]["plot-statics.json"],
        hex.as_str(),
        "{p}"
    );
}

/// A linearization with many output points draws the gain of a spread of them, says so, and
/// keeps its figure within the image size (41 points drew one 16 700 px high and plot failed).
#[test]
fn the_gain_of_many_output_points_is_drawn_at_twelve_of_them() {
    let lin = scratch("many-points.json");
    let xs: Vec<String> = (0..=40)
        .map(|i| format!("{}", 0.25 * i as f64 / 40.0))
        .collect();
    run_ok(&[
        "linearize",
        "single-tendon",
        "--output-at",
        &xs.join(","),
        "--json",
        s(&lin),
    ]);
    let out = scratch("many-points-figures");
    let stdout = run_ok(&["plot", s(&lin), "--out", s(&out)]);
    assert!(
        stdout.contains("static_gain: 12 of the 41 output points drawn"),
        "{stdout}"
    );
    assert!(out.join("static_gain.png").is_file() && out.join("poles.png").is_file());
}
