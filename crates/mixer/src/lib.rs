//! Two-stage mixer: carrier I/Q demodulation, single real mixer, demodulation at Omega and the sideband estimators
