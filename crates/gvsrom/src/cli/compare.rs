//! `gvsrom compare REFERENCE RUN`.

use super::*;

/// Two trajectories to compare.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The reference trajectory (a `simulate --out` directory), e.g. the full model's
    pub reference: PathBuf,
    /// The trajectory to measure against it, e.g. a reduced model's (same scenario, input and
    /// sample times)
    pub run: PathBuf,
    /// Compare the runs even if their scenario, physics, input or duration differ (or their
    /// meta.json cannot tell): the output then says how they differ. Without it such runs are
    /// refused, since one does not approximate the other.
    #[arg(long)]
    pub allow_different: bool,
    /// Also write the comparison as JSON, with both runs' hashes (`provenance`).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Let `--json` replace an earlier gvsrom output at that path.
    #[arg(long)]
    pub force: bool,
}

pub(super) fn compare_cmd(args: &CompareArgs, out: &mut impl Write) -> Result<()> {
    use gvsrom::compare::Trajectory;
    let json = match &args.json {
        Some(path) => {
            let inputs = [
                ("REFERENCE", args.reference.as_path()),
                ("RUN", args.run.as_path()),
            ];
            gvsrom::output::refuse_overlap("--json", path, &inputs)?;
            Some(OutputFile::create("--json", path, "compare", args.force)?)
        }
        None => None,
    };
    let compared = gvsrom::compare::run(&args.reference, &args.run, args.allow_different)?;
    for w in &compared.warnings {
        gvsrom::progress::stderr_line(format_args!("warning: {w}"));
    }
    let (reference, run, diffs, c) = (
        &compared.reference,
        &compared.run,
        &compared.differences,
        &compared.comparison,
    );
    let describe = |tr: &Trajectory| {
        let wall = tr.wall_time_s;
        format!(
            "{}: {}, {} DOF, {} samples to t = {} s{}, {}",
            tr.dir.display(),
            tr.scenario,
            tr.n_dof,
            tr.samples(),
            tr.t.last().copied().unwrap_or(0.0),
            if tr.complete { "" } else { " (partial)" },
            if wall.is_finite() && wall > 0.0 {
                format!("{wall:.3} s wall")
            } else {
                "wall time n/a".to_string()
            }
        )
    };
    writeln!(out, "reference  {}", describe(reference))?;
    // simulated time per wall time, so that a partial run compares fairly
    let speed = match compared.speed_ratio {
        Some(ratio) => speed_words(ratio),
        None => {
            "speed n/a (a wall time is zero or not recorded, or a run has no time span)".to_string()
        }
    };
    writeln!(out, "run        {}: {speed}", describe(run))?;
    for (label, tr) in [("REFERENCE", reference), ("RUN", run)] {
        if !tr.extrapolated.is_empty() {
            writeln!(
                out,
                "note       {label} used its model outside what it was trained on (--extrapolate): {}",
                tr.extrapolated.join("; ")
            )?;
        }
    }
    for d in &diffs.differ {
        writeln!(out, "differ     {d} (compared anyway: --allow-different)")?;
    }
    for u in &diffs.unknown {
        writeln!(out, "unknown    {u} (compared anyway: --allow-different)")?;
    }
    writeln!(
        out,
        "compared   {} samples, t = {} … {} s",
        c.samples,
        reference.t[0],
        reference.t[c.samples - 1]
    )?;
    writeln!(
        out,
        "tip error  mean {:.3} %, max {:.3} % at t = {} s, last {:.3} % of the length {} m",
        c.tip_mean, c.tip_max, c.tip_max_t, c.tip_end, reference.length
    )?;
    if c.starts_apart() {
        // both start alike (the inputs compared equal, `start` among them), or were compared anyway
        let from_equilibrium = [&reference, &run].iter().all(|r| {
            (r.input.as_ref()).and_then(|i| i.get("start")) == Some(&"equilibrium".into())
        });
        let why = match from_equilibrium {
            true => "each run starts at its own model's equilibrium under the starting tensions, so a reduced model's static error there is part of every error above (`gvsrom statics --model … --compare` measures it alone)",
            false => "a reduced model's rest can decode away from the full model's straight rod (simulate prints it on its `start` line); with --from-equilibrium each starts at its own model's equilibrium instead, where only the reduced model's static error separates them",
        };
        writeln!(
            out,
            "note       the runs start {:.3} % of the length apart (their tips at t = {} s), and that offset is part of every error above: {why}",
            c.tip_start, reference.t[0]
        )?;
    }
    let active: Vec<&str> = c
        .active
        .iter()
        .map(|&i| gvsrom::scenario::StrainMode::ALL[i].name())
        .collect();
    match (c.strain_mean, c.strain_max) {
        (Some(mean), Some(max)) => writeln!(
            out,
            "strain     error mean {mean:.3} %, max {max:.3} % (per sample: MAE over the points and {} / the reference's peak |ξ − ξ*|)",
            active.join(", ")
        )?,
        _ => writeln!(out, "strain     the reference is straight at every sample")?,
    }
    if let Some(e) = &c.tendon_length_mm {
        writeln!(
            out,
            "tendons    length error mean {:.4} mm, max {:.4} mm at t = {} s (|ℓ_run − ℓ_ref| over the samples and tendons)",
            e.mean, e.max, e.max_t
        )?;
    }
    if let Some(json) = json {
        let report = compared.report()?;
        let path = json.commit_json(&report)?;
        writeln!(out, "json       {}", path.display())?;
    }
    Ok(())
}
