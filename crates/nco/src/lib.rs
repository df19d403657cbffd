//! NCO with a 64-bit phase accumulator and the board's 90-degree phase shifter
