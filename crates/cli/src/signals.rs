//! Ctrl-C (SIGINT) and SIGTERM from a scheduler: the first raises the flag a run stops on
//! after saving its finished points; a second exits at once (files being written are
//! temporaries, never left under their final names).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

/// Exit code of a run stopped by Ctrl-C (128 + SIGINT, the shell convention).
pub const EXIT_INTERRUPTED: u8 = 130;

static CANCEL: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// The flag raised by Ctrl-C or SIGTERM; the handler is installed on first call.
pub fn cancel_flag() -> Arc<AtomicBool> {
    CANCEL
        .get_or_init(|| {
            let flag = Arc::new(AtomicBool::new(false));
            let f = flag.clone();
            let installed = ctrlc::set_handler(move || {
                if f.swap(true, Ordering::SeqCst) {
                    eprintln!("\ninterrupted again: exiting now");
                    std::process::exit(EXIT_INTERRUPTED.into());
                }
                eprintln!(
                    "\ninterrupt: saving the finished points and stopping \
                     (Ctrl-C again to quit at once)"
                );
            });
            if let Err(e) = installed {
                eprintln!("warning: Ctrl-C will not save progress: {e}");
            }
            flag
        })
        .clone()
}
