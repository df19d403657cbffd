//! The zero-order hold on the plant's force input. The discretisation assumes each force sample
//! is held constant over its period (the DAC's hold), so the plant, not the DAC, realises it:
//! its response is the plant input's, as the read-out needs it to compensate the chain.

use gyroemu_core::detmath;
use num_complex::Complex64;

/// The hold's response at `f_hz` for sample rate `fs_hz`: the average of `e^{-j 2 pi f t}` over
/// one hold period, `sinc(f Ts) e^{-j pi f Ts}` (`sinc(x) = sin(pi x) / (pi x)`); a delay of half
/// a sample at DC.
pub fn hold_response(f_hz: f64, fs_hz: f64) -> Complex64 {
    let x = f_hz / fs_hz; // f Ts
                          // sin(pi x) and e^{-j pi x} from half a turn of x, reduced exactly in turns.
    let (s, c) = detmath::sin_cos_turns(0.5 * x);
    let sinc = if x == 0.0 {
        1.0
    } else {
        s / (core::f64::consts::PI * x)
    };
    Complex64::new(sinc * c, -sinc * s)
}
