//! A mutex's value for the parallel sweeps' shared slots (boards, outcomes, a written dump):
//! each slot is written whole, so a holder that panicked leaves nothing half-done to refuse.

use std::sync::{Mutex, MutexGuard};

/// `m`'s guard, whether or not a panicking holder poisoned it.
pub fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}
