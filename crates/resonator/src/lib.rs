//! 2-DOF vibratory gyroscope plant, exactly discretised with the matrix exponential
