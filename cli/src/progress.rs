//! A one-line progress display on standard error, redrawn in place on a terminal.

use std::io::{IsTerminal, Write};
use std::time::Instant;

/// Progress over a known number of steps.
pub struct Progress {
    label: String,
    total: usize,
    done: usize,
    start: Instant,
    tty: bool,
}

impl Progress {
    /// Starts a display for `total` steps.
    pub fn new(label: &str, total: usize) -> Self {
        let p = Progress {
            label: label.to_string(),
            total,
            done: 0,
            start: Instant::now(),
            tty: std::io::stderr().is_terminal(),
        };
        p.draw("");
        p
    }

    /// One step done; `what` names the step just finished.
    pub fn step(&mut self, what: &str) {
        self.done += 1;
        self.draw(what);
    }

    fn draw(&self, what: &str) {
        if !self.tty {
            return;
        }
        let width = 30;
        let filled = (width * self.done).checked_div(self.total).unwrap_or(width).min(width);
        err!(
            "\r\x1b[2K{} [{}{}] {}/{} {:.1}s {}",
            self.label,
            "#".repeat(filled),
            " ".repeat(width - filled),
            self.done,
            self.total,
            self.start.elapsed().as_secs_f64(),
            what
        );
        let _ = std::io::stderr().flush();
    }

    /// Clears the line.
    pub fn finish(self) {
        if self.tty {
            err!("\r\x1b[2K");
        }
    }
}

/// Runs `f`, printing `what` and the time it took on standard error.
pub fn timed<T>(what: &str, f: impl FnOnce() -> T) -> (T, f64) {
    err!("{what} ... ");
    let start = Instant::now();
    let out = f();
    let s = start.elapsed().as_secs_f64();
    errln!("{:.3} s", s);
    (out, s)
}
