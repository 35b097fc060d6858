//! Re-records the content hashes of a gvsrom directory output after a test changed its files on
//! purpose, as a writer with a bug would: the loaders' own checks (shapes, consistency with the
//! scenario) are then what must refuse the output. Written from the manifest's documented scheme
//! (`output::integrity`), not with gvsrom's code, so it also checks that scheme.

use serde_json::{Map, Value};
use sha2::{Digest, Sha256};
use std::path::Path;

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Recomputes `sha256` of every listed file and `meta_sha256` of `dir/meta.json`.
pub fn reseal(dir: &Path) {
    let path = dir.join("meta.json");
    let mut meta: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let files: Vec<String> = meta["gvsrom"]["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap().to_string())
        .collect();
    let mut hashes = Map::new();
    for f in files {
        let bytes = std::fs::read(dir.join(&f)).unwrap();
        hashes.insert(f, Value::from(hex(&Sha256::digest(&bytes))));
    }
    let obj = meta.as_object().unwrap();
    let body: Map<String, Value> = obj
        .iter()
        .filter(|(k, _)| *k != "gvsrom")
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    let meta_hash = hex(&Sha256::digest(serde_json::to_vec(&body).unwrap()));
    let manifest = meta["gvsrom"].as_object_mut().unwrap();
    manifest.insert("sha256".into(), Value::Object(hashes));
    manifest.insert("meta_sha256".into(), Value::from(meta_hash));
    std::fs::write(&path, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
}

/// Recomputes `meta_sha256` of a JSON file output (`statics --json`, …) held as `value`.
#[allow(dead_code)]
pub fn reseal_json(value: &mut Value) {
    let body: Map<String, Value> = (value.as_object().unwrap().iter())
        .filter(|(k, _)| *k != "gvsrom")
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    let meta_hash = hex(&Sha256::digest(serde_json::to_vec(&body).unwrap()));
    value["gvsrom"]["meta_sha256"] = Value::from(meta_hash);
}
