//! Ctrl-C, SIGTERM and SIGHUP: one flag for the whole process, set by the handler and read by
//! every long phase.
//!
//! Owns: the flag, [`install_handler`], [`interrupted`], [`check`], the typed [`Interrupted`]
//! and the exit status [`EXIT_STATUS`]. Inputs: the signals (after `install_handler`). Outputs:
//! the flag; [`check`]'s error naming the phase. Invariants: the first signal only sets the
//! flag; every phase ends at its next check (the time loop at its next output; meshing ends the
//! gmsh child within 50 ms; the gravity relaxation every [`CHECK_EVERY`] steps; the static
//! Newton solve every iteration; pattern expansion, the model's build and a study's planning
//! between their parts). `jointquake run` then writes `summary.json` marked `interrupted` (with
//! the phase) and, like every other command, exits with [`EXIT_STATUS`]; a second signal quits
//! at once with the same status. Without `install_handler` the signals keep their default
//! action (the process ends).
//!
//! A leaf (std and ctrlc only), read by `gmsh`, `pipeline`, `dynamics`, `statics`, `study` and
//! the recorder in `output`.

use std::sync::atomic::{AtomicBool, Ordering};

static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Exit status of a process ended by Ctrl-C, SIGTERM or SIGHUP, in every phase and command:
/// 130 (128 + SIGINT, the shells' convention for a run stopped by Ctrl-C), the same whether the
/// time loop had started or not, and for a second signal that quits at once.
pub const EXIT_STATUS: i32 = 130;

/// How often an iterative loop that runs for minutes without output (the gravity relaxation)
/// reads the flag: every 100 iterations (one atomic load per 100 steps costs nothing; 100 steps
/// of the arch dam's relaxation take about a second, so a signal ends it within that).
pub const CHECK_EVERY: usize = 100;

/// A phase ended by Ctrl-C, SIGTERM or SIGHUP: which phase (e.g. "meshing", "the static
/// state"). Not a failure of the input: the CLI exits with [`EXIT_STATUS`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Interrupted {
    /// The phase the signal ended.
    pub phase: String,
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "interrupted (Ctrl-C or SIGTERM) during {}: stopped before the next phase, nothing after it was computed or written", self.phase)
    }
}

impl std::error::Error for Interrupted {}

/// Make Ctrl-C, SIGTERM and SIGHUP end a run cleanly: the first prints one line and sets the
/// flag; a second quits at once (exit status 130). For the CLI; call once.
pub fn install_handler() -> Result<(), String> {
    ctrlc::set_handler(|| {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            std::process::exit(EXIT_STATUS);
        }
        eprintln!("interrupted: stopping at the end of the current phase or output and writing what is whole (press Ctrl-C again to quit at once)");
    })
    .map_err(|e| format!("cannot install the Ctrl-C handler: {e}"))
}

/// Whether a signal arrived since the handler was installed.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// Set the flag as the handler does (for tests of the phases that honour it).
pub fn raise() {
    INTERRUPTED.store(true, Ordering::SeqCst);
}

/// Clear the flag (tests only: the flag is process-wide).
pub fn clear() {
    INTERRUPTED.store(false, Ordering::SeqCst);
}

/// `Err` naming `phase` when interrupted: "interrupted (Ctrl-C or SIGTERM) during <phase>".
pub fn check(phase: &str) -> Result<(), Interrupted> {
    if interrupted() {
        return Err(Interrupted { phase: phase.to_string() });
    }
    Ok(())
}

/// [`check`] in a loop: reads the flag only when `iteration` is a multiple of [`CHECK_EVERY`].
pub fn check_every(iteration: usize, phase: &str) -> Result<(), Interrupted> {
    if iteration % CHECK_EVERY == 0 {
        check(phase)
    } else {
        Ok(())
    }
}
