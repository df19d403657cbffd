//! Helpers shared by this crate's integration tests.

use std::path::Path;

/// The names in `dir`, sorted (hidden temporaries included: they start with a dot).
pub fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}
