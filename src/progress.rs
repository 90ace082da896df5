//! Progress on a terminal, quiet otherwise: a bar for counted work (a study's jobs, a
//! solve's time steps) and a spinner for work of unknown length (gmsh meshing and
//! refinement). Nothing is drawn when stderr is not a terminal (CI, pipes, tests).

use std::io::IsTerminal;
use std::time::Duration;

/// A progress bar or spinner; hidden when stderr is not a terminal.
pub struct Progress(indicatif::ProgressBar);

impl Progress {
    /// A bar of `n` units named `name`.
    pub fn new(n: u64, name: &str) -> Self {
        let pb = if std::io::stderr().is_terminal() {
            indicatif::ProgressBar::new(n)
        } else {
            indicatif::ProgressBar::hidden()
        };
        pb.set_style(
            indicatif::ProgressStyle::with_template(
                "{prefix} [{bar:30}] {pos}/{len} {msg} ({elapsed})",
            )
            .expect("valid template")
            .progress_chars("=> "),
        );
        pb.set_prefix(name.to_string());
        Progress(pb)
    }

    /// A spinner saying `message` (redrawn every 0.2 s) until finished.
    pub fn spinner(message: &str) -> Self {
        let pb = if std::io::stderr().is_terminal() {
            indicatif::ProgressBar::new_spinner()
        } else {
            indicatif::ProgressBar::hidden()
        };
        pb.set_style(
            indicatif::ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
                .expect("valid template"),
        );
        pb.set_message(message.to_string());
        pb.enable_steady_tick(Duration::from_millis(200));
        Progress(pb)
    }

    /// One unit done, labelled `label`.
    pub fn tick(&self, label: &str) {
        self.0.set_message(label.to_string());
        self.0.inc(1);
    }

    /// Clear the bar.
    pub fn finish(&self) {
        self.0.finish_and_clear();
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.0.finish_and_clear();
    }
}
