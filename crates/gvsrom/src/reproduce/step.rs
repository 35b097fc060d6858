//! Pipeline steps that are saved, keyed and skipped (`gvsrom reproduce`).
//!
//! A step has a name (its place under `<out>/steps/`) and a *key*: the FNV-1a hash of its name, its
//! configuration and the keys of its inputs, as canonical JSON. Its output (a dataset, a model) is an
//! ordinary gvsrom output at `<out>/steps/<name>/`; its value (the numbers it measured) and its key
//! are recorded in `<out>/steps/<name>.step.json`, written *after* the output is in place. A step whose
//! record holds the same key, and whose output still loads, is reused; anything else is computed
//! again and replaces what the run wrote before. So an interrupted run resumes where it stopped (a
//! step killed half-way left at most a hidden staging directory and no record), and changing one
//! option recomputes only the steps whose keys it enters.

use crate::output::{OutputError, OutputFile, RunDir};
use crate::reduced_model::fnv1a64;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// The run was stopped by a signal (SIGINT, SIGTERM) between or inside steps; the steps finished
/// before it are kept. The CLI exits with `128 + signal`.
#[derive(Debug, thiserror::Error)]
#[error("interrupted by {}; the finished steps are kept in `{}` and a new run with the same options reuses them", signal_name(*.signal), .out.display())]
pub struct Interrupted {
    pub signal: usize,
    pub out: PathBuf,
}

fn signal_name(sig: usize) -> &'static str {
    match sig {
        2 => "SIGINT",
        15 => "SIGTERM",
        _ => "a signal",
    }
}

/// How one step went, for the reports.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct StepRecord {
    pub name: String,
    pub key: String,
    /// Wall time of the computation when it ran \[s\] (a reused step shows the time it took then).
    pub wall_time_s: f64,
    /// Reused from an earlier run (same key, output present).
    pub reused: bool,
}

impl StepRecord {
    /// The reports' order of steps: by name, with runs of digits compared as numbers (`pod-2`
    /// before `pod-10`), so that a report lists its steps the same way whatever order its parallel
    /// steps finished in.
    pub fn report_order(a: &StepRecord, b: &StepRecord) -> std::cmp::Ordering {
        natural_key(&a.name).cmp(&natural_key(&b.name))
    }
}

/// `name` cut into runs of digits (as numbers) and runs of other characters, for
/// [`StepRecord::report_order`].
fn natural_key(name: &str) -> Vec<(String, u128)> {
    let mut key: Vec<(String, u128)> = vec![];
    let mut text = String::new();
    let mut digits = String::new();
    for ch in name.chars() {
        if ch.is_ascii_digit() {
            digits.push(ch);
        } else {
            if !digits.is_empty() {
                key.push((
                    std::mem::take(&mut text),
                    digits.parse().unwrap_or(u128::MAX),
                ));
                digits.clear();
            }
            text.push(ch);
        }
    }
    key.push((text, digits.parse().unwrap_or(0)));
    key
}

/// A finished step: its value, where its output is, and its record.
#[derive(Debug, Clone)]
pub struct Step<T> {
    pub value: T,
    pub path: PathBuf,
    pub record: StepRecord,
}

impl<T> Step<T> {
    pub fn key(&self) -> &str {
        &self.record.key
    }
}

/// The state of one `reproduce` run: its directory (locked), the interrupt flag and the steps done.
pub struct Run {
    dir: RunDir,
    interrupt: Arc<AtomicUsize>,
    records: Mutex<Vec<StepRecord>>,
}

impl Run {
    pub fn new(dir: RunDir, interrupt: Arc<AtomicUsize>) -> Run {
        Run {
            dir,
            interrupt,
            records: Mutex::new(vec![]),
        }
    }

    /// The run directory.
    pub fn path(&self) -> &Path {
        self.dir.path()
    }

    /// The run directory, to write loose files such as `index.html`.
    pub fn dir_mut(&mut self) -> &mut RunDir {
        &mut self.dir
    }

    /// The interrupt flag (a signal number once SIGINT/SIGTERM arrived).
    pub fn interrupt(&self) -> &Arc<AtomicUsize> {
        &self.interrupt
    }

    /// An error if a signal arrived.
    pub fn check_interrupt(&self) -> Result<(), Interrupted> {
        match self.interrupt.load(Ordering::SeqCst) {
            0 => Ok(()),
            signal => Err(Interrupted {
                signal,
                out: self.path().to_path_buf(),
            }),
        }
    }

    /// Where step `name`'s output goes: `<out>/steps/<name>`.
    pub fn step_path(&self, name: &str) -> PathBuf {
        self.path().join("steps").join(name)
    }

    /// The records of the steps run or reused so far, in order.
    pub fn records(&self) -> Vec<StepRecord> {
        self.records.lock().map(|r| r.clone()).unwrap_or_default()
    }

    /// The records of the steps whose names start with `prefix`.
    pub fn records_of(&self, names: &[&str]) -> Vec<StepRecord> {
        self.records()
            .into_iter()
            .filter(|r| names.iter().any(|n| r.name == *n))
            .collect()
    }

    /// Runs (or reuses) step `name` with configuration `config` (which must include the keys of its
    /// inputs). `valid(path)` says whether an earlier output at the step's path is still usable;
    /// `compute(path)` writes the output there (through the output module, replacing an earlier
    /// gvsrom output) and returns the step's value.
    pub fn step<T, C>(
        &self,
        name: &str,
        config: &C,
        valid: impl Fn(&Path) -> bool,
        compute: impl FnOnce(&Path) -> anyhow::Result<T>,
    ) -> anyhow::Result<Step<T>>
    where
        T: Serialize + DeserializeOwned,
        C: Serialize + ?Sized,
    {
        self.check_interrupt()?;
        let key = step_key(name, config)?;
        let path = self.step_path(name);
        let record_path = self.record_path(name);
        if let Some((value, wall_time_s)) = read_record::<T>(&record_path, &key)? {
            if valid(&path) {
                return Ok(self.finish(name, key, wall_time_s, true, value, path));
            }
        }
        // the record goes first: a record without its output is never trusted (key checked above,
        // `valid` below), an output without its record is recomputed
        let record = OutputFile::create("--out", &record_path, RECORD_FORMAT, true)?;
        let t0 = Instant::now();
        let value = compute(&path)?;
        let wall_time_s = t0.elapsed().as_secs_f64();
        self.check_interrupt()?;
        record.commit_json(json!({
            "step": name,
            "key": key,
            "wall_time_s": wall_time_s,
            "value": serde_json::to_value(&value)?,
        }))?;
        Ok(self.finish(name, key, wall_time_s, false, value, path))
    }

    fn record_path(&self, name: &str) -> PathBuf {
        self.path().join("steps").join(format!("{name}.step.json"))
    }

    fn finish<T>(
        &self,
        name: &str,
        key: String,
        wall_time_s: f64,
        reused: bool,
        value: T,
        path: PathBuf,
    ) -> Step<T> {
        let record = StepRecord {
            name: name.to_string(),
            key,
            wall_time_s,
            reused,
        };
        if let Ok(mut r) = self.records.lock() {
            r.push(record.clone());
        }
        Step {
            value,
            path,
            record,
        }
    }
}

/// The manifest format of a step record.
const RECORD_FORMAT: &str = "reproduce-step";

/// The key of a step: FNV-1a of `{"step": name, "config": config, "version": crate version}` as
/// canonical JSON (object keys sorted).
pub fn step_key<C: Serialize + ?Sized>(name: &str, config: &C) -> Result<String, OutputError> {
    let value = json!({
        "step": name,
        "config": serde_json::to_value(config).map_err(|e| io_err(name, e))?,
        "version": env!("CARGO_PKG_VERSION"),
    });
    Ok(fnv1a64(canonical(&value).as_bytes()))
}

fn io_err(name: &str, e: serde_json::Error) -> OutputError {
    OutputError::Refused {
        option: "reproduce".into(),
        path: PathBuf::from(name),
        reason: format!("the step's configuration cannot be serialized: {e}"),
    }
}

/// JSON text with object keys sorted at every level (serde_json keeps insertion order here).
fn canonical(v: &Value) -> String {
    match v {
        Value::Object(m) => {
            let mut keys: Vec<&String> = m.keys().collect();
            keys.sort();
            let items: Vec<String> = keys
                .iter()
                .map(|k| format!("{}:{}", Value::from(k.as_str()), canonical(&m[*k])))
                .collect();
            format!("{{{}}}", items.join(","))
        }
        Value::Array(a) => format!(
            "[{}]",
            a.iter().map(canonical).collect::<Vec<_>>().join(",")
        ),
        other => other.to_string(),
    }
}

/// The value of the step record at `path` and its wall time (0 if not recorded), if gvsrom wrote
/// it (a manifest of format `reproduce-step` with the `meta_sha256` of its values) and it holds
/// `key`. A record that cannot be used (missing, not a regular file, not JSON, without that
/// manifest, another key) is `None`: the step is computed again (and [`OutputFile::create`]
/// refuses to replace one gvsrom did not write). One edited since gvsrom wrote it (its values no
/// longer match its `meta_sha256`) is an error: it is neither reused nor replaced.
fn read_record<T: DeserializeOwned>(path: &Path, key: &str) -> anyhow::Result<Option<(T, f64)>> {
    let Some(mut v) = crate::output::read_regular_to_string(path)
        .ok()
        .and_then(|text| serde_json::from_str::<Value>(&text).ok())
    else {
        return Ok(None);
    };
    if crate::output::json_file_edited(&v) {
        anyhow::bail!(
            "the step record `{}` was changed after gvsrom wrote it (its values no longer match the `meta_sha256` of its manifest): reproduce neither reuses nor replaces it; restore it to reuse it, or move it away and the step is computed again",
            path.display()
        );
    }
    let manifest = v.get(crate::output::MANIFEST_KEY);
    let ours = manifest
        .and_then(|m| m.get("format"))
        .and_then(Value::as_str)
        == Some(RECORD_FORMAT)
        && manifest.is_some_and(|m| m.get("meta_sha256").is_some());
    if !ours || v.get("key").and_then(Value::as_str) != Some(key) {
        return Ok(None);
    }
    let wall_time_s = v.get("wall_time_s").and_then(Value::as_f64).unwrap_or(0.0);
    let Some(value) = v
        .get_mut("value")
        .and_then(|x| serde_json::from_value(x.take()).ok())
    else {
        return Ok(None);
    };
    Ok(Some((value, wall_time_s)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_key_ignores_key_order_and_changes_with_any_value() {
        let a = step_key("s", &json!({"a": 1, "b": [1.5, 2]})).unwrap();
        let b = step_key("s", &json!({"b": [1.5, 2], "a": 1})).unwrap();
        let c = step_key("s", &json!({"a": 1, "b": [1.5, 3]})).unwrap();
        let d = step_key("t", &json!({"a": 1, "b": [1.5, 2]})).unwrap();
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_ne!(a, d);
    }

    #[test]
    fn reports_list_steps_by_name_with_numbers_compared_as_numbers() {
        let names = [
            "iv-b/pod-10",
            "iv-b/pod-2",
            "iv-b/dataset",
            "iv-b/ae-r2-h7-scaled-seed1",
            "iv-b/ae-r1-h7",
            "iv-b/ae-r10-h3",
            "iv-b/ae-r2-h7",
            "iv-b/pod-1",
        ];
        let mut records: Vec<StepRecord> = names
            .iter()
            .map(|n| StepRecord {
                name: n.to_string(),
                key: String::new(),
                wall_time_s: 0.0,
                reused: true,
            })
            .collect();
        records.sort_by(StepRecord::report_order);
        let sorted: Vec<&str> = records.iter().map(|r| r.name.as_str()).collect();
        assert_eq!(
            sorted,
            [
                "iv-b/ae-r1-h7",
                "iv-b/ae-r2-h7",
                "iv-b/ae-r2-h7-scaled-seed1",
                "iv-b/ae-r10-h3",
                "iv-b/dataset",
                "iv-b/pod-1",
                "iv-b/pod-2",
                "iv-b/pod-10",
            ]
        );
    }

    #[test]
    fn a_record_is_reused_only_with_its_key_and_a_fifo_in_its_place_is_not_waited_on() {
        let dir = crate::output::test_util::sandbox("step", "record");
        let record = dir.join("s.step.json");
        let text = json!({"step": "s", "key": "k1", "wall_time_s": 2.5, "value": [1, 2]});
        // without gvsrom's manifest it is not a record: not reused
        std::fs::write(&record, text.to_string()).unwrap();
        assert_eq!(read_record::<Vec<u32>>(&record, "k1").unwrap(), None);
        std::fs::remove_file(&record).unwrap();
        OutputFile::create("--out", &record, RECORD_FORMAT, true)
            .unwrap()
            .commit_json(text)
            .unwrap();
        assert_eq!(
            read_record::<Vec<u32>>(&record, "k1").unwrap(),
            Some((vec![1, 2], 2.5))
        );
        assert_eq!(read_record::<Vec<u32>>(&record, "k2").unwrap(), None);
        #[cfg(target_os = "linux")]
        {
            let pipe = dir.join("p.step.json");
            crate::output::test_util::fifo(&pipe);
            // no writer ever opens it: a plain read would block this test forever
            assert_eq!(read_record::<Vec<u32>>(&pipe, "k1").unwrap(), None);
        }
    }

    #[test]
    fn a_record_edited_since_it_was_written_is_neither_reused_nor_replaced() {
        // a review edited a tip in a record of `reproduce v`, and the report then showed it
        let dir = crate::output::test_util::sandbox("step", "edited");
        let record = dir.join("s.step.json");
        let out = OutputFile::create("--out", &record, "reproduce-step", true).unwrap();
        out.commit_json(json!({"step": "s", "key": "k1", "wall_time_s": 2.5, "value": [1, 2]}))
            .unwrap();
        assert_eq!(
            read_record::<Vec<u32>>(&record, "k1").unwrap(),
            Some((vec![1, 2], 2.5))
        );
        let text = std::fs::read_to_string(&record).unwrap();
        let edited = text.replacen("2.5", "2.25", 1);
        assert_ne!(edited, text);
        std::fs::write(&record, &edited).unwrap();
        let e = read_record::<Vec<u32>>(&record, "k1")
            .unwrap_err()
            .to_string();
        assert!(e.contains("was changed after gvsrom wrote it"), "{e}");
        // nor does another key make it replaceable
        assert!(read_record::<Vec<u32>>(&record, "k2").is_err());
        assert_eq!(std::fs::read_to_string(&record).unwrap(), edited);
        // a mangled or removed hash does not make the edit reusable
        let mangled = edited.replacen("\"meta_sha256\":\"", "\"meta_sha256\":\"x", 1);
        assert_ne!(mangled, edited);
        std::fs::write(&record, &mangled).unwrap();
        assert!(read_record::<Vec<u32>>(&record, "k1").is_err());
        let mut v: Value = serde_json::from_str(&edited).unwrap();
        v["gvsrom"].as_object_mut().unwrap().remove("meta_sha256");
        std::fs::write(&record, v.to_string()).unwrap();
        assert_eq!(read_record::<Vec<u32>>(&record, "k1").unwrap(), None);
        v.as_object_mut().unwrap().remove("gvsrom");
        std::fs::write(&record, v.to_string()).unwrap();
        assert_eq!(read_record::<Vec<u32>>(&record, "k1").unwrap(), None);
    }
}
