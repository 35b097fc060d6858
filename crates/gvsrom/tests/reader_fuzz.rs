//! Property tests of the dataset and reduced-model readers (the "What must hold": a fuzz
//! target over the model and dataset readers, bytes and JSON mutations, never a panic).
//!
//! A tiny dataset, a POD model and an autoencoder are made once with the binary. Every case copies
//! one, mutates it — bytes of one of its files (anywhere, or in the first bytes where the `.npy` and
//! safetensors headers sit, or its `.npy` header rewritten with another shape and dtype, or its
//! safetensors header length or JSON header edited), or values of `meta.json` — and reads it twice:
//! (a) as mutated, when the hash check refuses most of it (a dataset is then read anyway to say how
//! it changed), and (b) resealed (`common::reseal`: its hashes recomputed, as a writer with a bug
//! would), so that the readers' own checks must answer.
//!
//! A dataset read `Ok` must be consistent (every array the length its meta.json gives, statuses and
//! counts in agreement, usable rows finite); it then goes through `reduce::dataset_scenario` and a
//! one-mode POD, whose model is checked as below. A model read `Ok` must be consistent (its weights
//! the shape of its layout and latent size) and is attached to the `single-tendon` preset as
//! `--model` does, with and without `--extrapolate`, and solved once. An `Err` anywhere is fine; a
//! panic, a hang (no answer within [`LIMIT`]) or a NaN in an `Ok` is not.
//!
//! The runs are deterministic: a fixed ChaCha seed and no failure persistence (`PROPTEST_CASES`
//! and `PROPTEST_RNG_SEED` give a longer or another local run).

mod common;

use common::{run_ok, s, scratch, sweep_dataset};
use gvsrom::dataset::Dataset;
use gvsrom::reduced_model::{ModelWeights, ReducedModel};
use proptest::prelude::*;
use proptest::sample::{select, Index};
use proptest::test_runner::{RngAlgorithm, RngSeed, TestCaseError, TestRunner};
use serde_json::Value;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Arc, OnceLock};
use std::time::Duration;

/// Longest a case may take (load, POD, attach and solve of a tiny model take well under a second
/// in a debug build): longer is reported as a hang.
const LIMIT: Duration = Duration::from_secs(60);

/// Six single-tendon equilibria at tensions in [-6, 3] N.
fn dataset() -> &'static Path {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| sweep_dataset("rfuzz-ds", "-6:3", 6))
}

/// A two-mode POD of [`dataset`].
fn pod_model() -> &'static Path {
    static M: OnceLock<PathBuf> = OnceLock::new();
    M.get_or_init(|| {
        let dir = scratch("rfuzz-pod");
        run_ok(&["pod", s(dataset()), "--modes", "2", "--out", s(&dir)]);
        dir
    })
}

/// A one-coordinate autoencoder of [`dataset`], trained briefly (its quality does not matter).
fn ae_model() -> &'static Path {
    static M: OnceLock<PathBuf> = OnceLock::new();
    M.get_or_init(|| {
        let dir = scratch("rfuzz-ae");
        run_ok(&[
            "train",
            s(dataset()),
            "--latent",
            "1",
            "--hidden-layers",
            "3",
            "--epochs",
            "5",
            "--lbfgs-iterations",
            "20",
            "--out",
            s(&dir),
        ]);
        dir
    })
}

/// The names of the files of `dir`, sorted.
fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap())
        .filter(|e| e.file_type().unwrap().is_file())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A copy of `src` in the fresh scratch directory `name`.
fn copy(src: &Path, name: &str) -> PathBuf {
    let dst = scratch(name);
    fs::create_dir_all(&dst).unwrap();
    for f in files(src) {
        fs::copy(src.join(&f), dst.join(&f)).unwrap();
    }
    dst
}

/// Deterministic configuration: `cases` cases (or `PROPTEST_CASES`) from a fixed seed (or
/// `PROPTEST_RNG_SEED`), nothing written to disk.
fn config(cases: u32) -> ProptestConfig {
    fn env<T: std::str::FromStr>(name: &str) -> Option<T> {
        std::env::var(name).ok().and_then(|v| v.parse().ok())
    }
    ProptestConfig {
        cases: env("PROPTEST_CASES").unwrap_or(cases),
        failure_persistence: None,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(env("PROPTEST_RNG_SEED").unwrap_or(0x0072_6675_7a7a)),
        ..ProptestConfig::default()
    }
}

/// Runs `f` on another thread; a panic there is a panic here, no answer within [`LIMIT`] a hang.
fn within<T: Send + 'static>(what: String, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    let worker = std::thread::spawn(move || {
        let out = f();
        let _ = tx.send(());
        out
    });
    match rx.recv_timeout(LIMIT) {
        Ok(()) | Err(RecvTimeoutError::Disconnected) => worker
            .join()
            .unwrap_or_else(|p| std::panic::resume_unwind(p)),
        Err(RecvTimeoutError::Timeout) => panic!("{what}: no answer within {LIMIT:?} (a hang)"),
    }
}

// ---------------------------------------------------------------------------------------------
// JSON mutations

/// Where a JSON edit applies: any value of the document, or one at or under a key of [`KEYS`] (the
/// sizes, shapes and ranges the readers check), falling back to any value if the document has none.
#[derive(Debug, Clone)]
enum At {
    Any(Index),
    Key(&'static str, Index),
}

/// Keys of meta.json (datasets and models) whose values size or shape what is read.
const KEYS: &[&str] = &[
    "samples",
    "n_dof",
    "n_points",
    "strain_x",
    "components",
    "parameters",
    "chunk_size",
    "chunk_done",
    "counts",
    "ok",
    "failed",
    "not_computed",
    "failures",
    "kind",
    "plan",
    "dynamic",
    "latent",
    "rest",
    "latent_range",
    "input_range",
    "min",
    "max",
    "anchor_parameters",
    "anchor_equilibria",
    "layout",
    "active",
    "hom_dof",
    "training",
    "encoder_sizes",
    "decoder_sizes",
    "hidden_layers",
    "files",
    "format",
    "shape",
    "dtype",
    "data_offsets",
];

#[derive(Debug, Clone)]
enum JsonEdit {
    /// The value at `at` replaced by `value`.
    Replace {
        at: At,
        value: Value,
    },
    /// A number multiplied by `factor` (integers stay integers where they can).
    Scale {
        at: At,
        factor: f64,
    },
    Delete {
        at: At,
    },
    /// An array's entry at `entry` inserted again after itself.
    Duplicate {
        at: At,
        entry: Index,
    },
    /// An array shrunk or grown (repeating its last entry, or `fill` if empty) to `len` entries.
    Resize {
        at: At,
        len: usize,
        fill: Value,
    },
}

#[derive(Debug, Clone, PartialEq)]
enum Seg {
    Key(String),
    Index(usize),
}

/// Every path of `v` (the root, `[]`, first), pre-order.
fn paths(v: &Value, here: &mut Vec<Seg>, out: &mut Vec<Vec<Seg>>) {
    out.push(here.clone());
    match v {
        Value::Object(m) => {
            for (k, c) in m {
                here.push(Seg::Key(k.clone()));
                paths(c, here, out);
                here.pop();
            }
        }
        Value::Array(a) => {
            for (i, c) in a.iter().enumerate() {
                here.push(Seg::Index(i));
                paths(c, here, out);
                here.pop();
            }
        }
        _ => {}
    }
}

fn get<'a>(v: &'a Value, path: &[Seg]) -> Option<&'a Value> {
    path.iter().try_fold(v, |v, seg| match (seg, v) {
        (Seg::Key(k), Value::Object(m)) => m.get(k),
        (Seg::Index(i), Value::Array(a)) => a.get(*i),
        _ => None,
    })
}

fn get_mut<'a>(v: &'a mut Value, path: &[Seg]) -> Option<&'a mut Value> {
    path.iter().try_fold(v, |v, seg| match (seg, v) {
        (Seg::Key(k), Value::Object(m)) => m.get_mut(k),
        (Seg::Index(i), Value::Array(a)) => a.get_mut(*i),
        _ => None,
    })
}

/// The path `at` picks among the non-root paths of `doc` whose value satisfies `fits`.
fn pick(doc: &Value, at: &At, fits: impl Fn(&Value) -> bool) -> Option<Vec<Seg>> {
    let mut all = vec![];
    paths(doc, &mut vec![], &mut all);
    let candidates: Vec<Vec<Seg>> = all
        .into_iter()
        .filter(|p| !p.is_empty() && get(doc, p).is_some_and(&fits))
        .collect();
    let (named, index) = match at {
        At::Any(i) => (vec![], i),
        At::Key(key, i) => (
            candidates
                .iter()
                .filter(|p| p.contains(&Seg::Key(key.to_string())))
                .cloned()
                .collect(),
            i,
        ),
    };
    let from = if named.is_empty() { candidates } else { named };
    (!from.is_empty()).then(|| index.get(&from).clone())
}

fn scaled(v: &Value, factor: f64) -> Value {
    let x = v.as_f64().unwrap_or(0.0) * factor;
    let integral = x.is_finite() && x.fract() == 0.0;
    if v.is_u64() && integral && (0.0..1.8e19).contains(&x) {
        Value::from(x as u64)
    } else if v.is_i64() && integral && x.abs() < 9.2e18 {
        Value::from(x as i64)
    } else {
        Value::from(x) // a non-finite result becomes null
    }
}

/// Applies `edit` to `doc`; an edit with no value to apply to leaves it unchanged.
fn apply_json(doc: &mut Value, edit: &JsonEdit) {
    match edit {
        JsonEdit::Replace { at, value } => {
            if let Some(p) = pick(doc, at, |_| true) {
                *get_mut(doc, &p).unwrap() = value.clone();
            }
        }
        JsonEdit::Scale { at, factor } => {
            if let Some(p) = pick(doc, at, Value::is_number) {
                let v = get_mut(doc, &p).unwrap();
                *v = scaled(v, *factor);
            }
        }
        JsonEdit::Delete { at } => {
            if let Some(p) = pick(doc, at, |_| true) {
                let (last, parent) = p.split_last().unwrap();
                match (last, get_mut(doc, parent).unwrap()) {
                    (Seg::Key(k), Value::Object(m)) => {
                        m.shift_remove(k);
                    }
                    (Seg::Index(i), Value::Array(a)) => {
                        a.remove(*i);
                    }
                    _ => unreachable!("a path's parent holds it"),
                }
            }
        }
        JsonEdit::Duplicate { at, entry } => {
            if let Some(p) = pick(doc, at, |v| v.as_array().is_some_and(|a| !a.is_empty())) {
                let a = get_mut(doc, &p).unwrap().as_array_mut().unwrap();
                let i = entry.index(a.len());
                a.insert(i + 1, a[i].clone());
            }
        }
        JsonEdit::Resize { at, len, fill } => {
            if let Some(p) = pick(doc, at, Value::is_array) {
                let a = get_mut(doc, &p).unwrap().as_array_mut().unwrap();
                let fill = a.last().cloned().unwrap_or_else(|| fill.clone());
                a.resize(*len, fill);
            }
        }
    }
}

/// JSON values the readers must refuse or accept: extreme, negative, zero and fractional numbers,
/// names of other kinds, wrong types, arrays of any length, nested arrays and objects.
fn json_value() -> impl Strategy<Value = Value> {
    let specials = vec![
        Value::from(0),
        Value::from(-1),
        Value::from(1),
        Value::from(2),
        Value::from(3),
        Value::from(0.5),
        Value::from(-0.5),
        Value::from(1e308),
        Value::from(-1e308),
        Value::from(5e-324),
        Value::from(1u64 << 32),
        Value::from(1u64 << 53),
        Value::from(u64::MAX),
        Value::from(i64::MIN),
        Value::Null,
        Value::Bool(true),
        Value::Bool(false),
        Value::from(""),
        Value::from("statics"),
        Value::from("dynamics"),
        Value::from("pod"),
        Value::from("autoencoder"),
        Value::from("dataset"),
        Value::from("reduced-model"),
        Value::from("tendons.0.tension"),
        Value::from("bend_y"),
        Value::from("F64"),
        Value::from("meta.json"),
        Value::from("../inputs.npy"),
        serde_json::json!([]),
        serde_json::json!({}),
        serde_json::json!([0.0, 1.0]),
        serde_json::json!([[-1e308, 1e308]]),
        serde_json::json!([[1.0, -1.0], [0.0, 0.0]]),
        serde_json::json!({"parameter": "tendons.0.tension", "min": 1e308, "max": -1e308}),
        serde_json::json!({"ok": 6, "failed": 0, "not_computed": 0, "warm_started": 0}),
    ];
    let scalar = prop_oneof![
        select(vec![
            Value::from(0),
            Value::from(-1),
            Value::from(1e308),
            Value::from(u64::MAX),
            Value::Null,
            Value::from("x"),
            Value::Bool(true),
        ]),
        (0u64..40).prop_map(Value::from),
        any::<f64>().prop_map(Value::from),
    ];
    prop_oneof![
        4 => select(specials),
        2 => (0u64..40).prop_map(Value::from),
        2 => any::<f64>().prop_map(Value::from),
        1 => "[a-z_.0-9]{0,12}".prop_map(Value::from),
        2 => prop::collection::vec(scalar.clone(), 0..8).prop_map(Value::from),
        1 => prop::collection::vec(prop::collection::vec(scalar.clone(), 0..3), 0..4)
            .prop_map(|v| Value::from(v.into_iter().map(Value::from).collect::<Vec<_>>())),
        1 => prop::collection::vec(("[a-z_]{1,8}", scalar), 0..4)
            .prop_map(|kv| Value::Object(kv.into_iter().collect())),
    ]
}

fn at() -> impl Strategy<Value = At> {
    prop_oneof![
        any::<Index>().prop_map(At::Any),
        (select(KEYS), any::<Index>()).prop_map(|(k, i)| At::Key(k, i)),
    ]
}

fn json_edit() -> impl Strategy<Value = JsonEdit> {
    let factor = select(vec![
        -1.0,
        0.0,
        0.5,
        2.0,
        3.0,
        10.0,
        1e6,
        1e-6,
        1e300,
        1.0 + 1e-9,
    ]);
    prop_oneof![
        4 => (at(), json_value()).prop_map(|(at, value)| JsonEdit::Replace { at, value }),
        2 => (at(), factor).prop_map(|(at, factor)| JsonEdit::Scale { at, factor }),
        2 => at().prop_map(|at| JsonEdit::Delete { at }),
        1 => (at(), any::<Index>()).prop_map(|(at, entry)| JsonEdit::Duplicate { at, entry }),
        2 => (at(), 0usize..24, json_value())
            .prop_map(|(at, len, fill)| JsonEdit::Resize { at, len, fill }),
    ]
}

// ---------------------------------------------------------------------------------------------
// Byte mutations

#[derive(Debug, Clone)]
enum ByteEdit {
    /// The byte at `at` XOR `mask`.
    Flip {
        at: Index,
        mask: u8,
    },
    /// Bytes from `at` on overwritten by `with`.
    Overwrite {
        at: Index,
        with: Vec<u8>,
    },
    /// As [`ByteEdit::Flip`] at byte `at` < 128: the `.npy` magic, version, header length and
    /// dict; the safetensors length and JSON header.
    FlipHead {
        at: usize,
        mask: u8,
    },
    /// As [`ByteEdit::Overwrite`] from byte `at` < 128.
    OverwriteHead {
        at: usize,
        with: Vec<u8>,
    },
    /// The file cut at `at` bytes.
    Truncate {
        at: Index,
    },
    Append {
        bytes: Vec<u8>,
    },
    Empty,
    /// The 8-byte value at `at` of the data (after the `.npy` or safetensors header, aligned as
    /// the f64 arrays are) replaced by `value`: NaN, infinities, extremes the readers must judge.
    Float {
        at: Index,
        value: f64,
    },
    /// `.npy`: the header dict rewritten with this dtype, order and shape (the data kept).
    NpyHeader {
        descr: &'static str,
        fortran: bool,
        shape: Vec<u64>,
    },
    /// safetensors: the 8-byte header length replaced.
    StLength(u64),
    /// safetensors: its JSON header edited (the length prefix follows it).
    StHeader(JsonEdit),
}

/// Applies `edit` to the content `b` of the file `name` (an edit for another kind of file, or of a
/// file too short for it, leaves it unchanged).
fn apply_bytes(name: &str, b: &mut Vec<u8>, edit: &ByteEdit) {
    let overwrite = |b: &mut Vec<u8>, at: usize, with: &[u8]| {
        for (k, &x) in with.iter().enumerate() {
            if let Some(y) = b.get_mut(at + k) {
                *y = x;
            }
        }
    };
    match edit {
        ByteEdit::Flip { at, mask } if !b.is_empty() => {
            let i = at.index(b.len());
            b[i] ^= mask;
        }
        ByteEdit::Overwrite { at, with } if !b.is_empty() => {
            let i = at.index(b.len());
            overwrite(b, i, with);
        }
        ByteEdit::FlipHead { at, mask } => {
            if let Some(y) = b.get_mut(*at) {
                *y ^= mask;
            }
        }
        ByteEdit::OverwriteHead { at, with } => overwrite(b, *at, with),
        ByteEdit::Truncate { at } => {
            let n = at.index(b.len() + 1);
            b.truncate(n);
        }
        ByteEdit::Append { bytes } => b.extend_from_slice(bytes),
        ByteEdit::Float { at, value } => {
            let start = data_start(name, b);
            let slots = b.len().saturating_sub(start) / 8;
            if slots > 0 {
                let i = start + 8 * at.index(slots);
                b[i..i + 8].copy_from_slice(&value.to_le_bytes());
            }
        }
        ByteEdit::Empty => b.clear(),
        ByteEdit::NpyHeader {
            descr,
            fortran,
            shape,
        } if name.ends_with(".npy") && b.len() >= 10 && b[6] == 1 => {
            // version 1.0: magic, version, u16 header length, dict padded to 64 bytes, data
            let old = u16::from_le_bytes([b[8], b[9]]) as usize;
            let data = b.get(10 + old..).unwrap_or(&[]).to_vec();
            let dims: Vec<String> = shape.iter().map(u64::to_string).collect();
            let tuple = match dims.len() {
                1 => format!("({},)", dims[0]),
                _ => format!("({})", dims.join(", ")),
            };
            let order = if *fortran { "True" } else { "False" };
            let mut dict =
                format!("{{'descr': '{descr}', 'fortran_order': {order}, 'shape': {tuple}, }}");
            while (10 + dict.len() + 1) % 64 != 0 {
                dict.push(' ');
            }
            dict.push('\n');
            b.truncate(8);
            b.extend_from_slice(&(dict.len() as u16).to_le_bytes());
            b.extend_from_slice(dict.as_bytes());
            b.extend_from_slice(&data);
        }
        ByteEdit::StLength(n) if name.ends_with(".safetensors") && b.len() >= 8 => {
            b[..8].copy_from_slice(&n.to_le_bytes());
        }
        ByteEdit::StHeader(e) if name.ends_with(".safetensors") && b.len() >= 8 => {
            let end =
                8usize.saturating_add(u64::from_le_bytes(b[..8].try_into().unwrap()) as usize);
            let Some(Ok(mut header)) = b.get(8..end).map(serde_json::from_slice::<Value>) else {
                return;
            };
            apply_json(&mut header, e);
            let text = serde_json::to_vec(&header).unwrap();
            let data = b[end..].to_vec();
            b.clear();
            b.extend_from_slice(&(text.len() as u64).to_le_bytes());
            b.extend_from_slice(&text);
            b.extend_from_slice(&data);
        }
        _ => {}
    }
}

/// Where the data of the file `name` start: after the `.npy` header (version 1.0) or the
/// safetensors length and header; 0 for other files or a header that does not fit.
fn data_start(name: &str, b: &[u8]) -> usize {
    let start = if name.ends_with(".npy") && b.len() >= 10 {
        10 + u16::from_le_bytes([b[8], b[9]]) as usize
    } else if name.ends_with(".safetensors") && b.len() >= 8 {
        8usize.saturating_add(u64::from_le_bytes(b[..8].try_into().unwrap()) as usize)
    } else {
        0
    };
    if start <= b.len() {
        start
    } else {
        0
    }
}

fn byte_edit() -> impl Strategy<Value = ByteEdit> {
    let mask = 1u8..=255;
    let bytes = prop::collection::vec(any::<u8>(), 1..16);
    let dim = prop_oneof![
        3 => 0u64..12,
        2 => select(vec![
            1u64 << 31,
            1 << 32,
            1 << 40,
            1 << 62,
            u64::MAX / 2,
            u64::MAX,
        ]),
    ];
    let descr = select(vec![
        "<f8", "<f4", ">f8", "|u1", "<u4", "<i8", "|b1", "<c16", "|O", "<U3", "|V8", "<f16",
    ]);
    let float = select(vec![
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        1e308,
        -1e308,
        1e6,
        -0.0,
        5e-324,
    ]);
    let length = prop_oneof![
        0u64..200,
        select(vec![100_000_000u64, 100_000_001, 1 << 32, u64::MAX]),
        any::<u64>(),
    ];
    prop_oneof![
        3 => (any::<Index>(), mask.clone()).prop_map(|(at, mask)| ByteEdit::Flip { at, mask }),
        2 => (any::<Index>(), bytes.clone())
            .prop_map(|(at, with)| ByteEdit::Overwrite { at, with }),
        3 => (0usize..128, mask).prop_map(|(at, mask)| ByteEdit::FlipHead { at, mask }),
        2 => (0usize..128, bytes.clone())
            .prop_map(|(at, with)| ByteEdit::OverwriteHead { at, with }),
        2 => any::<Index>().prop_map(|at| ByteEdit::Truncate { at }),
        1 => bytes.prop_map(|bytes| ByteEdit::Append { bytes }),
        1 => Just(ByteEdit::Empty),
        3 => (any::<Index>(), float)
            .prop_map(|(at, value)| ByteEdit::Float { at, value }),
        3 => (descr, any::<bool>(), prop::collection::vec(dim, 0..4))
            .prop_map(|(descr, fortran, shape)| ByteEdit::NpyHeader { descr, fortran, shape }),
        1 => length.prop_map(ByteEdit::StLength),
        3 => json_edit().prop_map(ByteEdit::StHeader),
    ]
}

// ---------------------------------------------------------------------------------------------
// Cases

/// A mutation of a fixture directory: bytes of one file, or values of meta.json.
#[derive(Debug, Clone)]
enum Mutation {
    Bytes { file: String, edits: Vec<ByteEdit> },
    Json(Vec<JsonEdit>),
}

/// Bytes of one file of `files`; a model's weights (its parser and most of its numbers) are picked
/// as often as all its other files together.
fn byte_mutation(files: Vec<String>) -> impl Strategy<Value = Mutation> {
    let mut pool = files.clone();
    if let Some(w) = files.iter().find(|f| f.ends_with(".safetensors")) {
        pool.extend(std::iter::repeat_n(
            w.clone(),
            files.len().saturating_sub(2),
        ));
    }
    (select(pool), prop::collection::vec(byte_edit(), 1..4))
        .prop_map(|(file, edits)| Mutation::Bytes { file, edits })
}

fn json_mutation() -> impl Strategy<Value = Mutation> {
    prop::collection::vec(json_edit(), 1..4).prop_map(Mutation::Json)
}

fn mutate(dir: &Path, m: &Mutation) {
    match m {
        Mutation::Bytes { file, edits } => {
            let path = dir.join(file);
            let mut b = fs::read(&path).unwrap();
            for e in edits {
                apply_bytes(file, &mut b, e);
            }
            fs::write(&path, b).unwrap();
        }
        Mutation::Json(edits) => {
            let path = dir.join("meta.json");
            let mut doc: Value = serde_json::from_slice(&fs::read(&path).unwrap()).unwrap();
            for e in edits {
                apply_json(&mut doc, e);
            }
            fs::write(&path, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
        }
    }
}

/// Whether [`common::reseal::reseal`] can reseal `dir`: meta.json a JSON object whose `gvsrom`
/// manifest is an object listing regular files of `dir`.
fn resealable(dir: &Path) -> bool {
    let Ok(text) = fs::read(dir.join("meta.json")) else {
        return false;
    };
    let Ok(Value::Object(meta)) = serde_json::from_slice::<Value>(&text) else {
        return false;
    };
    let Some(Value::Object(manifest)) = meta.get("gvsrom") else {
        return false;
    };
    let Some(Value::Array(files)) = manifest.get("files") else {
        return false;
    };
    files
        .iter()
        .all(|f| f.as_str().is_some_and(|f| dir.join(f).is_file()))
}

/// How far the reads of a fuzz target got, over both passes of all its cases.
#[derive(Default)]
struct Reach {
    reads: AtomicUsize,
    resealed: AtomicUsize,
    /// Datasets or models read `Ok`.
    read_ok: AtomicUsize,
    /// Datasets whose scenario was rebuilt and that gave a POD.
    pod_ok: AtomicUsize,
    /// Models (read, or made by a POD) attached to `single-tendon`.
    attached: AtomicUsize,
    /// Reduced statics solved `Ok`.
    solved: AtomicUsize,
}

fn bump(c: &AtomicUsize) {
    c.fetch_add(1, Ordering::Relaxed);
}

impl std::fmt::Display for Reach {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = |c: &AtomicUsize| c.load(Ordering::Relaxed);
        write!(
            f,
            "{} reads ({} resealed): {} read Ok, {} POD Ok, {} attached, {} solved Ok",
            n(&self.reads),
            n(&self.resealed),
            n(&self.read_ok),
            n(&self.pod_ok),
            n(&self.attached),
            n(&self.solved)
        )
    }
}

type Check = fn(&Path, &str, &Reach);

/// Mutates a copy of `fixture` in the scratch directory `name` by `m`, runs `check` on it as
/// mutated and resealed, and removes it.
fn run_case(fixture: &Path, name: &str, m: &Mutation, check: Check, reach: &Arc<Reach>) {
    let dir = copy(fixture, name);
    mutate(&dir, m);
    let what = format!("{m:?}");
    let (d, r) = (dir.clone(), reach.clone());
    within(format!("{what} (as mutated)"), move || check(&d, "a", &r));
    if resealable(&dir) {
        common::reseal::reseal(&dir);
        bump(&reach.resealed);
        let (d, r) = (dir.clone(), reach.clone());
        within(format!("{what} (resealed)"), move || check(&d, "b", &r));
    }
    fs::remove_dir_all(&dir).unwrap();
}

/// Runs `cases` cases of `strategy` on `fixture`; a failure reports its smallest mutation. Returns
/// how far the reads got.
fn fuzz(
    cases: u32,
    fixture: &Path,
    name: &str,
    strategy: impl Strategy<Value = Mutation>,
    check: Check,
) -> Arc<Reach> {
    let reach = Arc::new(Reach::default());
    let mut runner = TestRunner::new(config(cases));
    let result = runner.run(&strategy, |m| {
        std::panic::catch_unwind(|| run_case(fixture, name, &m, check, &reach)).map_err(|p| {
            let msg = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            TestCaseError::fail(msg)
        })
    });
    if let Err(e) = result {
        panic!("{name}: {e}");
    }
    eprintln!("{name}: {reach}");
    reach
}

// ---------------------------------------------------------------------------------------------
// What must hold

/// A dataset read `Ok` is consistent; its scenario, a POD and the POD's model then run without a
/// panic or NaN.
fn check_dataset(dir: &Path, pass: &str, reach: &Reach) {
    bump(&reach.reads);
    let Ok(ds) = Dataset::load(dir).map_err(|e| e.to_string()) else {
        return;
    };
    bump(&reach.read_ok);
    let m = &ds.meta;
    let (n, p) = (m.samples, m.strain_x.len());
    let row = p * m.components.len();
    let lengths = [
        (ds.inputs.len(), n * m.parameters.len()),
        (ds.strain.len(), n * row),
        (ds.q.len(), n * m.n_dof),
        (ds.tip_position.len(), 3 * n),
        (ds.tip_rotation.len(), 9 * n),
        (ds.status.len(), n),
        (ds.iterations.len(), n),
        (ds.residual.len(), n),
        (ds.strain_x.len(), p),
    ];
    for (k, (got, expected)) in lengths.iter().enumerate() {
        assert_eq!(got, expected, "array {k} of a dataset read Ok");
    }
    let mut counts = [0usize; 3];
    for &s in &ds.status {
        assert!(s <= 2, "status {s} in a dataset read Ok");
        counts[s as usize] += 1;
    }
    assert_eq!(
        counts,
        [m.counts.ok, m.counts.failed, m.counts.not_computed],
        "counts of a dataset read Ok"
    );
    let d = m.parameters.len();
    for k in ds.ok_rows() {
        assert!(
            ds.strain_row(k).iter().all(|v| v.is_finite())
                && ds.inputs[k * d..(k + 1) * d].iter().all(|v| v.is_finite()),
            "usable row {k} of a dataset read Ok holds NaN: inputs {:?}",
            &ds.inputs[k * d..(k + 1) * d]
        );
    }
    for (j, (a, b)) in ds.strain_x.iter().zip(&m.strain_x).enumerate() {
        assert!(
            (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
            "point {j} of a dataset read Ok: strain_x.npy {a}, meta.json {b}"
        );
    }
    if gvsrom::reduce::dataset_scenario(&ds).is_err() {
        return;
    }
    let out = dir.with_file_name(format!(
        "{}-pod-{pass}",
        dir.file_name().unwrap().to_string_lossy()
    ));
    let _ = fs::remove_dir_all(&out);
    if let Ok(summary) = gvsrom::reduce::pod(&[dir], 1, gvsrom::reduce::PodNorm::Plain, &out, true)
    {
        assert!(
            summary.captured_energy.is_finite()
                && summary.singular_values.iter().all(|v| v.is_finite()),
            "POD of a dataset read Ok: captured energy {}, singular values {:?}",
            summary.captured_energy,
            summary.singular_values
        );
        bump(&reach.pod_ok);
        if let Err(e) = ReducedModel::load(&out) {
            panic!("the POD of a dataset read Ok wrote a model that does not load: {e}");
        }
        attach_and_solve(&out, reach);
    }
    let _ = fs::remove_dir_all(&out);
}

/// The `single-tendon` preset built, and its TOML table (as `--model` on `statics` takes them).
fn single_tendon() -> (gvsrom::Built, toml::Table) {
    let s = gvsrom::presets::load("single-tendon", &[]).unwrap();
    let built = gvsrom::build(&s).unwrap();
    let src = gvsrom::presets::source("single-tendon").unwrap();
    let table = gvsrom::scenario::parse_table(&src.origin, &src.text).unwrap();
    (built, table)
}

/// A model read `Ok` is consistent; attached to `single-tendon` (with and without
/// `--extrapolate`) it solves without a panic, or NaN in an `Ok`.
fn check_model(dir: &Path, _pass: &str, reach: &Reach) {
    bump(&reach.reads);
    let Ok(model) = ReducedModel::load(dir).map_err(|e| e.to_string()) else {
        return;
    };
    bump(&reach.read_ok);
    let m = &model.meta;
    let (features, r) = (m.layout.features(), m.latent);
    match &model.weights {
        ModelWeights::Pod { modes, .. } => {
            assert_eq!((modes.nrows(), modes.ncols()), (features, r), "POD modes");
            assert!(modes.iter().all(|v| v.is_finite()), "POD modes hold NaN");
        }
        ModelWeights::Autoencoder(ae) => {
            assert_eq!((ae.n_features(), ae.latent()), (features, r), "autoencoder")
        }
    }
    assert_eq!(m.rest.len(), r, "rest coordinates");
    assert!(m.latent_range.is_empty() || m.latent_range.len() == r);
    if let Some(a) = &model.anchors {
        assert_eq!(a.inputs.len(), a.n * m.anchor_parameters.len(), "anchors");
        assert_eq!(a.latent.len(), a.n * r, "anchor coordinates");
        assert!(
            a.inputs.iter().chain(&a.latent).all(|v| v.is_finite()),
            "anchors hold NaN"
        );
    }
    attach_and_solve(dir, reach);
}

/// The model in `dir` attached to `single-tendon` as `--model` does, with and without
/// `--extrapolate`, and solved once: an `Ok` solve is finite.
fn attach_and_solve(dir: &Path, reach: &Reach) {
    let (mut built, table) = single_tendon();
    for extrapolate in [false, true] {
        built.reduced = None;
        let options = gvsrom::reduce::AttachOptions {
            extrapolate,
            tensions_from_signal: false,
        };
        if gvsrom::reduce::attach(&mut built, &table, dir, options).is_err() {
            continue;
        }
        bump(&reach.attached);
        let Ok(report) = gvsrom::statics::solve_repeated(&built, 1) else {
            continue;
        };
        bump(&reach.solved);
        assert!(
            report.q.iter().all(|v| v.is_finite())
                && report.tip_position.iter().all(|v| v.is_finite())
                && report.residual_norm.is_finite(),
            "reduced statics Ok with NaN (extrapolate {extrapolate}): q {:?}, tip {:?}, residual {}",
            report.q,
            report.tip_position,
            report.residual_norm
        );
        let reduced = built.reduced.as_ref().unwrap();
        let _ = reduced.check_range(&report.q);
        let _ = reduced.rest_strain_offset();
    }
}

/// Some cases must get past the readers, or the target fuzzes nothing but the hash check.
fn assert_reached(name: &str, reach: &Reach, deep: &AtomicUsize) {
    let n = |c: &AtomicUsize| c.load(Ordering::Relaxed);
    assert!(
        n(&reach.read_ok) > 0 && n(deep) > 0,
        "{name}: no case got past the reader: {reach}"
    );
}

#[test]
fn dataset_reader_survives_byte_mutations() {
    let fixture = dataset();
    let name = "rfuzz-ds-bytes";
    let reach = fuzz(
        300,
        fixture,
        name,
        byte_mutation(files(fixture)),
        check_dataset,
    );
    assert_reached(name, &reach, &reach.pod_ok);
}

#[test]
fn dataset_reader_survives_json_mutations() {
    let name = "rfuzz-ds-json";
    let reach = fuzz(300, dataset(), name, json_mutation(), check_dataset);
    assert_reached(name, &reach, &reach.solved);
}

#[test]
fn model_readers_survive_byte_mutations() {
    for (fixture, name) in [
        (pod_model(), "rfuzz-pod-bytes"),
        (ae_model(), "rfuzz-ae-bytes"),
    ] {
        let reach = fuzz(
            200,
            fixture,
            name,
            byte_mutation(files(fixture)),
            check_model,
        );
        assert_reached(name, &reach, &reach.solved);
    }
}

#[test]
fn model_readers_survive_json_mutations() {
    for (fixture, name) in [
        (pod_model(), "rfuzz-pod-json"),
        (ae_model(), "rfuzz-ae-json"),
    ] {
        let reach = fuzz(200, fixture, name, json_mutation(), check_model);
        assert_reached(name, &reach, &reach.solved);
    }
}

// ---------------------------------------------------------------------------------------------
// What the fuzz targets found, kept as plain cases

/// A copy of `fixture` in the scratch directory `name` changed by `change` and resealed.
fn resealed(fixture: &Path, name: &str, change: impl FnOnce(&Path)) -> PathBuf {
    let dir = copy(fixture, name);
    change(&dir);
    common::reseal::reseal(&dir);
    dir
}

/// The first value of the data of `dir/file` (an `.npy` or the safetensors) set to NaN.
fn nan_first_value(dir: &Path, file: &str) {
    let path = dir.join(file);
    let mut b = fs::read(&path).unwrap();
    let i = data_start(file, &b);
    b[i..i + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    fs::write(&path, b).unwrap();
}

/// `Dataset::load` of `dir`: an error naming `file`; removes `dir`.
fn dataset_refused(dir: PathBuf, file: &str) -> String {
    let e = Dataset::load(&dir).expect_err("refused").to_string();
    assert!(e.contains(file), "{e}");
    fs::remove_dir_all(&dir).unwrap();
    e
}

#[test]
fn an_npy_shape_whose_product_overflows_is_refused_not_multiplied() {
    // npyz multiplies the dimensions in u64 unchecked: 2³¹ · 2³¹ · 4 = 2⁶⁴ panicked in builds
    // with overflow checks
    let header = ByteEdit::NpyHeader {
        descr: "<f8",
        fortran: false,
        shape: vec![1 << 31, 1 << 31, 4],
    };
    let dir = resealed(dataset(), "rfuzz-case-npy-shape", |d| {
        mutate(
            d,
            &Mutation::Bytes {
                file: "q.npy".into(),
                edits: vec![header],
            },
        )
    });
    let e = dataset_refused(dir, "q.npy");
    assert!(e.contains("64 bits"), "{e}");
}

#[test]
fn a_nan_abscissa_in_strain_x_npy_is_refused() {
    // `(a − b).abs() > tol` is false for NaN: the comparison with meta.json let it through
    let dir = resealed(dataset(), "rfuzz-case-strain-x", |d| {
        nan_first_value(d, "strain_x.npy")
    });
    let e = dataset_refused(dir, "strain_x.npy");
    assert!(e.contains("point 0 at NaN"), "{e}");
}

#[test]
fn a_nan_input_of_a_usable_sample_is_refused() {
    // read Ok, a POD of it then wrote a model whose anchors (and input range) cannot be loaded
    let dir = resealed(dataset(), "rfuzz-case-inputs", |d| {
        nan_first_value(d, "inputs.npy")
    });
    let e = dataset_refused(dir, "inputs.npy");
    assert!(e.contains("row 0 has status ok"), "{e}");
}

#[test]
fn an_input_outside_its_plans_range_is_refused() {
    // a corrupt input would widen the training inputs a model records, and so where it answers
    // without a warning (the hashes catch it in a dataset that records them: this one is resealed)
    let dir = resealed(dataset(), "rfuzz-case-input-range", |d| {
        let path = d.join("inputs.npy");
        let mut b = fs::read(&path).unwrap();
        let i = data_start("inputs.npy", &b);
        b[i..i + 8].copy_from_slice(&(-1e6f64).to_le_bytes());
        fs::write(&path, b).unwrap();
    });
    let e = dataset_refused(dir, "inputs.npy");
    assert!(
        e.contains("row 0 holds the input -1000000") && e.contains("outside the range"),
        "{e}"
    );
}

#[test]
fn a_nan_in_the_weights_of_a_pod_model_is_refused_naming_the_tensor() {
    // POD modes and anchors were read without a finiteness check (the MLPs' weights had one)
    let dir = resealed(pod_model(), "rfuzz-case-pod-nan", |d| {
        nan_first_value(d, "weights.safetensors")
    });
    let e = ReducedModel::load(&dir).expect_err("refused").to_string();
    assert!(
        e.contains("weights.safetensors: tensor `") && e.contains("holds NaN"),
        "{e}"
    );
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn safetensors_offsets_that_overflow_the_file_size_are_refused() {
    // eight 1-byte tensors of 2⁶¹ − 1 values each end at byte 2⁶⁴ − 8 of the data: safetensors
    // adds that to the header length unchecked, which panicked in builds with overflow checks
    let size = (1u64 << 61) - 1;
    let header: serde_json::Map<String, Value> = (0..8u64)
        .map(|k| {
            let info = serde_json::json!({
                "dtype": "U8",
                "shape": [size],
                "data_offsets": [k * size, (k + 1) * size],
            });
            (format!("t{k}"), info)
        })
        .collect();
    let text = serde_json::to_vec(&header).unwrap();
    let mut bytes = (text.len() as u64).to_le_bytes().to_vec();
    bytes.extend_from_slice(&text);
    let dir = resealed(pod_model(), "rfuzz-case-st-offsets", |d| {
        fs::write(d.join("weights.safetensors"), bytes).unwrap()
    });
    let e = ReducedModel::load(&dir).expect_err("refused").to_string();
    assert!(
        e.contains("weights.safetensors is damaged") && e.contains("data bytes"),
        "{e}"
    );
    fs::remove_dir_all(&dir).unwrap();
}
