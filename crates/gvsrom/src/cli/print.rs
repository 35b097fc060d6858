//! The text the commands print: the model summary, a solution, number formats.

use super::*;

pub(super) fn fmt_vec(v: &[f64], prec: usize) -> String {
    // fixed-point, or the exponent form for a magnitude whose digits would run to hundreds
    // a tiny negative that rounds to zero prints as 0.000, not -0.000 (a sign with no digit to
    // carry it reads as a result)
    let one = |x: &f64| match x.abs() < 1e15 {
        true => {
            let s = format!("{x:.prec$}");
            match s.strip_prefix('-') {
                Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
                _ => s,
            }
        }
        false => format!("{x:.prec$e}"),
    };
    let items: Vec<String> = v.iter().map(one).collect();
    format!("[{}]", items.join(", "))
}

/// `[a, b, c]` with each number in its shortest exact form (the exponent form far from 1,
/// [`gvs::error::fmt_value`]).
pub(super) fn fmt_g(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| gvs::error::fmt_value(*x)).collect();
    format!("[{}]", items.join(", "))
}

/// `x` with `prec` decimals, or where those would show none of its digits (a run of 1e-6 s, a
/// real-time factor of 2e-4), to 2 significant digits: `0.250`, `1e-6`, `0.00021`.
pub(super) fn fmt_fixed(x: f64, prec: usize) -> String {
    if x == 0.0 || !x.is_finite() || x.abs() >= 10f64.powi(1 - prec as i32) {
        format!("{x:.prec$}")
    } else {
        gvs::error::fmt_value(format!("{x:.1e}").parse().unwrap_or(x))
    }
}

/// "3.2× faster" or, below 1, "1.4× slower" (not "0.7× faster").
pub(super) fn speed_words(speedup: f64) -> String {
    if !(speedup.is_finite() && speedup > 0.0) {
        "speed n/a".into()
    } else if speedup >= 1.0 {
        format!("{speedup:.1}× faster")
    } else {
        format!("{:.1}× slower", 1.0 / speedup)
    }
}

/// Warns of the tensions found for displacement drives at `u` that lie outside the reduced
/// model's training, under `--extrapolate` (`Built::model_extrapolated` past what attaching it
/// said): the answer is an extrapolation, and its JSON says so.
pub(super) fn warn_found_extrapolated(built: &gvsrom::Built, u: &[f64]) {
    let attached = built.reduced.as_ref().map_or(0, |r| r.extrapolated.len());
    for s in built.model_extrapolated(u).iter().skip(attached) {
        gvsrom::progress::stderr_line(format_args!("warning: extrapolating (--extrapolate): {s}"));
    }
}

pub(super) fn plural(n: usize, word: &str) -> String {
    if n == 1 {
        format!("{n} {word}")
    } else {
        format!("{n} {word}s")
    }
}

/// The summary of the model that runs. The scenario line is derived from the scenario as built;
/// the file's own `description` follows only when no `--set` or `--tension` changed the scenario
/// (its text may no longer hold then). `signal`: how a run's tensions vary in time, shown in place
/// of the scenario's constant ones.
pub(super) fn print_model(
    scenario: &Scenario,
    args: &ScenarioArgs,
    built: &Built,
    signal: Option<&str>,
    out: &mut impl Write,
) -> Result<()> {
    let m = &built.model;
    writeln!(
        out,
        "scenario   {} — {}",
        built.name,
        gvsrom::build::describe(scenario, built)
    )?;
    let unchanged = args.set.is_empty() && args.tension.is_none() && args.displacement.is_none();
    if let (Some(d), true) = (&scenario.description, unchanged) {
        writeln!(out, "           {d}")?;
    }
    writeln!(
        out,
        "model      {} DOF, {} computational points, {}, length {} m, Magnus {:?}",
        m.n_dof(),
        m.disc.n_points(),
        plural(m.rod.divisions.len(), "division"),
        gvs::error::fmt_rounded(m.rod.length()),
        m.disc.order
    )?;
    if let Some(r) = &built.reduced {
        writeln!(
            out,
            "reduced    {} model `{}`: {} on the {}-DOF basis",
            r.kind,
            r.path.display(),
            plural(r.model.n_dof(), "coordinate"),
            m.n_dof()
        )?;
    }
    if built.u.is_empty() {
        writeln!(out, "tendons    none")?;
    } else if let Some(signal) = signal {
        writeln!(out, "tendons    {}, {signal}", built.u.len())?;
    } else if built.displacement_driven() {
        writeln!(
            out,
            "tendons    {}, driven by displacement: {}",
            built.u.len(),
            gvsrom::build::drive_words(built).join("; ")
        )?;
    } else {
        writeln!(
            out,
            "tendons    {}, u = {} N",
            built.u.len(),
            fmt_g(&built.u)
        )?;
    }
    let (point, distributed) = gvsrom::build::wrench_frames(built);
    writeln!(
        out,
        "loads      gravity {} m/s², {}, {}",
        fmt_g(&built.loads.gravity),
        gvsrom::build::wrench_count(&point, "point wrench"),
        gvsrom::build::wrench_count(&distributed, "distributed wrench"),
    )?;
    for (k, line) in gvsrom::build::body_lines(built).iter().enumerate() {
        let label = if k == 0 { "bodies" } else { "" };
        writeln!(out, "{label:<10} {line}")?;
    }
    Ok(())
}

/// The `note` a motion, its modes or its linearization print for a reduced model made from
/// equilibria only ([`gvsrom::build::Reduced::motion_note`]).
pub(super) fn print_motion_note(built: &Built, out: &mut impl Write) -> Result<()> {
    if let Some(note) = built.reduced.as_ref().and_then(|r| r.motion_note()) {
        writeln!(out, "note       {note}")?;
    }
    Ok(())
}

pub(super) fn print_solution(r: &StaticsReport, out: &mut impl Write) -> Result<()> {
    writeln!(
        out,
        "solved     {} in {}, ‖R‖∞ = {}, {:.2} ms",
        plural(r.iterations, "iteration"),
        plural(r.load_stages, "load stage"),
        gvs::error::fmt_sci(r.residual_norm, 3),
        r.solve_time_s * 1e3
    )?;
    if let Some(c) = &r.continuation {
        let folds = c
            .folds
            .iter()
            .map(|l| format!("{l:.4}"))
            .collect::<Vec<_>>()
            .join(", ");
        let why = match c.after_unstable {
            Some(w2) => format!(
                "the full-load step converged onto an unstable equilibrium (ω² = {} 1/s²)",
                gvs::error::fmt_sci(w2, 3)
            ),
            None => "the load ramp stalled".to_string(),
        };
        writeln!(
            out,
            "continued  {why}: followed the equilibria from the straight rod by arc-length continuation in {} ({} rejected), through {}{}",
            plural(c.steps, "step"),
            c.rejected_steps,
            plural(c.folds.len(), "fold"),
            if folds.is_empty() { String::new() } else { format!(" at load factor {folds}") }
        )?;
    }
    if !r.drives.is_empty() {
        let slack: Vec<String> = (r.drives.iter().enumerate())
            .filter(|(_, d)| d.slack)
            .map(|(k, _)| k.to_string())
            .collect();
        writeln!(
            out,
            "tensions   u = [{}] N found in {}{}",
            (r.u.iter().map(|u| gvsrom::build::significant(*u)))
                .collect::<Vec<_>>()
                .join(", "),
            plural(r.drive_iterations.unwrap_or(0), "tension update"),
            match slack.len() {
                0 => String::new(),
                1 => format!(
                    "; tendon {} carries no tension (slack: its path is no longer than the tendon)",
                    slack[0]
                ),
                _ => format!(
                    "; tendons {} carry no tension (slack: their paths are no longer than the tendons)",
                    slack.join(", ")
                ),
            }
        )?;
    }
    if !r.stability_checked {
        writeln!(
            out,
            "stability  not checked (solver.check_stability = false): this may be an equilibrium the rod cannot rest on"
        )?;
    }
    if let Some(w2) = r.buckled {
        writeln!(
            out,
            "buckled    the equilibrium on the path from the straight rod diverges (ω² = {} 1/s²: a bifurcation, e.g. a column compressed past buckling); released along its divergent mode, the rod's overdamped motion settled in {} on this stable one (its mirror image is another when rod and loads are symmetric)",
            gvs::error::fmt_sci(w2, 3),
            plural(r.descent_steps, "step")
        )?;
    }
    if let Some(w2) = r.divergence {
        writeln!(
            out,
            "unstable   the equilibrium diverges: M⁻¹K_T has the real eigenvalue ω² = {} 1/s² < 0, and no stable equilibrium connected to the straight rod was found; a small disturbance moves the rod away from it (`gvsrom modes` shows the direction)",
            gvs::error::fmt_sci(w2, 3)
        )?;
    }
    writeln!(out, "tip        position {} m", fmt_vec(&r.tip_position, 6))?;
    let (axis, angle) = r.tip_axis_angle();
    writeln!(
        out,
        "           rotation axis {}, angle {:.4}°",
        fmt_vec(&axis, 6),
        angle.to_degrees()
    )?;
    for (i, row) in r.tip_rotation.iter().enumerate() {
        let label = if i == 0 { "R =" } else { "   " };
        writeln!(out, "           {label} {}", fmt_vec(row, 6))?;
    }
    if !r.tendon_lengths.is_empty() {
        let pulled: Vec<f64> = (r.tendon_rest_lengths.iter().zip(&r.tendon_lengths))
            .map(|(rest, l)| 1e3 * (rest - l))
            .collect();
        writeln!(
            out,
            "tendons    length {} m, pulled in {} mm from rest",
            fmt_vec(&r.tendon_lengths, 6),
            fmt_vec(&pulled, 3)
        )?;
    }
    Ok(())
}

/// The `anchors` line of `pod` and `train` (nothing when no anchor is an equilibrium).
pub(super) fn anchors_line(
    out: &mut dyn Write,
    equilibria: usize,
    rows: usize,
    seconds: f64,
) -> std::io::Result<()> {
    if equilibria == 0 {
        return Ok(());
    }
    writeln!(
        out,
        "anchors    {equilibria} of {rows} training inputs hold the reduced model's own equilibrium (solved in {seconds:.2} s): statics --model starts there"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_speed_ratio_below_one_reads_as_slower() {
        assert_eq!(speed_words(3.24), "3.2× faster");
        assert_eq!(speed_words(1.0), "1.0× faster");
        assert_eq!(speed_words(0.7), "1.4× slower");
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(speed_words(bad), "speed n/a");
        }
        assert_eq!(plural(1, "thread"), "1 thread");
        assert_eq!(plural(2, "thread"), "2 threads");
    }

    #[test]
    fn a_number_too_small_for_its_decimals_keeps_two_digits() {
        assert_eq!(fmt_fixed(0.25, 3), "0.250");
        assert_eq!(fmt_fixed(0.0, 3), "0.000");
        assert_eq!(fmt_fixed(0.01, 3), "0.010");
        assert_eq!(fmt_fixed(1e-6, 3), "1e-6");
        assert_eq!(fmt_fixed(0.0051234, 3), "0.0051");
        assert_eq!(fmt_fixed(5.6e-5, 1), "5.6e-5");
        assert_eq!(fmt_fixed(0.21, 1), "0.21");
        assert_eq!(fmt_fixed(4.23, 1), "4.2");
    }

    #[test]
    fn a_tiny_negative_prints_without_a_sign() {
        assert_eq!(
            fmt_vec(&[-1e-9, 1e-9, -0.0, 0.0], 6),
            "[0.000000, 0.000000, 0.000000, 0.000000]"
        );
        assert_eq!(
            fmt_vec(&[-6e-7, -0.25, -2e15], 6),
            "[-0.000001, -0.250000, -2.000000e15]"
        );
    }
}
