//! The error type of the renderers.

use std::path::PathBuf;

/// Failure to render or write a figure; messages name the file.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Width or height is zero or beyond [`MAX_SIDE_PX`](crate::MAX_SIDE_PX) (guards memory).
    #[error("cannot render {}: image size {width_px} x {height_px} px must be 1..={max} px per side", .path.display())]
    InvalidSize {
        /// Requested target.
        path: PathBuf,
        /// Requested width.
        width_px: u32,
        /// Requested height.
        height_px: u32,
        /// Largest accepted side.
        max: u32,
    },
    /// The panel grid cannot be laid out (e.g. zero columns).
    #[error("cannot render {}: {reason}", .path.display())]
    InvalidLayout {
        /// Requested target.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The bundled DejaVu Sans bytes were rejected by the font loader.
    #[error("cannot register the bundled DejaVu Sans font with plotters")]
    Font,
    /// Drawing or the atomic write failed (the message names the path and the step).
    #[error(transparent)]
    Io(#[from] gyroemu_io::IoError),
}

/// What drawing a figure can fail with: plotters' errors, boxed.
pub(crate) type DrawError = Box<dyn std::error::Error + Send + Sync>;
