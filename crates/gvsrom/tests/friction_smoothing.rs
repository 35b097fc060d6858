//! The scenario field `tendons.N.friction_smoothing` (issue 8): the curvature scale κ_ε of the
//! smoothed friction angle, defaulting to `gvs::actuation::DEFAULT_FRICTION_SMOOTHING` (0.3 rad/m in
//! the IV-A preset), passed to the engine, and rejected with the offending field and value when it is
//! not a finite number ≥ 0.

use gvs::actuation::DEFAULT_FRICTION_SMOOTHING;
use gvsrom::presets;

fn build(overrides: &[&str]) -> Result<gvsrom::Built, String> {
    build_inner(overrides)
}

fn error(overrides: &[&str]) -> String {
    match build_inner(overrides) {
        Ok(_) => panic!("{overrides:?} accepted"),
        Err(e) => e,
    }
}

fn build_inner(overrides: &[&str]) -> Result<gvsrom::Built, String> {
    build_preset("single-tendon", overrides)
}

fn build_preset(name: &str, overrides: &[&str]) -> Result<gvsrom::Built, String> {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let s = presets::load(name, &o).map_err(|e| e.to_string())?;
    gvsrom::build(&s).map_err(|e| e.to_string())
}

#[test]
fn friction_smoothing_defaults_and_passes_through() {
    // the six-tendon preset leaves the field out, the IV-A preset sets 0.3 rad/m
    let b = build_preset("six-tendon", &[]).unwrap();
    for t in &b.model.tendons {
        assert_eq!(t.friction_smoothing, DEFAULT_FRICTION_SMOOTHING);
    }
    let b = build(&[]).unwrap();
    assert_eq!(b.model.tendons[0].friction_smoothing, 0.3);
    for v in ["0", "0.05", "2.5"] {
        let b = build(&[&format!("tendons.0.friction_smoothing={v}")]).unwrap();
        assert_eq!(
            b.model.tendons[0].friction_smoothing,
            v.parse::<f64>().unwrap()
        );
    }
}

#[test]
fn invalid_friction_smoothing_is_rejected_with_its_field() {
    // a scale above the largest curvature a load may imply (200 rad over the 0.25 m arm: 800
    // rad/m) smooths the friction away at every curvature: 1e300 once did so without a word
    for v in ["-0.1", "nan", "inf", "-inf", "801", "1e300"] {
        let err = error(&[&format!("tendons.0.friction_smoothing={v}")]);
        assert!(
            err.contains("tendons[0].friction_smoothing")
                && (err.contains("a number in [0, 800]") || err.contains("finite")),
            "{v}: {err}"
        );
    }
    assert!(build(&["tendons.0.friction_smoothing=800"]).is_ok());
    let err = error(&["tendons.0.friction_smoothing=\"small\""]);
    assert!(err.contains("friction_smoothing"), "{err}");
}
