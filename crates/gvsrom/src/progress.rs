//! Progress of long commands (datasets, training, `reproduce`) on stderr: a live bar on a terminal;
//! elsewhere — a log file, a batch job, a pipe — one plain line at most every
//! [`log_period`], so that a run of hours in the background shows how far it is and that it is
//! alive, without filling its log with redraws.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle, TermLike};
use std::fmt;
use std::io::{self, IsTerminal, Write};
use std::sync::{Mutex, Once};
use std::time::{Duration, Instant};

/// The environment variable that sets the period of the plain progress lines, in seconds.
pub const PERIOD_VAR: &str = "GVSROM_PROGRESS_SECONDS";
/// The period of the plain progress lines when [`PERIOD_VAR`] is not set.
pub const DEFAULT_PERIOD: Duration = Duration::from_secs(30);

/// One line on stderr (a warning, a progress line, the final error), best effort: a closed or full
/// stderr — a reader that went away, `2>&-` — must not stop or abort the work the line reports on,
/// so a failed write is dropped where `eprintln!` would panic. Called as
/// `stderr_line(format_args!("warning: {w}"))`.
pub fn stderr_line(line: fmt::Arguments<'_>) {
    let _ = writeln!(io::stderr().lock(), "{line}");
}

/// The period of the plain progress lines: [`PERIOD_VAR`] if it holds a finite number of
/// seconds ≥ 0 (`0`: a line at every update the bar draws, at most one a second after the first
/// few), else [`DEFAULT_PERIOD`] — with a warning on stderr, once per process, when the variable
/// is set to anything else.
pub fn log_period() -> Duration {
    let Ok(value) = std::env::var(PERIOD_VAR) else {
        return DEFAULT_PERIOD;
    };
    match period_of(&value) {
        Some(period) => period,
        None => {
            static WARNED: Once = Once::new();
            WARNED.call_once(|| {
                stderr_line(format_args!(
                    "warning: {PERIOD_VAR}={value:?} is not a number of seconds ≥ 0 (e.g. 5 or 0.5); progress lines come every {} s",
                    DEFAULT_PERIOD.as_secs()
                ));
            });
            DEFAULT_PERIOD
        }
    }
}

/// `value` as a period: a finite number of seconds ≥ 0, else `None`.
fn period_of(value: &str) -> Option<Duration> {
    let seconds = value.trim().parse::<f64>().ok()?;
    Duration::try_from_secs_f64(seconds).ok()
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
        if self.due(line, Instant::now()) {
            stderr_line(format_args!("{}", line.trim_end()));
        }
        Ok(())
    }

    /// Whether `line`, offered at `now`, is written: not blank, and a period after the last line
    /// written (or after the start, for the first); if so, `now` becomes the last.
    fn due(&self, line: &str, now: Instant) -> bool {
        if line.trim_end().is_empty() {
            return false;
        }
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        let since = now.saturating_duration_since(last.unwrap_or(self.start));
        if since >= self.period {
            *last = Some(now);
            return true;
        }
        false
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
        let start = Instant::now();
        let lines = LogLines {
            period: Duration::from_secs(30),
            start,
            last: Mutex::new(None),
        };
        let at = |s: u64| start + Duration::from_secs(s);
        assert!(
            !lines.due("progress   1/10", at(29)),
            "a line before the first period"
        );
        assert!(
            lines.due("progress   2/10", at(30)),
            "a line a period after the start"
        );
        assert!(
            !lines.due("progress   3/10", at(59)),
            "a second line within the period"
        );
        assert!(!lines.due("   ", at(90)), "a blank line");
        assert!(
            lines.due("progress   4/10", at(60)),
            "a line a period after the last"
        );
        assert!(!lines.due("progress   5/10", at(61)));
    }

    #[test]
    fn a_period_is_a_finite_number_of_seconds_at_least_zero() {
        assert_eq!(period_of("5"), Some(Duration::from_secs(5)));
        assert_eq!(period_of(" 0.5 "), Some(Duration::from_millis(500)));
        assert_eq!(period_of("0"), Some(Duration::ZERO));
        for bad in ["-5", "abc", "", "inf", "NaN", "1e400"] {
            assert_eq!(period_of(bad), None, "{bad:?}");
        }
    }
}
