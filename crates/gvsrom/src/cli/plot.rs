//! `gvsrom plot INPUT --out DIR`.

use super::*;

/// `gvsrom plot INPUT --out DIR`.
#[derive(Debug, Args)]
pub struct PlotArgs {
    /// A `statics --json`, `modes --json` or `linearize --json` file, or a directory written by
    /// `simulate --out`, `dataset`, `pod` or `train`
    pub input: PathBuf,
    /// New directory for the figures
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Image formats, comma-separated
    #[arg(long, value_enum, value_delimiter = ',', default_value = "svg,png")]
    pub format: Vec<gvsrom::figures::FigureFormat>,
    /// Replace DIR if it is an earlier gvsrom output
    #[arg(long)]
    pub force: bool,
}

pub(super) fn plot_cmd(args: &PlotArgs, out: &mut impl Write) -> Result<()> {
    let s = gvsrom::figures::plot_outputs(&args.input, &args.out, &args.format, args.force)?;
    for note in &s.notes {
        writeln!(out, "note: {note}")?;
    }
    writeln!(
        out,
        "{} figures of the {} `{}` in {} ({:.1} s):",
        s.written.len(),
        s.kind.name(),
        args.input.display(),
        s.out.display(),
        s.wall_time_s
    )?;
    for w in &s.written {
        writeln!(out, "  {:<28} {:>9} bytes", w.name, w.bytes)?;
    }
    Ok(())
}
