//! The gyroemu command-line program
