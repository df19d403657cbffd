//! facade (stages pending)
pub use gyroemu_core as core;
