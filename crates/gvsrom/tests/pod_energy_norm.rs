//! `gvsrom pod --norm energy`: a POD optimal in the strain-energy norm. Its norm weights are the
//! section stiffness of each point and component (checked against the closed forms `E I`, `E A`,
//! `G A` of the tapered IV-A arm), its modes are orthonormal in that norm, its singular values are
//! those of the weighted snapshots, a snapshot's coordinates are its projection in that norm, and it
//! reconstructs the data closer than the plain POD in that norm (and less close in the plain one).

mod common;

use common::{
    assert_sigma_squared_are_eigenvalues, copy_dir, gvsrom, json, run_ok, s, scratch, snapshots,
    sweep_dataset,
};
use gvsrom::reduced_model::{ModelWeights, ReducedModel};
use nalgebra::{DMatrix, DVector};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// A sweep of 15 tensions over [-6, 0] N of the single-tendon arm (3 components at 102 points),
/// its POD-2 in the plain norm and in the energy norm.
fn models() -> &'static (PathBuf, PathBuf, PathBuf) {
    static M: OnceLock<(PathBuf, PathBuf, PathBuf)> = OnceLock::new();
    M.get_or_init(|| {
        let data = sweep_dataset("energy-pod-data", "-6:0", 15);
        let (plain, energy) = (scratch("energy-pod-plain"), scratch("energy-pod-energy"));
        run_ok(&["pod", s(&data), "--modes", "2", "--out", s(&plain)]);
        let printed = run_ok(&[
            "pod",
            s(&data),
            "--modes",
            "2",
            "--norm",
            "energy",
            "--out",
            s(&energy),
        ]);
        assert!(printed.contains("in the strain-energy norm"), "{printed}");
        (data, plain, energy)
    })
}

fn pod_of(dir: &Path) -> (DMatrix<f64>, Option<Vec<f64>>) {
    match ReducedModel::load(dir).unwrap().weights {
        ModelWeights::Pod {
            modes,
            norm_weights,
            ..
        } => (modes, norm_weights),
        ModelWeights::Autoencoder(_) => panic!("a POD model"),
    }
}

/// The strain-energy weights of the preset `single-tendon` from its geometry and material
/// (`gvsrom show single-tendon`): radius 12.5 → 5 mm linearly over 0.25 m, E = 0.617 MPa,
/// ν = 0.5 (G = E / 3), weight of (point, component) = `E I`, `E A` or `G A` there.
fn closed_form_weights(strain_x: &[f64], active: &[String]) -> Vec<f64> {
    let (e, g) = (0.617e6, 0.617e6 / 3.0);
    let pi = std::f64::consts::PI;
    strain_x
        .iter()
        .flat_map(|&x| {
            let r = 0.0125 + (0.005 - 0.0125) * x / 0.25;
            let (area, inertia) = (pi * r * r, pi * r.powi(4) / 4.0);
            active.iter().map(move |a| match a.as_str() {
                "bend_y" | "bend_z" => e * inertia,
                "elongation" => e * area,
                "shear_y" | "shear_z" => g * area,
                other => panic!("component {other} is not active in single-tendon"),
            })
        })
        .collect()
}

#[test]
fn energy_pod_weights_are_the_section_stiffness_of_the_tapered_arm() {
    let (_, plain, energy) = models();
    let meta = json(&energy.join("meta.json"));
    assert_eq!(meta["pod_norm"], "energy");
    assert_eq!(json(&plain.join("meta.json"))["pod_norm"], "plain");
    let strain_x: Vec<f64> = serde_json::from_value(meta["layout"]["strain_x"].clone()).unwrap();
    let active: Vec<String> = serde_json::from_value(meta["layout"]["active"].clone()).unwrap();
    assert_eq!((strain_x.len(), active.len()), (102, 3));
    let expected = closed_form_weights(&strain_x, &active);
    let (_, w) = pod_of(energy);
    let w = w.expect("an energy POD stores its norm weights");
    assert_eq!(w.len(), expected.len());
    for (j, (got, want)) in w.iter().zip(&expected).enumerate() {
        assert!(
            (got - want).abs() <= 1e-12 * want,
            "feature {j}: {got} against {want}"
        );
    }
    assert!(pod_of(plain).1.is_none());
}

#[test]
fn energy_pod_modes_are_orthonormal_in_the_norm_and_its_singular_values_are_the_weighted_ones() {
    let (data, _, energy) = models();
    let (phi, w) = pod_of(energy);
    let w = DVector::from_vec(w.unwrap());
    let wd = DMatrix::from_diagonal(&w);
    let gram = phi.transpose() * &wd * &phi;
    assert!(
        (&gram - DMatrix::identity(2, 2)).amax() < 1e-10,
        "Φᵀ W Φ = {gram}"
    );
    // σ_k² are the eigenvalues of W^{1/2} XᵀX W^{1/2} (a symmetric eigensolver, not an SVD)
    let x = snapshots(data);
    let root = DMatrix::from_diagonal(&w.map(f64::sqrt));
    let xw = &x * &root;
    assert_sigma_squared_are_eigenvalues(energy, &(xw.transpose() * &xw), 2, 1e-8);
}

#[test]
fn energy_pod_is_the_closer_fit_in_its_norm_and_plain_pod_in_the_plain_one() {
    let (data, plain, energy) = models();
    let x = snapshots(data);
    let w = DVector::from_vec(pod_of(energy).1.unwrap());
    // each model's reconstruction D(E(x)) through the library, as `reconstruct` and Python use it
    let rebuilt = |dir: &Path| {
        let m = ReducedModel::load(dir).unwrap();
        let rows: Vec<f64> = x.transpose().iter().copied().collect();
        let q = m.encode(&rows, true).unwrap();
        let back = m.decode(&q, true).unwrap();
        DMatrix::from_row_slice(x.nrows(), x.ncols(), &back)
    };
    let (rp, re) = (rebuilt(plain), rebuilt(energy));
    let energy_err = |r: &DMatrix<f64>| {
        let d = r - &x;
        (0..d.nrows())
            .map(|i| {
                (0..d.ncols())
                    .map(|j| w[j] * d[(i, j)].powi(2))
                    .sum::<f64>()
            })
            .sum::<f64>()
    };
    let plain_err = |r: &DMatrix<f64>| (r - &x).norm_squared();
    let (pe, ee) = (energy_err(&rp), energy_err(&re));
    assert!(
        ee < 0.99 * pe,
        "energy-norm error: energy POD {ee:e}, plain POD {pe:e}"
    );
    let (pp, ep) = (plain_err(&rp), plain_err(&re));
    assert!(pp < ep, "plain error: plain POD {pp:e}, energy POD {ep:e}");
    // the energy POD's coordinates are the W-projection Φᵀ W x, computed here from its modes
    let (phi, _) = pod_of(energy);
    let wd = DMatrix::from_diagonal(&w);
    let projected = (&phi * (phi.transpose() * &wd * x.transpose())).transpose();
    assert!((&re - &projected).amax() <= 1e-10 * x.amax());
}

#[test]
fn an_unknown_norm_is_refused_with_the_accepted_ones() {
    let (data, _, _) = models();
    let out = scratch("energy-pod-bad-norm");
    let o = gvsrom(&[
        "pod",
        s(data),
        "--modes",
        "2",
        "--norm",
        "kinetic",
        "--out",
        s(&out),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for needle in ["--norm", "kinetic", "plain", "energy"] {
        assert!(err.contains(needle), "`{needle}` in {err}");
    }
    assert!(!out.exists());
}

/// A copy of the model `from` at the scratch path `name` with `meta.json`'s `pod_norm` set to
/// `norm`, its hashes recomputed (a consistent file set that disagrees with itself).
fn relabelled(from: &Path, name: &str, norm: &str) -> PathBuf {
    let dir = copy_dir(from, name);
    let path = dir.join("meta.json");
    let mut meta = json(&path);
    meta["pod_norm"] = serde_json::json!(norm);
    std::fs::write(&path, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
    common::reseal::reseal(&dir);
    dir
}

#[test]
fn a_pod_whose_norm_and_weights_disagree_is_refused_on_load() {
    let (_, plain, energy) = models();
    // energy in meta.json, but no weights to project with
    let dir = relabelled(plain, "energy-pod-no-weights", "energy");
    let e = ReducedModel::load(&dir).expect_err("refused").to_string();
    assert!(e.contains("norm_weights"), "{e}");
    // weights, but meta.json says plain: the coordinates would silently be another projection
    let dir = relabelled(energy, "energy-pod-said-plain", "plain");
    let e = ReducedModel::load(&dir).expect_err("refused").to_string();
    assert!(e.contains("norm_weights") && e.contains("plain"), "{e}");
    // the copies themselves are sound: relabelled as they were, both load
    assert!(ReducedModel::load(&relabelled(energy, "energy-pod-same", "energy")).is_ok());
    assert!(ReducedModel::load(&relabelled(plain, "energy-pod-plain-same", "plain")).is_ok());
}
