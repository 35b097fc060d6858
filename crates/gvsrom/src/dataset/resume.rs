//! `--resume`: the incomplete dataset to continue, checked against this run, and its finished rows.

use super::generate::SampleResult;
use super::{Dataset, DatasetError, Meta};
use std::path::Path;
use toml::{Table, Value};

/// The incomplete dataset at `path`, checked to be a continuation of `meta`'s run.
pub(super) fn resumable(path: &Path, meta: &Meta) -> Result<Dataset, DatasetError> {
    let shown = path.display().to_string();
    let resume = |message: String| DatasetError::Resume {
        path: shown.clone(),
        message,
    };
    if !path.exists() {
        return Err(resume(
            "there is no dataset to resume (run without --resume to start one)".into(),
        ));
    }
    let prev = Dataset::load(path).map_err(|e| resume(format!("cannot be resumed: {e}")))?;
    let p = &prev.meta;
    if p.complete {
        return Err(resume(
            "the dataset is already complete: nothing to resume".into(),
        ));
    }
    let differs = |what: &str, old: String, new: String| {
        resume(format!(
            "the {what} differs from the incomplete dataset's ({old} there, {new} now); rerun with the same arguments, or use --force instead of --resume to start again"
        ))
    };
    if p.scenario_toml != meta.scenario_toml && !same_tables(&p.scenario_toml, &meta.scenario_toml)
    {
        let what = match toml_difference(&p.scenario_toml, &meta.scenario_toml) {
            Some((path, old, new)) => format!(
                "scenario (after --set): `{path}` differs from the incomplete dataset's ({old} there, {new} now)"
            ),
            None => format!(
                "scenario (after --set) differs from the incomplete dataset's (`{}` there, `{}` now)",
                p.scenario, meta.scenario
            ),
        };
        return Err(resume(format!(
            "the {what}; rerun with the same arguments, or use --force instead of --resume to start again"
        )));
    }
    let (Some(a), Some(b)) = (&p.plan, &meta.plan) else {
        return Err(resume(
            "only static datasets can be resumed: rerun a dynamic dataset with --force".into(),
        ));
    };
    if a.kind != b.kind || a.specs != b.specs {
        return Err(differs(
            "plan",
            format!("{} {}", a.kind.option(), a.specs.join(" ")),
            format!("{} {}", b.kind.option(), b.specs.join(" ")),
        ));
    }
    if a.samples != b.samples {
        return Err(differs(
            "--samples",
            a.samples.to_string(),
            b.samples.to_string(),
        ));
    }
    if p.seed != meta.seed {
        return Err(differs("--seed", p.seed.to_string(), meta.seed.to_string()));
    }
    if p.chunk_size != meta.chunk_size {
        return Err(differs(
            "--chunk-size",
            p.chunk_size.to_string(),
            meta.chunk_size.to_string(),
        ));
    }
    if p.q_order != meta.q_order {
        return Err(differs(
            "order of the coordinates in q.npy (q_order)",
            format!("`{}`", p.q_order),
            format!("`{}`", meta.q_order),
        ));
    }
    if p.parameters != meta.parameters
        || p.components != meta.components
        || p.n_dof != meta.n_dof
        || prev.strain_x.len() != meta.strain_x.len()
        || prev
            .strain_x
            .iter()
            .zip(&meta.strain_x)
            .any(|(x, y)| x.to_bits() != y.to_bits())
    {
        return Err(resume(
            "its parameters or point layout differ from this run's; use --force instead of --resume to start again".into(),
        ));
    }
    Ok(prev)
}

/// The first value that differs between two resolved scenario TOMLs: its key path
/// (`divisions[0].radius_end`) and both values (`missing` where absent); `None` if either text does
/// not parse or they are equal as tables.
fn toml_difference(old: &str, new: &str) -> Option<(String, String, String)> {
    let old = Value::Table(old.parse::<Table>().ok()?);
    let new = Value::Table(new.parse::<Table>().ok()?);
    difference_at(&old, &new, String::new())
}

/// Whether two scenario TOMLs hold the same values (an integer equal to a float, `1000` and
/// `1000.0`, counts as the same: the scenario reads both as the real number), though their texts
/// differ.
fn same_tables(old: &str, new: &str) -> bool {
    match (old.parse::<Table>(), new.parse::<Table>()) {
        (Ok(a), Ok(b)) => {
            difference_at(&Value::Table(a), &Value::Table(b), String::new()).is_none()
        }
        _ => false,
    }
}

fn difference_at(a: &Value, b: &Value, path: String) -> Option<(String, String, String)> {
    let shown = |v: Option<&Value>| v.map_or_else(|| "missing".to_string(), |v| v.to_string());
    let child = |key: &str| match path.is_empty() {
        true => key.to_string(),
        false => format!("{path}.{key}"),
    };
    match (a, b) {
        (Value::Table(x), Value::Table(y)) => {
            let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
            keys.into_iter().find_map(|k| match (x.get(k), y.get(k)) {
                (Some(u), Some(v)) => difference_at(u, v, child(k)),
                (u, v) => Some((child(k), shown(u), shown(v))),
            })
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .find_map(|(i, (u, v))| difference_at(u, v, format!("{path}[{i}]"))),
        (Value::Integer(i), Value::Float(f)) | (Value::Float(f), Value::Integer(i))
            if *i as f64 == *f =>
        {
            None
        }
        _ if a == b => None,
        _ => Some((path, shown(Some(a)), shown(Some(b)))),
    }
}

/// Sample `k` as stored in a previous dataset. `lengths_of(k, q)`: the tendons' lengths of a solved
/// sample that a dataset written before they were recorded does not hold.
pub(super) fn from_previous(
    prev: &Dataset,
    k: usize,
    lengths_of: impl Fn(usize, &[f64]) -> Vec<f64>,
) -> SampleResult {
    let r = prev.row_len();
    let n = prev.meta.n_dof;
    let reason = prev
        .meta
        .failures
        .iter()
        .find(|f| f.index == k)
        .map(|f| f.reason.clone());
    let q = &prev.q[k * n..(k + 1) * n];
    let tendon_lengths = match prev.tendon_lengths_row(k) {
        Some(row) => row.to_vec(),
        None => lengths_of(k, q),
    };
    SampleResult {
        status: prev.status[k],
        strain: prev.strain[k * r..(k + 1) * r].to_vec(),
        q: q.to_vec(),
        tendon_lengths,
        tip_position: std::array::from_fn(|i| prev.tip_position[3 * k + i]),
        tip_rotation: std::array::from_fn(|i| prev.tip_rotation[9 * k + i]),
        iterations: prev.iterations[k],
        residual: prev.residual[k],
        warm_started: false,
        reason,
    }
}

#[cfg(test)]
mod tests {
    use super::toml_difference;

    #[test]
    fn the_first_differing_scenario_value_is_named_with_both_values() {
        let a = "name = \"a\"\n[material]\ndensity = 1121.0\n[[divisions]]\nlength = 0.25\nradius = [1, 2]\n";
        let b = a.replace("radius = [1, 2]", "radius = [1, 3]");
        assert_eq!(
            toml_difference(a, &b),
            Some(("divisions[0].radius[1]".into(), "2".into(), "3".into()))
        );
        let c = a.replace("density = 1121.0", "density = 1000.0\ndamping = 3.0");
        assert_eq!(
            toml_difference(a, &c),
            Some(("material.damping".into(), "missing".into(), "3.0".into()))
        );
        assert_eq!(toml_difference(a, a), None);
        // an integer and the equal float are the same value: the first real difference is named
        let d = a.replace("density = 1121.0", "density = 1121\ngravity = [0, 0, -5]");
        let e = a.replace(
            "density = 1121.0",
            "density = 1121.0\ngravity = [0.0, 0.0, 0.0]",
        );
        assert_eq!(
            toml_difference(&e, &d),
            Some(("material.gravity[2]".into(), "0.0".into(), "-5".into()))
        );
        assert!(super::same_tables(a, &a.replace("1121.0", "1121")));
        assert!(!super::same_tables(a, &a.replace("1121.0", "1121.5")));
    }
}
