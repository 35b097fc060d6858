//! `gvsrom statics` and `gvsrom modes`.

use super::*;

#[derive(Debug, Args)]
pub struct StaticsArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,

    /// Also write the solution (q, tip pose, centreline, strains, solver statistics) as JSON to FILE
    /// (a new file; see `--force`).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,

    /// Replace FILE if it is an earlier gvsrom output (never anything else).
    #[arg(long, requires = "json")]
    pub force: bool,

    /// Solve with the reduced model in directory MODEL (from `gvsrom pod` or `gvsrom train`) in
    /// place of the scenario's basis; the model must have been learned on this scenario's points.
    #[arg(long, value_name = "MODEL")]
    pub model: Option<PathBuf>,

    /// With `--model`: also solve the full model and report the strain error (MAE, % of the peak
    /// strain), the tip error (% of the length) and both solve times.
    #[arg(long, requires = "model")]
    pub compare: bool,

    /// Solve N times and report the mean solve time (warm caches; for timing comparisons).
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub repeat: u32,
}

#[derive(Debug, Args)]
pub struct ModesArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,

    /// Number of modes reported, lowest first (an integer ≥ 1, default 10); more than the model's DOF
    /// count reports all of them, with a note.
    #[arg(long, value_name = "K", allow_hyphen_values = true)]
    pub count: Option<String>,

    /// Also write the equilibrium, the frequencies and the mode shapes (q-space, tip displacement
    /// and rotation, strain at the computational points) as JSON to FILE (a new file; see `--force`).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,

    /// Replace FILE if it is an earlier gvsrom output (never anything else).
    #[arg(long, requires = "json")]
    pub force: bool,

    /// Use the reduced model in directory MODEL (from `gvsrom pod` or `gvsrom train`) in place of
    /// the scenario's basis, for the equilibrium and the modes.
    #[arg(long, value_name = "MODEL")]
    pub model: Option<PathBuf>,
}

pub(super) fn statics_cmd(args: &StaticsArgs, out: &mut impl Write) -> Result<()> {
    let (r, provenance) =
        load_for_equilibrium(&args.scenario, args.model.as_ref(), args.json.as_ref())?;
    // the output is checked, locked and staged before the solve, so a bad path fails at once
    let json = match &args.json {
        Some(path) => Some(OutputFile::create("--json", path, "statics", args.force)?),
        None => None,
    };
    print_model(&r.scenario, &args.scenario, &r.built, None, out)?;
    let run = statics::run(&r.built, args.repeat, args.compare)?;
    warn_found_extrapolated(&r.built, &run.report.u);
    print_solution(&run.report, out)?;
    if let (Some(full), Some(c)) = (&run.full, &run.comparison) {
        writeln!(
            out,
            "full model {} DOF solved in {:.2} ms; reduced {} DOF in {:.2} ms: {}",
            full.n_dof,
            full.solve_time_s * 1e3,
            run.report.n_dof,
            run.report.solve_time_s * 1e3,
            speed_words(c.speedup)
        )?;
        writeln!(
            out,
            "error      strain {:.3} % (MAE / peak |ξ − ξ*|), tip {:.4} % of the length{}",
            c.strain_error_percent,
            c.tip_error_percent,
            match c.tendon_length_error_mm {
                Some(e) => format!(", tendon lengths within {e:.4} mm"),
                None => String::new(),
            }
        )?;
    }
    if let Some(json) = json {
        let path = json.commit_json(run.json(&r.built, &provenance))?;
        writeln!(out, "json       {}", path.display())?;
    }
    Ok(())
}

pub(super) fn modes_cmd(args: &ModesArgs, out: &mut impl Write) -> Result<()> {
    use gvsrom::modes;
    let (r, provenance) =
        load_for_equilibrium(&args.scenario, args.model.as_ref(), args.json.as_ref())?;
    let (scenario, built) = (&r.scenario, &r.built);
    let n_dof = built.n_dof();
    let (count, clipped) = modes::parse_count(args.count.as_deref(), n_dof)?;
    // the output is checked, locked and staged before the solve, so a bad path fails at once
    let json = match &args.json {
        Some(path) => Some(OutputFile::create("--json", path, "modes", args.force)?),
        None => None,
    };
    print_model(scenario, &args.scenario, built, None, out)?;
    print_motion_note(built, out)?;
    if clipped {
        writeln!(
            out,
            "note       --count {} exceeds the model's {n_dof} DOF: reporting all {n_dof} modes",
            args.count.as_deref().unwrap_or_default()
        )?;
    }
    let (eq, report) = modes::compute(built, count)?;
    warn_found_extrapolated(built, &report.u);
    writeln!(
        out,
        "solved     equilibrium in {} and {}, ‖R‖∞ = {} (as `gvsrom statics`)",
        plural(eq.iterations, "iteration"),
        plural(eq.load_stages, "load stage"),
        gvs::error::fmt_sci(eq.residual_norm, 3),
    )?;
    writeln!(
        out,
        "tip        position {} m",
        fmt_vec(&eq.tip_position, 6)
    )?;
    if !report.held_tendons.is_empty() {
        let (threads, rigid): (Vec<usize>, Vec<usize>) =
            (report.held_tendons.iter()).partition(|k| report.held_by_threads.contains(k));
        let list = |ks: &[usize]| {
            let names: Vec<String> = ks.iter().map(|k| k.to_string()).collect();
            let noun = if ks.len() == 1 { "tendon" } else { "tendons" };
            format!("{noun} {}", names.join(", "))
        };
        let mut parts = vec![];
        if !rigid.is_empty() {
            parts.push(format!(
                "{} at {} length: {} constraint{}",
                list(&rigid),
                if rigid.len() == 1 { "its" } else { "their" },
                rigid.len(),
                if rigid.len() == 1 { "" } else { "s" },
            ));
        }
        if !threads.is_empty() {
            parts.push(format!(
                "{} through {} elastic thread{} (axial_stiffness): spring{}, no constraint",
                list(&threads),
                if threads.len() == 1 { "its" } else { "their" },
                if threads.len() == 1 { "" } else { "s" },
                if threads.len() == 1 { "" } else { "s" },
            ));
        }
        writeln!(
            out,
            "held       by the locked motors (driven by displacement): {}; tensions u = [{}] N",
            parts.join("; "),
            (report.u.iter().map(|u| gvsrom::build::significant(*u)))
                .collect::<Vec<_>>()
                .join(", ")
        )?;
    }
    let n_modes = report.all_frequencies_hz.len();
    writeln!(
        out,
        "modes      lowest {} of {n_modes}, undamped, linearized about the equilibrium; each shape by its largest share of the strain energy and its tip motion (world axes)",
        count.min(n_modes)
    )?;
    writeln!(
        out,
        "{:>4}  {:>14}  {:>12}  {:<20}  tip motion",
        "mode", "frequency [Hz]", "period [s]", "strain energy"
    )?;
    let length = built.model.disc.length();
    let mut unstable = 0;
    for m in &report.modes {
        let period = match m.period_s {
            Some(t) => format!("{t:.6}"),
            None => "∞".into(),
        };
        let mut tip = modes::tip_motion(m, length);
        if m.omega_squared < 0.0 {
            unstable += 1;
            tip.push_str(&format!(" (ω² = {:.3e} < 0: unstable)", m.omega_squared));
        }
        writeln!(
            out,
            "{:>4}  {:>14.6}  {:>12}  {:<20}  {tip}",
            m.mode,
            m.frequency_hz,
            period,
            format!("{} {:.1} %", m.dominant_strain, 100.0 * m.dominant_share()),
        )?;
    }
    if unstable > 0 {
        writeln!(
            out,
            "note       {} with ω² < 0: the equilibrium is unstable (it buckles) along them; their frequency is shown as 0",
            plural(unstable, "mode")
        )?;
    }
    if report.stiffness_asymmetry > gvs::dynamics::SYMMETRY_TOLERANCE {
        let complex = report
            .modes
            .iter()
            .filter(|m| m.omega_squared_imag != 0.0)
            .count();
        writeln!(
            out,
            "note       the tangent stiffness is not symmetric (‖K_T − K_Tᵀ‖/‖K_T‖ = {}: tendon friction or follower loads): the modes are the eigenpairs of M⁻¹K_T, the undamped poles of `gvsrom linearize`, and their shapes are not M-orthogonal{}",
            gvs::error::fmt_sci(report.stiffness_asymmetry, 2),
            if complex > 0 {
                format!("; {complex} of the modes shown have a complex ω² (flutter of the undamped linearization): shown by its real part, with the real part of its vector as the shape")
            } else {
                String::new()
            }
        )?;
    }
    if let Some(json) = json {
        let doc = modes::ModesJson {
            report: &report,
            model: args.model.as_ref().map(|p| p.display().to_string()),
            model_extrapolated: built.model_extrapolated(&report.u),
            provenance: Some(&provenance),
        };
        let path = json.commit_json(&doc)?;
        writeln!(out, "json       {}", path.display())?;
    }
    Ok(())
}
