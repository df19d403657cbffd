//! Low-pass decimator (Butterworth and lock-in biquad cascades) and compensated averager
