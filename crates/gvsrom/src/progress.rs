//! Progress of long commands (datasets, training, `reproduce`) on stderr: a live bar on a terminal;
//! elsewhere — a log file, a batch job, a pipe — one plain line at most every
//! [`log_period`], so that a run of hours in the background shows how far it is and that it is
//! alive, without filling its log with redraws.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle, TermLike};
use std::io::{self, IsTerminal};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The environment variable that sets the period of the plain progress lines, in seconds.
pub const PERIOD_VAR: &str = "GVSROM_PROGRESS_SECONDS";
/// The period of the plain progress lines when [`PERIOD_VAR`] is not set.
pub const DEFAULT_PERIOD: Duration = Duration::from_secs(30);

/// The period of the plain progress lines: [`PERIOD_VAR`] if it holds a finite number of
/// seconds ≥ 0 (`0`: a line at every update the bar draws, about one a second), else
/// [`DEFAULT_PERIOD`].
pub fn log_period() -> Duration {
    std::env::var(PERIOD_VAR)
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .and_then(|s| Duration::try_from_secs_f64(s).ok())
        .unwrap_or(DEFAULT_PERIOD)
}

/// A progress bar counting `len` `unit`s with the time elapsed and an estimate of what is left:
/// drawn live when stderr is a terminal, else as plain lines ([`log_period`]).
pub fn bar(len: u64, unit: &str) -> ProgressBar {
    let counts = format!(
        "{{pos}}/{{len}} {unit}  {{elapsed_precise}} elapsed, ETA {{eta_precise}}  {{msg}}"
    );
    if !io::stderr().is_terminal() {
        let lines = LogLines {
            period: log_period(),
            start: Instant::now(),
            last: Mutex::new(None),
        };
        let bar = ProgressBar::with_draw_target(
            Some(len),
            ProgressDrawTarget::term_like_with_hz(Box::new(lines), 1),
        );
        if let Ok(style) = ProgressStyle::with_template(&format!("progress   {counts}")) {
            bar.set_style(style);
        }
        return bar;
    }
    let bar = ProgressBar::new(len);
    if let Ok(style) = ProgressStyle::with_template(&format!("[{{bar:30}}] {counts}")) {
        bar.set_style(style.progress_chars("#>."));
    }
    bar
}

/// indicatif's terminal, for a stderr that is not one: every redraw is offered as a line, and
/// one is written when a period has passed since the last (the first a period after the start).
#[derive(Debug)]
struct LogLines {
    period: Duration,
    start: Instant,
    last: Mutex<Option<Instant>>,
}

impl LogLines {
    fn offer(&self, line: &str) -> io::Result<()> {
        let line = line.trim_end();
        if line.is_empty() {
            return Ok(());
        }
        let now = Instant::now();
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        if now.duration_since(last.unwrap_or(self.start)) >= self.period {
            *last = Some(now);
            eprintln!("{line}");
        }
        Ok(())
    }
}

impl TermLike for LogLines {
    fn width(&self) -> u16 {
        160
    }
    fn move_cursor_up(&self, _: usize) -> io::Result<()> {
        Ok(())
    }
    fn move_cursor_down(&self, _: usize) -> io::Result<()> {
        Ok(())
    }
    fn move_cursor_right(&self, _: usize) -> io::Result<()> {
        Ok(())
    }
    fn move_cursor_left(&self, _: usize) -> io::Result<()> {
        Ok(())
    }
    fn write_line(&self, s: &str) -> io::Result<()> {
        self.offer(s)
    }
    fn write_str(&self, s: &str) -> io::Result<()> {
        self.offer(s)
    }
    fn clear_line(&self) -> io::Result<()> {
        Ok(())
    }
    fn flush(&self) -> io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_lines_come_at_most_once_a_period() {
        let lines = LogLines {
            period: Duration::from_millis(50),
            start: Instant::now(),
            last: Mutex::new(None),
        };
        let written = |l: &LogLines| *l.last.lock().unwrap();
        lines.offer("progress   1/10").unwrap();
        assert_eq!(written(&lines), None, "a line before the first period");
        std::thread::sleep(Duration::from_millis(60));
        lines.offer("progress   2/10").unwrap();
        let first = written(&lines).expect("a line after a period");
        lines.offer("progress   3/10").unwrap();
        assert_eq!(
            written(&lines),
            Some(first),
            "a second line within the period"
        );
        lines.offer("   ").unwrap();
        assert_eq!(written(&lines), Some(first));
    }
}
