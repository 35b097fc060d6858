//! Reading a scenario: TOML text → `toml::Table` (syntax errors on one line, with line and column)
//! → `--set` overrides → a check that no number is NaN or infinite → [`Scenario`] (type errors
//! name the key's path); and the resolved scenario back to a table or TOML text.

use super::overrides::apply_override;
use super::path::{render_path, Seg};
use super::types::Scenario;
use crate::error::ScenarioError;
use toml::{Table, Value};

impl Scenario {
    /// Parses a scenario from TOML text with `--set` overrides applied. `source_name` names the
    /// text in syntax errors (a path or a preset name).
    pub fn from_toml(
        source_name: &str,
        text: &str,
        overrides: &[String],
    ) -> Result<Scenario, ScenarioError> {
        let mut table = parse_table(source_name, text)?;
        for spec in overrides {
            apply_override(&mut table, spec)?;
        }
        from_table(table)
    }

    /// The resolved scenario as a TOML table: every field, defaults filled in, `--set` overrides
    /// applied. Parsing it back gives the same scenario.
    pub fn to_table(&self) -> Result<Table, ScenarioError> {
        Table::try_from(self).map_err(|e| ScenarioError::invalid("scenario", e.to_string()))
    }

    /// [`Self::to_table`] as TOML text.
    pub fn to_toml(&self) -> Result<String, ScenarioError> {
        toml::to_string(&self.to_table()?)
            .map_err(|e| ScenarioError::invalid("scenario", e.to_string()))
    }
}

/// TOML text → table; syntax errors carry line and column.
pub fn parse_table(source_name: &str, text: &str) -> Result<Table, ScenarioError> {
    text.parse::<Table>().map_err(|e| {
        let mut message = one_line(&e.to_string());
        // toml names neither the key given twice nor what is wrong with it: its span does
        let key = e.span().and_then(|span| text.get(span)).map(str::trim);
        if let (true, Some(key)) = (message.ends_with("duplicate key"), key) {
            message = format!("{message} `{key}` (each key once per table)");
        }
        ScenarioError::Syntax {
            source_name: source_name.to_string(),
            message,
        }
    })
}

/// Table → [`Scenario`], after checking that no number is NaN or infinite. Errors name the key path.
pub fn from_table(table: Table) -> Result<Scenario, ScenarioError> {
    let value = Value::Table(table);
    check_finite(&value, &mut Vec::new())?;
    // kept for a second reading of a misnamed enum (`name_expected`)
    let original = value.clone();
    serde_path_to_error::deserialize::<_, Scenario>(value).map_err(|e| {
        let mut field = e.path().to_string();
        let message = e
            .inner()
            .message()
            .replace("expected usize", "expected an integer >= 0")
            .replace("expected f64", "expected a number");
        let message = match message == ENUM_NOT_A_STRING {
            true => name_expected(original, e.path()).unwrap_or(message),
            false => without_type_names(message),
        };
        // Inside tagged tables (`kind = ...`) the path stops at the table: add the unknown key.
        if let Some(key) = message
            .strip_prefix("unknown field `")
            .and_then(|m| m.split('`').next())
        {
            if !field.ends_with(&format!(".{key}")) && field != key {
                field = if field == "." || field.is_empty() {
                    key.to_string()
                } else {
                    format!("{field}.{key}")
                };
            }
        }
        let message = array_length_message(&field, message);
        if field == "." || field.is_empty() {
            // a required key missing at the top: name it, not the path `.`
            match message
                .strip_prefix("missing field `")
                .and_then(|m| m.split('`').next())
            {
                Some(key) => {
                    return ScenarioError::Format {
                        field: key.to_string(),
                        message: "missing: a required key at the top level of the scenario"
                            .to_string(),
                    }
                }
                None => field = "(top level)".to_string(),
            }
        }
        ScenarioError::Format { field, message }
    })
}

/// serde's message for a fixed-size array of the wrong length, with the length and form the key
/// takes: a list too long reads "expected fewer elements in array", which does not say how many;
/// a tendon's offset, often given as the 3-vector `[0, y, z]` of the spec's `d(X)`, says that
/// it is `[y, z]`.
fn array_length_message(field: &str, message: String) -> String {
    if !message.starts_with("invalid length ") {
        return message;
    }
    // the key, and the index of a row in `path` or `rotation`
    let last = field.rsplit('.').next().unwrap_or(field);
    let leaf = last.split('[').next().unwrap_or(last);
    // a row of `rotation` or `path` (`base.rotation[1]`), not the list of rows
    let row = last.ends_with(']');
    let form = match leaf {
        "rotation" if row => "3 values: a row of the rotation matrix",
        "path" if row => "3 values `[X, y, z]` [m]: a knot's abscissa and offset",
        "offset_start" | "offset_end" => {
            "2 values `[y, z]` [m]: the offset in the section's plane (y and z of the section frame; the tendon's abscissa is its x)"
        }
        "position" | "force" | "moment" | "gravity" | "axis" => "3 values `[x, y, z]`",
        "center" => "3 values `[x, y, z]` [m]: the centre of mass in the section frame (x along the rod)",
        "path" => "rows of 3 values `[X, y, z]` [m]: the knots' abscissae and offsets",
        "rotation" => "3 rows of 3 values",
        "reference_strain" => {
            "6 values `[torsion, bend_y, bend_z, elongation, shear_y, shear_z]`"
        }
        _ => return message,
    };
    let given = message
        .strip_prefix("invalid length ")
        .and_then(|m| m.split(',').next())
        .unwrap_or("?");
    let values = if given == "1" { "value" } else { "values" };
    format!("{given} {values} given; expected {form}")
}

/// serde's "expected struct MaterialSpec" names a Rust type: the user wrote a TOML table there.
fn without_type_names(message: String) -> String {
    match message.split_once("expected struct ") {
        Some((before, rest)) => {
            let after = rest.trim_start_matches(|c: char| c.is_alphanumeric() || c == '_');
            format!("{before}expected a table (`[…]` or `{{ key = value, … }}`){after}")
        }
        None => message,
    }
}

/// toml's message for a value that is not a string where a name (an enum) is read: it names
/// neither the value given nor the names accepted.
const ENUM_NOT_A_STRING: &str = "invalid type: unit variant, expected string only";

/// The message for a key at `path` that takes a name (`section = "rectangle"`) but was given
/// another value (`section = 3`): the value, and the names accepted, learned by reading the
/// scenario again with an empty name in its place (serde then lists the names). `None` if the
/// path cannot be followed or the second reading says something else.
fn name_expected(mut root: Value, path: &serde_path_to_error::Path) -> Option<String> {
    use serde_path_to_error::Segment;
    let mut at = &mut root;
    for seg in path.iter() {
        at = match (seg, at) {
            (Segment::Map { key }, Value::Table(t)) => t.get_mut(key)?,
            (Segment::Seq { index }, Value::Array(a)) => a.get_mut(*index)?,
            _ => return None,
        };
    }
    let given = match at {
        Value::String(_) => return None,
        Value::Integer(i) => format!("the integer {i}"),
        Value::Float(x) => format!("the number {x}"),
        Value::Boolean(b) => format!("`{b}`"),
        Value::Datetime(d) => format!("the date {d}"),
        Value::Array(_) => "a list".to_string(),
        Value::Table(_) => "a table".to_string(),
    };
    *at = Value::String(String::new());
    let again = serde_path_to_error::deserialize::<_, Scenario>(root).err()?;
    let names = (again.path().to_string() == path.to_string())
        .then(|| again.inner().message())?
        .split_once("expected ")?
        .1
        .to_string();
    Some(format!("{given} given; expected a name in quotes, {names}"))
}

/// Rejects NaN and ±inf anywhere in the tree (TOML allows `nan` and `inf`).
fn check_finite(v: &Value, path: &mut Vec<Seg>) -> Result<(), ScenarioError> {
    match v {
        Value::Float(x) if !x.is_finite() => Err(ScenarioError::value(
            render_path(path),
            *x,
            "a finite number",
        )),
        Value::Table(t) => {
            for (k, v) in t {
                path.push(Seg::Key(k.clone()));
                check_finite(v, path)?;
                path.pop();
            }
            Ok(())
        }
        Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                path.push(Seg::Index(i));
                check_finite(v, path)?;
                path.pop();
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// Collapses a multi-line error (toml's source excerpt with carets) into one line, keeping the
/// position and the message.
fn one_line(s: &str) -> String {
    let is_excerpt = |l: &str| {
        let rest = l
            .trim_start_matches(|c: char| c.is_ascii_digit())
            .trim_start();
        rest.starts_with('|') || l.chars().all(|c| c == '^' || c == ' ')
    };
    let lines: Vec<&str> = s
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !is_excerpt(l))
        .collect();
    lines.join(": ")
}
