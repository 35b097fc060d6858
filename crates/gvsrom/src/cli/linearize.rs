//! `gvsrom linearize`.

use super::*;

#[derive(Debug, Args)]
pub struct LinearizeArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,

    /// Number of poles printed, slowest first (an integer ≥ 1, default 10); the `--json` file holds
    /// them all.
    #[arg(long, value_name = "K", allow_hyphen_values = true)]
    pub count: Option<String>,

    /// The output `y`: the world positions of the points at these abscissae [m] along the rod,
    /// 3 rows of `C` each, e.g. `--output-at 0.3,0.6` (between the computational points, the
    /// centreline's interpolant); default: the tip.
    #[arg(
        long,
        value_name = "X[,X...]",
        allow_hyphen_values = true,
        value_delimiter = ','
    )]
    pub output_at: Option<Vec<f64>>,

    /// Also output the tip's orientation: 3 rows of `C` after the positions, the tip section's
    /// small rotation in world axes [rad] (for a controller that points the tip).
    #[arg(long)]
    pub output_tip_orientation: bool,

    /// Also output each tendon's length [m] along its thread, one row of `C` each after the
    /// positions: for actuators under position control; the static gain's tendon rows are then the
    /// tendons' compliance, the settled change of each length per newton of each tension.
    #[arg(long)]
    pub output_tendon_lengths: bool,

    /// Also discretize with a zero-order hold of H seconds (tensions held over each sample):
    /// `δx_{k+1} = A_d δx_k + B_d δu_k`, written to the JSON as `discrete`.
    #[arg(long, value_name = "H", allow_hyphen_values = true)]
    pub sample_time: Option<f64>,

    /// Also write the operating point, `A`, `B`, `C`, the poles and the static gain as JSON to FILE
    /// (a new file; see `--force`).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,

    /// Replace FILE if it is an earlier gvsrom output (never anything else).
    #[arg(long, requires = "json")]
    pub force: bool,

    /// Use the reduced model in directory MODEL (from `gvsrom pod` or `gvsrom train`) in place of
    /// the scenario's basis, for the equilibrium and the linearization (2r states).
    #[arg(long, value_name = "MODEL")]
    pub model: Option<PathBuf>,
}

pub(super) fn linearize_cmd(args: &LinearizeArgs, out: &mut impl Write) -> Result<()> {
    use gvsrom::linearize;
    let (r, provenance) =
        load_for_equilibrium(&args.scenario, args.model.as_ref(), args.json.as_ref())?;
    let (scenario, built) = (&r.scenario, &r.built);
    let n_states = 2 * built.n_dof();
    let count = linearize::parse_count(args.count.as_deref(), n_states)?;
    // the output is checked, locked and staged before the solve, so a bad path fails at once
    let json = match &args.json {
        Some(path) => Some(OutputFile::create("--json", path, "linearize", args.force)?),
        None => None,
    };
    if let Some(h) = args.sample_time {
        linearize::check_sample_time(h)?;
    }
    let mut outputs = match &args.output_at {
        Some(xs) => linearize::Outputs::at(built, xs)?,
        None => linearize::Outputs::tip(built),
    };
    if args.output_tip_orientation {
        outputs = outputs.with_tip_orientation();
    }
    if args.output_tendon_lengths {
        outputs = outputs.with_tendon_lengths(built)?;
    }
    print_model(scenario, &args.scenario, built, None, out)?;
    print_motion_note(built, out)?;
    let (eq, mut lin) = linearize::about_equilibrium(built, &outputs)?;
    super::print::warn_found_extrapolated(built, &lin.u);
    if let Some(h) = args.sample_time {
        lin.discretize(h)?;
    }
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
    let mut y = match args.output_at {
        None => "the tip position".to_string(),
        Some(_) => format!(
            "the positions at X = {} m",
            (lin.outputs.iter().map(|x| gvs::error::fmt_rounded(*x)))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    y += " (world) [m]";
    let mut more = vec![];
    if lin.output_tip_rotation.is_some() {
        more.push("the tip's orientation (small rotation, world) [rad]");
    }
    if !lin.output_tendon_lengths.is_empty() {
        more.push("the tendon lengths [m]");
    }
    if let Some((last, rest)) = more.split_last() {
        for m in rest {
            y = format!("{y}, {m}");
        }
        y = format!("{y} and {last}");
    }
    writeln!(
        out,
        "system     δẋ = A δx + B δu, δy = C δx: x = [q; q̇] ({n_states} states), u {}, y {y}; linearized in {:.2} ms",
        match (lin.n_actuators, lin.displacement_channels.len()) {
            (0, _) => "empty (no tendons: B has no columns)".to_string(),
            (k, 0) => format!("the {} [N]", plural(k, "tendon tension")),
            (k, d) => format!(
                "per tendon its tension [N], or its motor's displacement [m] through the thread (tendon{} {}: {} of {k})",
                if d == 1 { "" } else { "s" },
                (lin.displacement_channels.iter().map(|j| j.to_string()).collect::<Vec<_>>()).join(", "),
                plural(d, "displacement channel")
            ),
        },
        lin.time_s * 1e3
    )?;
    if args.output_at.is_some() {
        for (x, p) in lin.outputs.iter().zip(&lin.output_positions) {
            writeln!(
                out,
                "output     X = {} m at {} m",
                gvs::error::fmt_rounded(*x),
                fmt_vec(p, 6)
            )?;
        }
    }
    if !lin.output_tendon_lengths.is_empty() {
        writeln!(
            out,
            "output     tendon lengths {} m",
            fmt_vec(&lin.output_tendon_lengths, 6)
        )?;
    }
    let shown = count.min(lin.poles.len());
    writeln!(
        out,
        "poles      slowest {shown} of {} (the {} eigenvalues of A, conjugate pairs listed once)",
        lin.poles.len(),
        2 * lin.n_dof
    )?;
    writeln!(
        out,
        "{:>4}  {:>14}  {:>14}  {:>14}  {:>13}",
        "pole", "Re λ [1/s]", "Im λ [rad/s]", "|λ|/2π [Hz]", "damping ratio"
    )?;
    for (k, p) in lin.poles.iter().enumerate().take(shown) {
        writeln!(
            out,
            "{:>4}  {:>14.4}  {:>14.4}  {:>14.6}  {:>13.5}",
            k + 1,
            p.re,
            p.im,
            p.natural_frequency_hz,
            p.damping_ratio
        )?;
    }
    if lin.relaxation_poles > 1 {
        let rate = 1.0 / lin.damping_time_s;
        writeln!(
            out,
            "note       {} of the {} poles lie within 5 % of −1/t_d = −{:.4} 1/s, t_d = {:.4} s the material's relaxation time (Kelvin–Voigt): the slow pole of every overdamped mode tends there (all real when the stiffness is proportional to the damping; loads and tendons, which stiffen the rod unlike its damping, can pair some with small imaginary parts)",
            lin.relaxation_poles,
            2 * lin.n_dof,
            rate,
            lin.damping_time_s
        )?;
    }
    if lin.unstable_poles > 0 {
        writeln!(
            out,
            "note       {} with Re λ > 0: the equilibrium is unstable (no motion settles there: the gain below is the equilibrium's sensitivity, not a settled displacement)",
            plural(lin.unstable_poles, "pole")
        )?;
    }
    // a pole near 0 makes A nearly singular (a limit point, the onset of buckling): the gain,
    // ∝ 1/|λ|, is then ill-conditioned (a compressed column 0.04 % below its buckling load gave
    // 147 m/N on a 0.25 m rod)
    let mut magnitudes: Vec<f64> = (lin.poles.iter()).map(|p| p.re.hypot(p.im)).collect();
    magnitudes.sort_by(f64::total_cmp);
    // the next pole of another size: a round rod's two bending planes give equal ones
    let next = (magnitudes.first()).and_then(|&s| magnitudes.iter().find(|&&m| m > 2.0 * s));
    if let (Some(&slowest), Some(&next)) = (magnitudes.first(), next) {
        if slowest < 1e-3 * next && lin.n_actuators > 0 {
            writeln!(
                out,
                "note       the slowest pole, |λ| = {}, lies below 1e-3 of the next ({}): A is nearly singular (the equilibrium is near a limit point or the onset of buckling), so the gain, ∝ 1/|λ|, is ill-conditioned",
                gvsrom::build::significant(slowest),
                gvsrom::build::significant(next)
            )?;
        }
    }
    // a displacement channel's gain is per metre wound in: shown per millimetre, as mm/mm or
    // mrad/mm
    let driven = |k: usize| lin.displacement_channels.contains(&k);
    let per = |k: usize| if driven(k) { 1.0 } else { 1e3 };
    let unit = |k: usize| if driven(k) { "  per mm wound in" } else { "" };
    let settled = match lin.unstable_poles {
        0 => "settled",
        _ => "equilibrium's",
    };
    let (input, unit_in) = match lin.displacement_channels.is_empty() {
        true => ("newton of tension", "N"),
        false => ("unit input", "N, or per mm where marked"),
    };
    match &lin.static_gain {
        _ if lin.n_actuators == 0 => {}
        Some(g) => {
            for (o, x) in lin.outputs.iter().enumerate() {
                let at = match args.output_at {
                    None => "tip".to_string(),
                    Some(_) => format!("X = {} m", gvs::error::fmt_rounded(*x)),
                };
                writeln!(
                    out,
                    "gain       {settled} {at} displacement per {input}, −C A⁻¹ B (world x, y, z) [mm/{unit_in}]"
                )?;
                for k in 0..lin.n_actuators {
                    let col: Vec<f64> = g[3 * o..3 * o + 3]
                        .iter()
                        .map(|row| row[k] * per(k))
                        .collect();
                    writeln!(out, "  tendon {:<3} {}{}", k, fmt_vec(&col, 4), unit(k))?;
                }
            }
            let mut rows = &g[3 * lin.outputs.len()..];
            if lin.output_tip_rotation.is_some() {
                writeln!(
                    out,
                    "gain       {settled} tip rotation per {input}, −C A⁻¹ B (about world x, y, z) [mrad/{unit_in}]"
                )?;
                for k in 0..lin.n_actuators {
                    let col: Vec<f64> = rows[..3].iter().map(|row| row[k] * per(k)).collect();
                    writeln!(out, "  tendon {:<3} {}{}", k, fmt_vec(&col, 4), unit(k))?;
                }
                rows = &rows[3..];
            }
            if !rows.is_empty() {
                writeln!(
                    out,
                    "gain       {settled} change of each tendon length per {input}, −C A⁻¹ B (tendons' compliance, lengths 0…{}) [mm/{unit_in}]",
                    rows.len() - 1
                )?;
                for k in 0..lin.n_actuators {
                    let col: Vec<f64> = rows.iter().map(|row| row[k] * per(k)).collect();
                    writeln!(out, "  tendon {:<3} {}{}", k, fmt_vec(&col, 4), unit(k))?;
                }
            }
        }
        None => {
            writeln!(out, "gain       none: A is singular at this equilibrium")?;
        }
    }
    if let Some(d) = &lin.discrete {
        writeln!(
            out,
            "discrete   zero-order hold of {} s: δx_k+1 = A_d δx_k + B_d δu_k, poles e^(λh) within |z| ≤ {}{}",
            gvs::error::fmt_value(d.sample_time_s),
            match d.spectral_radius {
                r if (1e-4..1e6).contains(&r) => format!("{r:.6}"),
                r => format!("{r:.3e}"),
            },
            if args.json.is_some() { " (A_d, B_d in the JSON)" } else { " (--json writes A_d, B_d)" }
        )?;
    }
    if let Some(json) = json {
        let doc = linearize::LinearizationJson {
            report: &lin,
            model: args.model.as_ref().map(|p| p.display().to_string()),
            model_extrapolated: built.model_extrapolated(&lin.u),
            provenance: Some(&provenance),
        };
        let path = json.commit_json(&doc)?;
        writeln!(out, "json       {}", path.display())?;
    }
    Ok(())
}
