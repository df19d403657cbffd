//! Shared helpers of the run-lifecycle tests: a reporter that keeps what it is told, and
//! readers of an output folder.
#![allow(dead_code)]

use gyroemu_experiment::{Quiet, Reporter, Task};
use serde_json::Value;
use std::path::Path;
use std::sync::Mutex;

/// Keeps the notes and warnings.
#[derive(Default)]
pub struct Record(pub Mutex<Vec<String>>);

impl Reporter for Record {
    fn task(&self, _: &str) -> Box<dyn Task + '_> {
        Box::new(Quiet)
    }
    fn note(&self, text: &str) {
        self.0.lock().unwrap().push(text.to_string());
    }
    fn warn(&self, text: &str) {
        self.0.lock().unwrap().push(format!("warning: {text}"));
    }
}

pub fn json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// The names of the files in `out/dir`, sorted (none when it does not exist).
pub fn files_in(out: &Path, dir: &str) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(out.join(dir))
        .map(|d| {
            d.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}
