//! Every crate root of the workspace, and its source files.

use std::path::{Path, PathBuf};

/// Every crate root of the workspace: `(name, root file)`.
pub(crate) fn crate_roots(workspace: &Path) -> Vec<(String, PathBuf)> {
    let mut srcs = vec![("gyroemu".to_string(), workspace.join("src"))];
    let mut crates: Vec<PathBuf> = std::fs::read_dir(workspace.join("crates"))
        .expect("crates/ is readable")
        .map(|e| e.expect("a crates/ entry").path())
        .filter(|p| p.join("src").is_dir())
        .collect();
    crates.sort();
    for c in crates {
        let name = c.file_name().unwrap().to_string_lossy().into_owned();
        srcs.push((name, c.join("src")));
    }
    let mut roots = Vec::new();
    for (name, src) in srcs {
        for root in ["lib.rs", "main.rs"] {
            if src.join(root).is_file() {
                roots.push((format!("{name} ({root})"), src.join(root)));
            }
        }
        if let Ok(bins) = std::fs::read_dir(src.join("bin")) {
            let mut bins: Vec<PathBuf> = bins.map(|e| e.expect("a bin/ entry").path()).collect();
            bins.sort();
            for b in bins {
                let root = if b.is_dir() { b.join("main.rs") } else { b };
                if root.extension().is_some_and(|e| e == "rs") && root.is_file() {
                    roots.push((format!("{name} ({})", root.display()), root));
                }
            }
        }
    }
    roots
}

pub(crate) fn rs_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).expect("a readable source folder") {
        let p = e.expect("a folder entry").path();
        if p.is_dir() {
            rs_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}
