//! Ctrl-C, SIGTERM and SIGHUP: one flag for the whole process, set by the handler and read by
//! every long phase.
//!
//! Owns: the flag, [`install_handler`], [`interrupted`], [`check`]. Inputs: the signals (after
//! `install_handler`). Outputs: the flag; [`check`]'s message naming the phase. Invariants:
//! the first signal only sets the flag (the run stops at its next output, or at the end of the
//! phase it is in: meshing ends the gmsh child, the static state and pattern expansion stop
//! before the next phase), a second one quits at once (exit status 130). Without
//! `install_handler` the signals keep their default action (the process ends).
//!
//! A leaf (std and ctrlc only), read by `gmsh`, `pipeline` and the recorder in `output`.

use std::sync::atomic::{AtomicBool, Ordering};

static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Make Ctrl-C, SIGTERM and SIGHUP end a run cleanly: the first prints one line and sets the
/// flag; a second quits at once (exit status 130). For the CLI; call once.
pub fn install_handler() -> Result<(), String> {
    ctrlc::set_handler(|| {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
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
pub fn check(phase: &str) -> Result<(), String> {
    if interrupted() {
        return Err(format!("interrupted (Ctrl-C or SIGTERM) during {phase}: stopped before the next phase, nothing after it was computed or written"));
    }
    Ok(())
}
