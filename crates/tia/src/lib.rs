//! Transimpedance front end: gain, one pole, inversion, output rails.
//!
//! The sensed electrode gives a motional *current* proportional to velocity (THEORY section 2);
//! the TIA turns it into a voltage with gain `R` (ohm) and the pole of its feedback `R || C`.
#![warn(missing_docs)]

mod tia;

pub use tia::{min_pole_hz, min_pole_rule, pole_coefficient, realised_pole_hz, Tia, TiaParams};

mod noise;
pub use noise::input_referred_noise_a_per_rthz;
