//! Progress on a terminal, quiet otherwise: a bar for counted work (a study's jobs, a
//! solve's time steps) and a spinner for work of unknown length (gmsh meshing and
//! refinement). Nothing is drawn when stderr is not a terminal (CI, pipes, tests).

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::Duration;

/// What the run is doing now ("rates: measuring 24 solutions against the reference"), for
/// the line an interrupted run prints; empty between phases.
static PHASE: Mutex<String> = Mutex::new(String::new());

fn set_phase(what: &str) {
    let mut p = PHASE
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    p.clear();
    p.push_str(what);
}

/// What the run was doing when it was last told ([`Progress::phase`], [`Progress::new`]);
/// None between phases.
pub fn current_phase() -> Option<String> {
    let p = PHASE
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    (!p.is_empty()).then(|| p.clone())
}

/// The run's phase, set without drawing anything (the bars and spinners inside it draw),
/// for as long as the value lives ([`during`]).
pub struct During;

/// Name the phase `what` ("rates: meshing and planning") until the value is dropped.
pub fn during(what: &str) -> During {
    set_phase(what);
    During
}

impl Drop for During {
    fn drop(&mut self) {
        set_phase("");
    }
}

/// Clear the line a bar or spinner is drawn on (a run about to exit in the middle of one
/// leaves the prompt on a clean line); nothing when stderr is not a terminal.
pub fn clear_line() {
    if std::io::stderr().is_terminal() {
        use std::io::Write as _;
        let _ = write!(std::io::stderr(), "\r\x1b[2K");
    }
}

/// A progress bar or spinner; hidden when stderr is not a terminal. A bar or a phase is the
/// run's current phase until dropped; a plain spinner (gmsh within a phase) is not.
pub struct Progress(indicatif::ProgressBar, bool);

impl Progress {
    /// A bar of `n` units (`unit`, singular: "job", "time step") named `name`.
    pub fn new(n: u64, name: &str, unit: &str) -> Self {
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
        set_phase(&format!(
            "{name}: solving {}",
            crate::io::count(n as usize, unit)
        ));
        Progress(pb, true)
    }

    /// A long phase of a run without a count (the error integrals, the report): a spinner
    /// saying `name: what` on a terminal, one line on stderr otherwise (a log shows where a
    /// run spends its time), until dropped.
    pub fn phase(name: &str, what: &str) -> Self {
        let line = format!("{name}: {what}");
        if !std::io::stderr().is_terminal() {
            eprintln!("{line}");
        }
        set_phase(&line);
        Progress(spinner_bar(&line), true)
    }

    /// A spinner saying `message` (redrawn every 0.2 s) until finished.
    /// Between phases (`solve` meshing before its bar), it is the phase until finished.
    pub fn spinner(message: &str) -> Self {
        let owns = current_phase().is_none();
        if owns {
            set_phase(message);
        }
        Progress(spinner_bar(message), owns)
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
        if self.1 {
            set_phase("");
        }
    }
}

/// A spinner saying `message`, redrawn every 0.2 s; hidden when stderr is not a terminal.
fn spinner_bar(message: &str) -> indicatif::ProgressBar {
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
    pb
}
