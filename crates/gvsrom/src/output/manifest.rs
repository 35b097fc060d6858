//! The `"gvsrom"` manifest object of an output (rule 2 of [`super`]): written at the top of every
//! output's JSON, and read back from an existing output to recognise it.

use super::MANIFEST_KEY;
use serde::Serialize;
use serde_json::{Map, Value};
use std::io;
use std::path::Path;

/// The manifest object written with every output.
pub(super) fn manifest(format: &str, files: Option<&[String]>) -> Value {
    let mut m = Map::new();
    m.insert("format".into(), Value::from(format));
    m.insert("version".into(), Value::from(env!("CARGO_PKG_VERSION")));
    if let Some(files) = files {
        m.insert("files".into(), Value::from(files.to_vec()));
    }
    Value::Object(m)
}

/// Puts `manifest` under [`MANIFEST_KEY`] at the top of `value` (which must serialize to an object).
pub(super) fn with_manifest(value: impl Serialize, manifest: Value) -> io::Result<Value> {
    match serde_json::to_value(value)? {
        Value::Object(mut map) => {
            let mut out = Map::new();
            out.insert(MANIFEST_KEY.into(), manifest);
            out.append(&mut map);
            Ok(Value::Object(out))
        }
        _ => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "output metadata must be a JSON object",
        )),
    }
}

/// Reads the manifest of an existing output: the `"gvsrom"` object of `json_path`, and its `files`
/// (only a directory output's manifest has them).
pub(super) fn read_manifest(json_path: &Path) -> Option<(String, Option<Vec<String>>)> {
    let text = super::read::read_regular_to_string(json_path).ok()?;
    let value: Value = serde_json::from_str(&text).ok()?;
    let m = value.get(MANIFEST_KEY)?.as_object()?;
    let format = m.get("format")?.as_str()?.to_string();
    let files = match m.get("files") {
        Some(Value::Array(a)) => Some(
            a.iter()
                .map(|f| f.as_str().map(str::to_string))
                .collect::<Option<Vec<_>>>()?,
        ),
        None => None,
        Some(_) => return None,
    };
    Some((format, files))
}
