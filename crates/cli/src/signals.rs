//! Ctrl-C (SIGINT) and SIGTERM from a scheduler. For `run`, the first raises the flag a run
//! stops on after saving its finished points; a second exits at once. Other commands, and
//! any second signal, exit at once after marking the manifest of a run in progress
//! `interrupted` and removing this process's folder locks (files being written are
//! temporaries, never left under their final names).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

/// Exit code of a run stopped by Ctrl-C (128 + SIGINT, the shell convention).
pub const EXIT_INTERRUPTED: u8 = 130;

static CANCEL: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// Installs the handler (first call only): `graceful`, the first signal raises the returned
/// flag (a run stops on it); otherwise every signal exits at once.
pub fn install(graceful: bool) -> Arc<AtomicBool> {
    CANCEL
        .get_or_init(|| {
            let flag = Arc::new(AtomicBool::new(false));
            let f = flag.clone();
            let installed = ctrlc::set_handler(move || {
                if graceful && !f.swap(true, Ordering::SeqCst) {
                    note!(
                        "\ninterrupt: saving the finished points and stopping \
                         (Ctrl-C again to quit at once)"
                    );
                    return;
                }
                let marked = gyroemu_runs::abort_now();
                // Finished files still waiting for their sync and rename go in place first.
                gyroemu_io::flush_background_persist();
                let removed = gyroemu_io::remove_temporaries();
                for m in &marked {
                    note!("\ninterrupted: `{}` marked interrupted", m.display());
                }
                note!(
                    "\ninterrupted: exiting now; the files already written are complete, and the \
                     {removed} being written were removed (none is left half-written)"
                );
                std::process::exit(EXIT_INTERRUPTED.into());
            });
            if let Err(e) = installed {
                note!("warning: Ctrl-C will not save progress nor release the lock: {e}");
            }
            flag
        })
        .clone()
}
