//! A dump's channels carry the units of docs/user-guide.md section 5.3: in the SigMF
//! metadata's `gyroemu:channels`, and as `gyroemu inspect` prints them from the SigMF and
//! from the CSV (which carries no units).

mod common;

use common::*;
use std::collections::BTreeMap;
use std::path::Path;

/// A rotating sweep dumping every node (the default).
const ALL_NODES: &str = r#"
[experiment]
kind = "rotating"
rates_dps = [900.0, 1800.0, 2700.0]
average_s = 0.2
settle_s = 0.05
[dump]
"#;

/// Each channel's unit in the guide's table of section 5.3 (`""`: dimensionless).
fn guide_units() -> BTreeMap<String, String> {
    let guide = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/user-guide.md");
    let text = std::fs::read_to_string(guide).unwrap();
    let at = text
        .find("| node | rate | channels | unit | signal |")
        .unwrap();
    let mut units = BTreeMap::new();
    for row in text[at..]
        .lines()
        .skip(2)
        .take_while(|l| l.starts_with('|'))
    {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        let (chans, unit) = (cells[3], cells[4]);
        // `V; `mod_*` dimensionless`: the first unit, but for the names a later part excepts.
        let mut parts = unit.split(';');
        let main = parts.next().unwrap().trim();
        let dimensionless: Vec<String> = parts
            .filter(|p| p.contains("dimensionless"))
            .map(|p| {
                p.trim()
                    .trim_start_matches('`')
                    .split('*')
                    .next()
                    .unwrap()
                    .into()
            })
            .collect();
        for c in chans.split(',').map(|c| c.trim().trim_matches('`')) {
            let u = if dimensionless.iter().any(|d| c.starts_with(d.as_str())) {
                ""
            } else {
                main
            };
            units.insert(c.to_string(), u.to_string());
        }
    }
    assert_eq!(units.len(), 26, "every channel of the table: {units:?}");
    units
}

/// `(channel, unit)` as `gyroemu inspect FILE` prints them (`-` is no unit).
fn inspected(file: &Path, out: &Path) -> Vec<(String, String)> {
    let o = ok(gyroemu(&["inspect", s(file), "--out", s(out)], &[]));
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .filter(|l| l.starts_with("  "))
        .filter(|l| {
            !["channel ", "note: ", "warning: "]
                .iter()
                .any(|p| l.trim_start().starts_with(p))
        })
        .map(|l| {
            let mut w = l.split_whitespace();
            let (name, unit) = (w.next().unwrap(), w.next().unwrap());
            (name.to_string(), unit.replace('-', ""))
        })
        .collect()
}

#[test]
fn every_dump_channel_has_the_unit_of_the_user_guides_table() {
    let want = guide_units();
    let dir = tempfile::tempdir().unwrap();
    let cfg = config(dir.path(), "c.toml", &small_board(ALL_NODES));
    let out = dir.path().join("out");
    ok(gyroemu(&["run", s(&cfg), "--out", s(&out)], &[]));
    let mut seen = 0;
    for stem in ["dump_fullrate", "dump_decimated"] {
        let meta = json(&out.join(format!("{stem}.sigmf-meta")));
        for c in meta["global"]["gyroemu:channels"].as_array().unwrap() {
            let name = c["name"].as_str().unwrap();
            assert_eq!(
                c["unit"].as_str(),
                Some(want[name].as_str()),
                "{stem}: {name}"
            );
            seen += 1;
        }
        for ext in ["sigmf-meta", "csv"] {
            let file = out.join(format!("{stem}.{ext}"));
            let shown = inspected(&file, &dir.path().join("insp"));
            assert!(!shown.is_empty(), "{file:?}");
            for (name, unit) in shown {
                assert_eq!(unit, want[&name], "inspect {file:?}: {name}");
            }
        }
    }
    assert_eq!(
        seen,
        want.len(),
        "the dump holds every channel of the table"
    );
}
