//! `--set path=value` overrides, applied to the parsed TOML table before it is read into the
//! types: missing tables on the path are created, a list index may append one entry, and every
//! error names the path and what is there instead.

use super::path::{every_entry, parse_path, render_path, Seg};
use crate::error::ScenarioError;
use toml::{Table, Value};

/// A key segment meant as a list index that is not a valid one: a signed integer or one too large
/// for an index (`-1`, `-0`, `99999999999999999999999`).
fn looks_like_index(key: &str) -> bool {
    let digits = key.trim_start_matches(['-', '+']);
    !digits.is_empty() && digits.chars().all(|c| c.is_ascii_digit())
}

/// Parses the right-hand side of `--set` as a TOML value (number, bool, array, inline table,
/// quoted string). A number TOML does not write (`.5`, `5.`, `1e999`, which overflows to
/// infinity and is then refused as not finite) is read as Rust reads a float; anything else that
/// is not valid TOML is taken as a bare string (`--set magnus=z2`).
fn parse_value(raw: &str) -> Value {
    let raw = raw.trim();
    match format!("v = {raw}").parse::<Table>() {
        Ok(mut t) => t
            .remove("v")
            .unwrap_or_else(|| Value::String(raw.to_string())),
        Err(_) => match raw.parse::<f64>() {
            Ok(x) if raw.bytes().any(|b| b.is_ascii_digit()) => Value::Float(x),
            _ => Value::String(raw.to_string()),
        },
    }
}

/// Most segments in a `--set` key path. The deepest key of the format has 5
/// (`divisions[0].basis.orders.bend_y`); the limit keeps a path of thousands of segments from
/// building a tree as deep, whose recursive walks would overflow the stack.
pub const MAX_OVERRIDE_SEGMENTS: usize = 16;

/// Applies one `path=value` override. Missing tables on the path are created (the deserializer
/// then rejects keys the format does not know, naming the path); a list index may be at most the
/// list's length (equal appends a new entry).
pub fn apply_override(table: &mut Table, spec: &str) -> Result<(), ScenarioError> {
    let err = |message: String| ScenarioError::Override {
        spec: spec.to_string(),
        message,
    };
    let (path, raw) = spec
        .split_once('=')
        .ok_or_else(|| err("expected `path=value`, e.g. `tendons.0.tension=-2`".into()))?;
    if let Some(each) = every_entry(table, path.trim()).map_err(&err)? {
        // applied to a copy, so that a failing entry leaves the scenario as it was
        let mut changed = table.clone();
        for p in each {
            apply_override(&mut changed, &format!("{p}={raw}")).map_err(|e| match e {
                ScenarioError::Override { message, .. } => err(format!("{p}: {message}")),
                other => other,
            })?;
        }
        *table = changed;
        return Ok(());
    }
    let segs = parse_path(path.trim()).map_err(&err)?;
    if segs.len() > MAX_OVERRIDE_SEGMENTS {
        return Err(err(format!(
            "the key path has {} segments (accepted: at most {MAX_OVERRIDE_SEGMENTS})",
            segs.len()
        )));
    }
    let Some(Seg::Key(_)) = segs.first() else {
        return Err(err("the path must start with a key".into()));
    };
    let value = parse_value(raw);
    let shape = section_shape(&segs, &value);
    let mut root = Value::Table(std::mem::take(table));
    let r = set_at(&mut root, &segs, 0, value);
    if let Value::Table(t) = root {
        *table = t;
    }
    r.map_err(err)?;
    if let Some((j, shape)) = shape {
        drop_other_shape(table, j, &shape);
    }
    Ok(())
}

/// The keys that size a circular section (a tube's bore too), and those that size a rectangle or
/// an ellipse.
const CIRCLE_KEYS: [&str; 6] = [
    "radius",
    "radius_start",
    "radius_end",
    "inner_radius",
    "inner_radius_start",
    "inner_radius_end",
];
const BOX_KEYS: [&str; 6] = [
    "width",
    "width_start",
    "width_end",
    "height",
    "height_start",
    "height_end",
];

/// `Some((j, shape))` for an override of `divisions.j.section` to a string.
fn section_shape(segs: &[Seg], value: &Value) -> Option<(usize, String)> {
    match (segs, value) {
        ([Seg::Key(d), Seg::Index(j), Seg::Key(k)], Value::String(shape))
            if d == "divisions" && k == "section" =>
        {
            Some((*j, shape.clone()))
        }
        _ => None,
    }
}

/// An override of a division's `section` replaces the description of the section it had: a
/// rectangle or an ellipse drops the circle's radii (and a tube's inner radii), a circle the rectangle's widths and heights
/// (`--set divisions.0.section=rectangle --set divisions.0.width=0.03 --set
/// divisions.0.height=0.01` on a preset of circular sections). An unknown shape keeps both, for
/// the format's error to name it.
fn drop_other_shape(table: &mut Table, j: usize, shape: &str) {
    let dropped: &[&str] = match shape {
        "rectangle" | "ellipse" => &CIRCLE_KEYS,
        "circle" => &BOX_KEYS,
        _ => return,
    };
    let division = (table.get_mut("divisions"))
        .and_then(Value::as_array_mut)
        .and_then(|a| a.get_mut(j))
        .and_then(Value::as_table_mut);
    if let Some(d) = division {
        for k in dropped {
            d.remove(*k);
        }
    }
}

fn set_at(node: &mut Value, segs: &[Seg], depth: usize, value: Value) -> Result<(), String> {
    let here = || {
        if depth == 0 {
            "the scenario".to_string()
        } else {
            format!("`{}`", render_path(&segs[..depth]))
        }
    };
    let last = depth + 1 == segs.len();
    match (&segs[depth], node) {
        (Seg::Key(k), Value::Table(t)) => {
            if last {
                t.insert(k.clone(), value);
                return Ok(());
            }
            let child = t.entry(k.clone()).or_insert_with(|| match &segs[depth + 1] {
                Seg::Key(k) if !looks_like_index(k) => Value::Table(Table::new()),
                _ => Value::Array(Vec::new()),
            });
            set_at(child, segs, depth + 1, value)
        }
        (Seg::Index(i), Value::Array(a)) => {
            let i = *i;
            if i > a.len() {
                return Err(format!(
                    "index {i} is out of range: {} has {} entries (use index {} to append one)",
                    here(),
                    a.len(),
                    a.len()
                ));
            }
            if last {
                if i == a.len() {
                    a.push(value);
                } else {
                    a[i] = value;
                }
                return Ok(());
            }
            if i == a.len() {
                a.push(match segs[depth + 1] {
                    Seg::Key(_) => Value::Table(Table::new()),
                    Seg::Index(_) => Value::Array(Vec::new()),
                });
            }
            set_at(&mut a[i], segs, depth + 1, value)
        }
        (Seg::Index(i), Value::Table(_)) => Err(format!(
            "{} is a table, not a list: it has no index {i}",
            here()
        )),
        (Seg::Key(k), Value::Array(a)) if looks_like_index(k) => Err(format!(
            "`{k}` is not a valid index of {}: indices are 0-based non-negative integers and the list has {} entries ({})",
            here(),
            a.len(),
            match a.len() {
                0 => "give 0 to add the first".to_string(),
                1 => "0 changes it, 1 appends one".to_string(),
                n => format!("0 to {} change one, {n} appends one", n - 1),
            }
        )),
        (Seg::Key(k), Value::Array(_)) => Err(format!(
            "{} is a list: give an index before `{k}` (e.g. `{}.0.{k}`)",
            here(),
            render_path(&segs[..depth])
        )),
        (_, other) => Err(format!(
            "{} is a {}, it has no `{}`",
            here(),
            other.type_str(),
            render_path(&segs[depth..=depth]).trim_start_matches('.')
        )),
    }
}
