//! `gvsrom`: the command line. Parses arguments, calls the library, prints; errors become a one-line
//! message on stderr and exit code 1.

mod cli;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    // A bug must still end in one line, not a backtrace (exit code 101 tells it from a user error).
    std::panic::set_hook(Box::new(|info| {
        gvsrom::progress::stderr_line(format_args!(
            "error: internal error (please report): {info}"
        ));
    }));
    let cli = cli::Cli::parse();
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    match cli::run(cli, &mut out) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let broken_pipe = e
                .chain()
                .filter_map(|c| c.downcast_ref::<std::io::Error>())
                .any(|io| io.kind() == std::io::ErrorKind::BrokenPipe);
            if broken_pipe {
                return ExitCode::SUCCESS;
            }
            let msg = gvsrom::error::message_chain(e.as_ref()).replace('\n', " ");
            if let Some(i) = e.downcast_ref::<cli::Interrupted>() {
                gvsrom::progress::stderr_line(format_args!("interrupted: {msg}"));
                return ExitCode::from((128 + i.signal).clamp(0, 255) as u8);
            }
            gvsrom::progress::stderr_line(format_args!("error: {msg}"));
            ExitCode::FAILURE
        }
    }
}
