//! Outputs: atomic file writes, CSV, JSON, multichannel WAV, SigMF and windowed signal dumps.
//!
//! Every writer goes through a hidden temporary file in the target's directory that is flushed,
//! fsynced and renamed over the target, so a crash or error never leaves a half-written file
//! under the final name. Formats are chosen to open with one line of Python:
//! `pandas.read_csv`, `json.load`, `soundfile.read`, `sigmf.sigmffile.fromfile` (or
//! `numpy.fromfile(.., dtype="<f8")`).

mod atomic;
mod bounded_read;
mod csv_table;
mod dump;
mod error;
mod fast_text;
mod json;
mod recorder;
mod sigmf;
mod wav;

pub use atomic::{
    batched_files, deferred_dir_syncs, flush_background_persist, remove_temporaries,
    with_background_persist, with_batched_persist, with_deferred_dir_sync, write_atomic,
    write_atomic_via,
};
pub use bounded_read::{
    read_capped, read_own_text, MAX_LOCK_BYTES, MAX_MANIFEST_BYTES, MAX_RECORD_BYTES,
};
pub use csv_table::{format_f64, write_csv, CsvCell, CsvTable};
pub use dump::{dump_source, read_csv_dump, read_dump, read_sigmf, Dump, DumpSource};
pub use error::IoError;
pub use json::write_json;
pub use recorder::SignalRecorder;
pub use sigmf::{
    write_sigmf, SigmfChannel, SigmfFiles, SigmfMeta, DEFAULT_HW, GYROEMU_EXTENSION_VERSION,
    SIGMF_DATATYPE_REAL_F64, SIGMF_VERSION,
};
pub use wav::{
    check_wav_f32_size, wav_f32_rate_problem, write_wav_f32, WAV_F32_HEADER_BYTES,
    WAV_F32_MAX_DATA_BYTES, WAV_RATE_REL_TOL,
};
