//! CSV tables with exact float text, readable with one line of pandas/numpy.

use crate::atomic::atomic_stream;
use crate::IoError;
use std::fmt::Write as _;
use std::path::Path;

/// One CSV cell.
#[derive(Clone, Debug, PartialEq)]
pub enum CsvCell {
    /// A float, written in shortest round-trip form (re-reads bit-exactly).
    F64(f64),
    /// An integer (counts, sample indices).
    Int(i64),
    /// Free text, quoted by the csv crate when needed.
    Text(String),
}

/// A table with a header row; every row must have `headers.len()` cells.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CsvTable {
    /// Column names (put units in them, e.g. `time_s`).
    pub headers: Vec<String>,
    /// Data rows.
    pub rows: Vec<Vec<CsvCell>>,
}

/// Appends `x` to `out` in Rust's shortest round-trip text, so `float(text)` in Python or
/// `str::parse` gives back the same bits. Plain `{}` notation for 1e-5 <= |x| < 1e16 (and 0);
/// outside that `{:e}` (equally exact) so that 1e-300 is not 300 characters of zeros.
/// Non-finite values become `NaN`, `inf`, `-inf` (pandas and numpy parse them).
pub fn format_f64(x: f64, out: &mut String) {
    let a = x.abs();
    // Writing to a String cannot fail.
    let _ = if x == 0.0 || !x.is_finite() || (1e-5..1e16).contains(&a) {
        write!(out, "{x}")
    } else {
        write!(out, "{x:e}")
    };
}

/// Row-by-row CSV emitter shared by [`write_csv`] and the signal recorder.
pub(crate) struct CsvSink<W: std::io::Write> {
    wtr: csv::Writer<W>,
    buf: String,
    path: std::path::PathBuf,
}

impl<W: std::io::Write> CsvSink<W> {
    /// Wraps `w` and writes the header row.
    pub(crate) fn new(w: W, path: &Path, headers: &[String]) -> Result<Self, IoError> {
        let mut s = CsvSink {
            wtr: csv::Writer::from_writer(w),
            buf: String::new(),
            path: path.to_path_buf(),
        };
        s.wtr.write_record(headers).map_err(|e| s.err(e))?;
        Ok(s)
    }

    fn err(&self, source: csv::Error) -> IoError {
        IoError::Csv {
            path: self.path.clone(),
            reason: source,
        }
    }

    /// Writes one cell of the current row.
    pub(crate) fn cell(&mut self, c: &CsvCell) -> Result<(), IoError> {
        match c {
            CsvCell::F64(x) => self.f64(*x),
            CsvCell::Int(i) => self.int(*i),
            CsvCell::Text(t) => self.wtr.write_field(t).map_err(|e| self.err(e)),
        }
    }

    /// Writes a float cell of the current row.
    pub(crate) fn f64(&mut self, x: f64) -> Result<(), IoError> {
        self.buf.clear();
        format_f64(x, &mut self.buf);
        self.wtr.write_field(&self.buf).map_err(|e| IoError::Csv {
            path: self.path.clone(),
            reason: e,
        })
    }

    /// Writes an integer cell of the current row.
    pub(crate) fn int(&mut self, i: i64) -> Result<(), IoError> {
        self.buf.clear();
        let _ = write!(self.buf, "{i}");
        self.wtr.write_field(&self.buf).map_err(|e| IoError::Csv {
            path: self.path.clone(),
            reason: e,
        })
    }

    /// Ends the current row.
    pub(crate) fn end_row(&mut self) -> Result<(), IoError> {
        self.wtr
            .write_record(std::iter::empty::<&[u8]>())
            .map_err(|e| self.err(e))
    }

    /// Flushes the csv crate's buffer into the underlying writer.
    pub(crate) fn finish(mut self) -> Result<(), IoError> {
        self.wtr.flush().map_err(|source| IoError::Write {
            path: self.path.clone(),
            reason: source,
        })
    }
}

/// Atomically writes `table` as CSV (header row first). Rows with the wrong number of cells are
/// refused before anything reaches the final name.
pub fn write_csv(path: &Path, table: &CsvTable) -> Result<(), IoError> {
    let expected = table.headers.len();
    if let Some((row, r)) = table
        .rows
        .iter()
        .enumerate()
        .find(|(_, r)| r.len() != expected)
    {
        return Err(IoError::CsvShape {
            path: path.to_path_buf(),
            row,
            got: r.len(),
            expected,
        });
    }
    atomic_stream(path, |w| {
        let mut sink = CsvSink::new(w, path, &table.headers)?;
        for r in &table.rows {
            for c in r {
                sink.cell(c)?;
            }
            sink.end_row()?;
        }
        sink.finish()
    })
}

#[cfg(test)]
mod tests {
    use super::format_f64;

    #[test]
    fn float_text_round_trips_and_stays_short() {
        let xs = [
            0.0,
            -0.0,
            1.0,
            0.1,
            1e-5,
            9.99e-6,
            1e16,
            123456.789,
            5e-324,
            f64::MAX,
            -1.5e-300,
        ];
        for &x in &xs {
            let mut s = String::new();
            format_f64(x, &mut s);
            let back: f64 = s.parse().unwrap();
            assert_eq!(back.to_bits(), x.to_bits(), "{x} -> {s}");
            assert!(s.len() <= 24, "{s}");
        }
        let mut s = String::new();
        format_f64(f64::NAN, &mut s);
        assert_eq!(s, "NaN");
    }
}
