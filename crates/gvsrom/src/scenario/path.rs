//! Key paths of the scenario format (`tendons.0.tension`, `divisions[0].basis.order`): parsing,
//! rendering, and the value a path names in a table.

use toml::{Table, Value};

/// A segment of a key path.
#[derive(Debug, Clone, PartialEq)]
pub enum Seg {
    Key(String),
    Index(usize),
}

/// `a.b[0].c`
pub fn render_path(path: &[Seg]) -> String {
    let mut s = String::new();
    for seg in path {
        match seg {
            Seg::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Seg::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// Parses `tendons.0.tension`, `tendons[0].tension` or `loads.gravity[2]` into segments. A purely
/// numeric dotted segment is an index.
pub fn parse_path(path: &str) -> Result<Vec<Seg>, String> {
    let mut segs = Vec::new();
    for part in path.split('.') {
        if part.is_empty() {
            return Err("empty segment in the key path".into());
        }
        let (key, mut rest) = match part.find('[') {
            Some(p) => (&part[..p], &part[p..]),
            None => (part, ""),
        };
        if !key.is_empty() {
            match key.parse::<usize>() {
                Ok(i) => segs.push(Seg::Index(i)),
                Err(_) => segs.push(Seg::Key(key.to_string())),
            }
        } else if rest.is_empty() {
            return Err("empty segment in the key path".into());
        }
        while !rest.is_empty() {
            let close = rest
                .find(']')
                .ok_or_else(|| format!("unclosed `[` in `{part}`"))?;
            let idx = rest[1..close].parse::<usize>().map_err(|_| {
                format!(
                    "`{}` is not a list index (indices are 0-based non-negative integers)",
                    &rest[1..close]
                )
            })?;
            segs.push(Seg::Index(idx));
            rest = &rest[close + 1..];
            if !rest.is_empty() && !rest.starts_with('[') {
                return Err(format!("unexpected `{rest}` after an index in `{part}`"));
            }
        }
    }
    Ok(segs)
}

/// The number at the dotted `path` (`tendons.0.tension`) in `table`, if there is one (an integer
/// read as a float).
pub fn number_at(table: &Table, path: &str) -> Option<f64> {
    match lookup(table, &parse_path(path).ok()?)? {
        Value::Float(v) => Some(*v),
        Value::Integer(v) => Some(*v as f64),
        _ => None,
    }
}

/// The value at `path` in `table`, if there is one.
pub fn lookup<'a>(table: &'a Table, path: &[Seg]) -> Option<&'a Value> {
    let (first, rest) = path.split_first()?;
    let Seg::Key(k) = first else { return None };
    let mut node = table.get(k)?;
    for seg in rest {
        node = match (seg, node) {
            (Seg::Key(k), Value::Table(t)) => t.get(k)?,
            (Seg::Index(i), Value::Array(a)) => a.get(*i)?,
            _ => return None,
        };
    }
    Some(node)
}

/// The paths a `*` segment stands for, in `--set` and in a dataset's plans: every entry of the
/// list before it (`tendons.*.tension`, or `tendons[*].tension`, is `tendons.0.tension`,
/// `tendons.1.tension`, …); `None` for a path without one. Only the first `*` is expanded (an
/// override expands a later one by each path's own override).
pub fn every_entry(table: &Table, path: &str) -> Result<Option<Vec<String>>, String> {
    // `tendons[*].tension` as `tendons.*.tension`, as an index may be written either way
    let path = path.replace("[*]", ".*");
    let parts: Vec<&str> = path.split('.').filter(|p| !p.is_empty()).collect();
    let Some(i) = parts.iter().position(|p| *p == "*") else {
        return Ok(None);
    };
    let prefix = parts[..i].join(".");
    if prefix.is_empty() {
        return Err("`*` must follow the path of a list (e.g. `tendons.*.tension`)".into());
    }
    let n = match lookup(table, &parse_path(&prefix)?) {
        Some(Value::Array(a)) if !a.is_empty() => a.len(),
        Some(Value::Array(_)) => {
            return Err(format!(
                "the list `{prefix}` is empty: `*` stands for every entry of a list"
            ))
        }
        Some(_) => {
            return Err(format!(
                "`{prefix}` is not a list: `*` stands for every entry of a list"
            ))
        }
        None => {
            return Err(format!(
                "the scenario has no list `{prefix}` for `*` to stand for"
            ))
        }
    };
    let rest = parts[i + 1..].join(".");
    Ok(Some(
        (0..n)
            .map(|k| match rest.is_empty() {
                true => format!("{prefix}.{k}"),
                false => format!("{prefix}.{k}.{rest}"),
            })
            .collect(),
    ))
}
