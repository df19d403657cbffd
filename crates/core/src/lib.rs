//! Kernel of gyroemu, kept apart from the runtime (in the spirit of FutureSDR's `futuredsp`):
//! the numeric sample type every stage is generic over, the small interface every stage
//! shares, the parameter error, and trigonometry that gives the same bits on every platform.

#[cfg(feature = "check")]
pub mod check;
pub mod detmath;
pub mod error;
pub mod flicker;
pub mod gauss;
#[cfg(target_arch = "x86_64")]
mod gauss_avx512;
mod gauss_scalar;
mod gauss_tables;
pub mod noise;
pub mod sample;
mod significant;
pub mod stage;

pub use error::{ParamError, ParamResult};
pub use num_complex::Complex64;
pub use sample::Sample;
pub use significant::sig3;
pub use stage::{Response, Stage};
pub use wide::f64x4;
