//! Outputs: atomic file writes, CSV, JSON, multichannel WAV and windowed signal dumps
