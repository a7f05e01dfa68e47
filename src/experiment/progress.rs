//! Progress of long runs on stderr: a bar with an ETA while stderr is a terminal (indicatif hides
//! it otherwise), and one summary line when it is not, so that a log still says what was done.

use std::io::IsTerminal;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};

/// A bar over `len` items named `unit` (e.g. "units", "converged readings"), prefixed `name`.
pub fn progress_bar(len: usize, name: &str, unit: &str) -> ProgressBar {
    let bar = ProgressBar::new(len as u64);
    if let Ok(style) = ProgressStyle::with_template(&format!(
        "{{prefix}} [{{bar:30}}] {{pos}}/{{len}} {unit}, {{elapsed_precise}} elapsed, ETA {{eta}}"
    )) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_prefix(name.to_string());
    bar
}

/// Items done against those asked, with the one summary line when stderr is no terminal.
pub struct Progress {
    bar: ProgressBar,
    name: String,
    unit: String,
    asked: usize,
    started: Instant,
}

impl Progress {
    /// `asked` items named `unit` (e.g. "objects explored"), prefixed `name`.
    pub fn new(name: &str, asked: usize, unit: &str) -> Self {
        Self {
            bar: progress_bar(asked, name, unit),
            name: name.to_string(),
            unit: unit.to_string(),
            asked,
            started: Instant::now(),
        }
    }

    /// Converged readings collected against those asked, `readings_per_object` of each of
    /// `objects` objects (`collect`, and the data collection of `demo` and the experiments).
    pub fn collection(name: &str, objects: usize, readings_per_object: usize) -> Self {
        Self::new(
            name,
            objects.saturating_mul(readings_per_object),
            "converged readings",
        )
    }

    /// One more item done (any thread).
    pub fn inc(&self) {
        self.bar.inc(1);
    }

    /// Clears the bar; without a terminal, prints the summary line instead.
    pub fn finish(&self, done: usize) {
        self.bar.finish_and_clear();
        if !std::io::stderr().is_terminal() {
            eprintln!(
                "{}: {done} of {} {} in {:.1} s",
                self.name,
                self.asked,
                self.unit,
                self.started.elapsed().as_secs_f64()
            );
        }
    }
}
