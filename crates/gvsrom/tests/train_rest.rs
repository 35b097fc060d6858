//! The rest coordinates of an autoencoder trained on trajectory data decode to the straight rod,
//! where every simulation from rest starts (the zero-strain anchor of `gvsrom train`).
//!
//! Babbling data of the single tendon under gravity start from the straight rod, but it is one
//! snapshot of hundreds: the rest of the data sag (shown below), and without the anchor the
//! decoder places `D(rest)` far from zero. With it, `D(rest)` is within 5 % of the data's largest
//! strain. (Measured with the anchor switched off: `D(rest)` is then 21 % of it off, and the test
//! fails.)

mod common;

use common::{run_ok, scratch};
use gvsrom::reduced_model::{ModelWeights, ReducedModel};

fn npy(path: &std::path::Path) -> Vec<f64> {
    let bytes = std::fs::read(path).unwrap();
    npyz::NpyFile::new(&bytes[..]).unwrap().into_vec().unwrap()
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

#[test]
fn trained_rest_decodes_to_the_straight_rod_from_sagging_trajectory_data() {
    let data = scratch("rest-sag-data");
    run_ok(&[
        "dataset",
        "single-tendon",
        "--duration",
        "3",
        "--babble=-3,0,0.3,0.6",
        "--sample-rate",
        "100",
        "--seed",
        "2",
        "--out",
        data.to_str().unwrap(),
    ]);
    let strain = npy(&data.join("strain.npy"));
    let rows = npy(&data.join("tip_position.npy")).len() / 3;
    let n = strain.len() / rows;
    let largest = max_abs(&strain);
    // the first snapshot is the straight rod; after 0.1 s every snapshot sags
    let straightest = strain
        .chunks_exact(n)
        .skip(10)
        .map(max_abs)
        .fold(f64::INFINITY, f64::min);
    assert!(
        max_abs(&strain[..n]) == 0.0,
        "the data start from the straight rod"
    );
    assert!(
        straightest > 0.1 * largest,
        "a later sample is nearly straight ({straightest:.3e} of {largest:.3e}): the test would not test the anchor"
    );

    let model = scratch("rest-sag-model");
    run_ok(&[
        "train",
        data.to_str().unwrap(),
        "--latent",
        "1",
        "--hidden-layers",
        "3",
        "--epochs",
        "300",
        "--seed",
        "3",
        "--out",
        model.to_str().unwrap(),
    ]);
    let m = ReducedModel::load(&model).unwrap();
    let ModelWeights::Autoencoder(ae) = &m.weights else {
        panic!("an autoencoder model")
    };
    let decoded = ae.decode(&m.meta.rest).unwrap();
    let off = max_abs(&decoded);
    assert!(
        off <= 0.05 * largest,
        "D(rest) is {off:.3e} from the straight rod, more than 5 % of the data's largest strain {largest:.3e} (the straightest sample after 0.1 s: {straightest:.3e})"
    );
}
