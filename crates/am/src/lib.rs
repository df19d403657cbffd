//! AM modulator of the two drives and the DAC (hold, quantisation)
