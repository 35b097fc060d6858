//! The target of an output before anything is written (rules 1 and 2 of [`super`]): its plain final
//! name, the paths it may never be (the home or current directory, an input of the command), and what
//! stands there now: nothing, a gvsrom output `--force` may replace, or something refused.

use super::manifest::read_manifest;
use super::{Kind, Named, OutputError, MANIFEST_FILE, MANIFEST_KEY};
use std::fs;
use std::io;
use std::path::{Component, Path, PathBuf};

/// Where a target stands before writing.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum Existing {
    Nothing,
    /// A gvsrom output that `--force` lets us replace; for directories, the files its manifest lists.
    Previous {
        files: Vec<String>,
    },
}

/// The final name of `path` and the directory that holds it (created if missing).
pub(super) fn split_target(n: &Named) -> Result<(PathBuf, String), OutputError> {
    let path = &n.path;
    let name = match path.components().next_back() {
        Some(Component::Normal(s)) => s.to_string_lossy().into_owned(),
        _ => {
            return Err(n.refused(
                "not a new file or directory name: `.`, `..`, `/` and empty paths would mean writing over a directory gvsrom did not create; name a new path such as `results/run1`",
            ))
        }
    };
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    fs::create_dir_all(&parent).map_err(n.io(format!(
        "create its parent directory `{}`",
        parent.display()
    )))?;
    Ok((parent, name))
}

/// Refuses an output path (`out_option` = `out`) that equals, contains or lies inside one of the
/// command's `inputs` (`(option, path)` pairs; compared by canonical path, so `./d`, `d/` and a link to `d` are
/// the same): with `--force` such an output would replace the command's own input. Call it before
/// the output is created. Inputs that do not exist are skipped (reading them fails on its own).
pub fn refuse_overlap(
    out_option: &str,
    out: &Path,
    inputs: &[(&str, &Path)],
) -> Result<(), OutputError> {
    let named = Named {
        option: out_option.into(),
        path: out.to_path_buf(),
    };
    let Some(Component::Normal(name)) = out.components().next_back() else {
        return Ok(()); // refused later by split_target, with its own reason
    };
    let parent = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let Ok(target) = fs::canonicalize(parent).map(|p| p.join(name)) else {
        return Ok(()); // the parent does not exist yet: nothing in it can be an input
    };
    // the target itself may be a link to an input
    let target = fs::canonicalize(&target).unwrap_or(target);
    for (option, input) in inputs {
        let Ok(input_c) = fs::canonicalize(input) else {
            continue;
        };
        if input_c.starts_with(&target) {
            let how = if input_c == target { "is" } else { "contains" };
            return Err(named.refused(format!(
                "{how} the input {option} `{}`; an output never replaces the command's own input: choose another path",
                input.display()
            )));
        }
        // inside an input directory, the output would be an entry that directory's manifest does
        // not list: the input would then be refused as holding files gvsrom did not write
        if input_c.is_dir() && target.starts_with(&input_c) {
            return Err(named.refused(format!(
                "lies inside the input {option} `{}`; an output inside another output would make that one hold a file its manifest does not list: choose a path beside it",
                input.display()
            )));
        }
    }
    Ok(())
}

/// Refuses the home directory and the current directory or its ancestors (by canonical path).
/// Refuses a target inside another gvsrom output directory (one whose `meta.json` holds a
/// manifest), except a run directory ([`super::RUN_FORMAT`]), which holds outputs by design. The
/// outer output's manifest would not list it, so gvsrom would later refuse to replace that output,
/// saying it holds an entry gvsrom did not write (a review's `statics --json DATASET/extra.json`).
pub(super) fn refuse_inside_output(n: &Named, parent: &Path) -> Result<(), OutputError> {
    let Ok(mut dir) = fs::canonicalize(parent) else {
        return Ok(());
    };
    loop {
        if let Some((format, _)) = read_manifest(&dir.join(MANIFEST_FILE)) {
            if format == super::RUN_FORMAT {
                return Ok(());
            }
            return Err(n.refused(format!(
                "lies inside the gvsrom output `{}` (format `{format}`), whose manifest would not list it: gvsrom could then no longer replace that output; choose a path outside it",
                dir.display()
            )));
        }
        if !dir.pop() {
            return Ok(());
        }
    }
}

pub(super) fn refuse_special(n: &Named, parent: &Path, name: &str) -> Result<(), OutputError> {
    let Ok(target) = fs::canonicalize(parent).map(|p| p.join(name)) else {
        return Ok(());
    };
    if let Ok(cwd) = std::env::current_dir().and_then(fs::canonicalize) {
        if cwd.starts_with(&target) {
            return Err(n.refused(
                "is the current directory or one of its ancestors; gvsrom only writes new paths or its own earlier outputs",
            ));
        }
    }
    if let Some(home) = std::env::var_os("HOME").and_then(|h| fs::canonicalize(h).ok()) {
        if home == target {
            return Err(n.refused("is the home directory; name a new path inside it"));
        }
    }
    Ok(())
}

/// Whether a gvsrom output was changed since it was written.
enum Edits {
    /// As written, by the hashes its manifest records (or it only lacks files: nothing of the
    /// user's is lost by replacing it).
    None,
    /// How it differs from what gvsrom wrote.
    Found(String),
    /// It records no hashes to tell: an output of an earlier version, or a file that only looks
    /// like a gvsrom output.
    Unknown,
}

/// How the gvsrom output at `target` of `format` differs from what gvsrom wrote, by the hashes its
/// manifest records: a listed file's content, or the values of its meta.json (a JSON file output:
/// its own values).
fn edited_since_written(target: &Path, kind: Kind, format: &str) -> Edits {
    use super::hashes::META_SHA256_KEY;
    use super::integrity::{json_file_edited, verify_dir, Integrity, Problem};
    match kind {
        Kind::Dir => match verify_dir(target, format) {
            Err(e) if matches!(e.problem, Problem::Changed | Problem::MetaEdited) => {
                Edits::Found(e.to_string())
            }
            Ok(Integrity::Unhashed) => Edits::Unknown,
            _ => Edits::None,
        },
        Kind::File => {
            let value = super::read::read_regular_to_string(target)
                .ok()
                .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok());
            let Some(value) = value else {
                return Edits::Unknown;
            };
            if value[MANIFEST_KEY].get(META_SHA256_KEY).is_none() {
                return Edits::Unknown;
            }
            match json_file_edited(&value) {
                true => Edits::Found(
                    "its values no longer match the `meta_sha256` recorded in its manifest: it was edited"
                        .to_string(),
                ),
                false => Edits::None,
            }
        }
    }
}

/// Checks what is at the target now, for an output of `format`; see the module documentation for
/// the rules.
pub(super) fn inspect(
    n: &Named,
    target: &Path,
    kind: Kind,
    format_written: &str,
    force: bool,
) -> Result<Existing, OutputError> {
    let meta = match fs::symlink_metadata(target) {
        Ok(m) => m,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Existing::Nothing),
        Err(e) => return Err(n.io("inspect it")(e)),
    };
    let ft = meta.file_type();
    if ft.is_symlink() {
        return Err(n.refused(
            "is a symbolic link; gvsrom does not write through links: name the real path",
        ));
    }
    let is_kind = match kind {
        Kind::File => ft.is_file(),
        Kind::Dir => ft.is_dir(),
    };
    if !is_kind {
        let what = if ft.is_dir() {
            "a directory"
        } else if ft.is_file() {
            "a regular file"
        } else {
            "a special file (device, FIFO or socket)"
        };
        return Err(n.refused(format!(
            "exists and is {what}, not a {}; gvsrom never replaces what it did not write: choose another path",
            kind.noun()
        )));
    }
    let manifest_path = match kind {
        Kind::File => target.to_path_buf(),
        Kind::Dir => target.join(MANIFEST_FILE),
    };
    let Some((format, files)) = read_manifest(&manifest_path) else {
        return Err(n.refused(format!(
            "exists and is not a gvsrom output (no `{MANIFEST_KEY}` manifest{}); gvsrom never replaces what it did not write: choose another path or move it away",
            if kind == Kind::Dir { " in meta.json" } else { "" }
        )));
    };
    if kind == Kind::File && files.is_some() {
        // e.g. `--json MODEL/meta.json`: replacing it would break the directory output around it
        return Err(n.refused(format!(
            "is the meta.json of a gvsrom {format} directory, not a file output; gvsrom never replaces part of an output: choose another path"
        )));
    }
    let files = files.unwrap_or_default();
    if !force {
        return Err(n.refused(format!(
            "exists (a gvsrom {format} output); pass --force to replace it, or choose another path"
        )));
    }
    if format != format_written {
        return Err(n.refused(format!(
            "is a gvsrom {format} output; this writes a {format_written}, and --force replaces an output only by one of its kind (a mistyped path would lose it): move it away or choose another path"
        )));
    }
    match edited_since_written(target, kind, &format) {
        Edits::None => {}
        Edits::Found(why) => {
            return Err(n.refused(format!(
                "was changed after gvsrom wrote it ({why}); gvsrom never replaces what it did not write, whatever the options: move it away or choose another path"
            )))
        }
        Edits::Unknown => {
            return Err(n.refused(
                "records no content hashes (written by a gvsrom before it recorded them, or not by gvsrom): whether it was changed since cannot be told, so it is never replaced, whatever the options: move it away or choose another path",
            ))
        }
    }
    // Only the regular files actually present *and* listed are ever removed later: a manifest
    // naming `../elsewhere` or a missing file removes nothing outside the directory.
    let mut present = vec![];
    if kind == Kind::Dir {
        let mut foreign = vec![];
        for entry in fs::read_dir(target).map_err(n.io("list it"))? {
            let entry = entry.map_err(n.io("list it"))?;
            let name = entry.file_name().to_string_lossy().into_owned();
            let listed = name == MANIFEST_FILE || files.contains(&name);
            let plain = entry.file_type().map(|t| t.is_file()).unwrap_or(false);
            if !(listed && plain) {
                foreign.push(name);
            } else if name != MANIFEST_FILE {
                present.push(name);
            }
        }
        if !foreign.is_empty() {
            foreign.sort();
            let shown: Vec<_> = foreign.iter().take(3).map(|f| format!("`{f}`")).collect();
            return Err(n.refused(format!(
                "holds {} that gvsrom did not write ({}{}); it is never replaced, whatever the options: move them away or choose another path",
                if foreign.len() == 1 { "an entry" } else { "entries" },
                shown.join(", "),
                if foreign.len() > 3 { ", …" } else { "" }
            )));
        }
    }
    Ok(Existing::Previous { files: present })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sandbox(name: &str) -> PathBuf {
        super::super::test_util::sandbox("output", name)
    }

    #[test]
    fn an_output_inside_another_output_is_refused_but_not_inside_a_run_directory() {
        use super::super::{OutputDir, OutputFile, RunDir};
        let d = sandbox("nested");
        let outer = d.join("data");
        OutputDir::create("--out", &outer, "dataset", false)
            .unwrap()
            .commit(serde_json::json!({}))
            .unwrap();
        for inner in [outer.join("extra.json"), outer.join("deeper/extra.json")] {
            let e = OutputFile::create("--json", &inner, "statics", false)
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("lies inside the gvsrom output") && e.contains("format `dataset`"),
                "{e}"
            );
            assert!(!inner.exists());
        }
        // beside it, and inside a run directory (which holds outputs by design), it is written
        OutputFile::create("--json", &d.join("extra.json"), "statics", false).unwrap();
        let run = d.join("run");
        drop(RunDir::open("--out", &run).unwrap());
        OutputFile::create("--json", &run.join("steps/x.json"), "statics", false).unwrap();
    }

    #[test]
    fn an_output_that_is_contains_or_lies_inside_an_input_is_refused_by_any_spelling() {
        let d = sandbox("overlap");
        let data = d.join("data");
        fs::create_dir_all(data.join("inner")).unwrap();
        let other = d.join("other");
        for (out, inputs) in [
            (data.clone(), vec![("DATASET", data.as_path())]),
            (d.join("data/"), vec![("DATASET", data.as_path())]),
            (d.join("./data"), vec![("DATASET", data.as_path())]),
            (
                data.clone(),
                vec![("--model", data.join("inner").as_path())],
            ),
        ] {
            let err = refuse_overlap("--out", &out, &inputs)
                .unwrap_err()
                .to_string();
            assert!(err.contains("input") && err.contains("--out"), "{err}");
        }
        #[cfg(unix)]
        {
            let link = d.join("link");
            std::os::unix::fs::symlink(&data, &link).unwrap();
            assert!(refuse_overlap("--out", &link, &[("DATASET", &data)]).is_err());
        }
        // an output inside an input directory would be an entry its manifest does not list
        let err = refuse_overlap("--out", &data.join("inner/new"), &[("DATASET", &data)])
            .unwrap_err()
            .to_string();
        assert!(err.contains("lies inside the input DATASET"), "{err}");
        // distinct paths, a sibling with the input's name as a prefix, and a missing input pass
        refuse_overlap("--out", &other, &[("DATASET", &data)]).unwrap();
        refuse_overlap("--out", &d.join("data-figs"), &[("DATASET", &data)]).unwrap();
        refuse_overlap("--out", &other, &[("DATASET", &d.join("missing"))]).unwrap();
    }
}
