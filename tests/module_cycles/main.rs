//! Issue 13, docs/architecture.md §3: no module of a crate imports a module that imports it
//! back. Every crate of the workspace (`crates/*/src`, and the facade's `src`) is read from
//! its root (`lib.rs`, `main.rs`, `bin/*.rs`) along its `mod` declarations, and each
//! reference of a top-level module (a file `x.rs` or a folder `x/`) to another is collected:
//! `crate::x` (also in `use crate::{x, y::z}` groups), `super::` chains that climb to the
//! crate root, and `crate::Name` where the root imports `Name` from `x` (`pub use x::Name`).
//! Comments (doc comments too, so doc links do not count), string and character
//! literals and `#[cfg(test)]` items are left out: only the code a build compiles counts.
//! The top-level modules of a crate must then form no cycle; a failure names each cycle with
//! the file and line of every reference along it.

mod facts;
mod graph;
mod lex;
mod workspace;

use facts::read_file;
use graph::{cycles, scan_crate, Cycle, ModuleGraph, Site};
use lex::{drop_test_items, lex};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use workspace::{crate_roots, rs_files};

#[test]
fn no_module_imports_a_module_that_imports_it_back() {
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR"));
    let roots = crate_roots(workspace);
    let read = |p: &Path| std::fs::read_to_string(p).ok();
    let graphs: Vec<ModuleGraph> = roots
        .iter()
        .map(|(name, root)| scan_crate(name, root, &read))
        .collect();

    // The scan must have seen the workspace, not an empty corner of it.
    let modules: usize = graphs.iter().map(|g| g.modules.len()).sum();
    let edges: usize = graphs
        .iter()
        .map(|g| g.edges.values().map(BTreeMap::len).sum::<usize>())
        .sum();
    assert!(roots.len() > 10, "only {} crate roots found", roots.len());
    assert!(modules > 50, "only {modules} top-level modules found");
    assert!(edges > 50, "only {edges} references between modules found");
    // The files no `mod` reaches are test-only ones (`#[cfg(test)] #[path = ..] mod ..`).
    let reached: BTreeSet<&PathBuf> = graphs.iter().flat_map(|g| &g.files).collect();
    let mut all = Vec::new();
    for (_, root) in &roots {
        rs_files(root.parent().unwrap(), &mut all);
    }
    let unreached: BTreeSet<&PathBuf> = all.iter().filter(|p| !reached.contains(p)).collect();
    eprintln!(
        "{} crate roots, {modules} top-level modules, {edges} references between them, {} files \
         read; not reached by any non-test `mod`: {unreached:?}",
        roots.len(),
        reached.len()
    );

    let found: Vec<Cycle> = graphs.iter().flat_map(cycles).collect();
    assert!(
        found.is_empty(),
        "top-level modules that import each other back (docs/architecture.md §3; move the \
         shared piece to the module it belongs in or to a leaf both use):\n{}",
        found
            .iter()
            .map(|c| c.to_string())
            .collect::<Vec<_>>()
            .join("\n")
    );
}

// The detector itself, on a small crate written out here.

/// A crate of four top-level modules `a`, `b` (a folder), `c` and an inline `d`, whose only
/// cycle is `a -> b -> a` (the back reference through `super::super` in `b/inner.rs`); `c`
/// and `d` use `a` (`d` through the root's re-export), and every mention of them in `a` is
/// in a comment, a literal or test code, which would close further cycles if it counted.
/// `back` chooses whether the back reference is there.
fn synthetic(back: bool) -> BTreeMap<PathBuf, String> {
    let files = [
        (
            "src/lib.rs",
            "//! The root: crate::c in a doc comment.\n\
             mod a;\n\
             pub mod b;\n\
             #[cfg(target_os = \"linux\")]\n\
             mod c;\n\
             #[cfg(test)]\n\
             mod tests;\n\
             mod d {\n    use crate::Alias;\n}\n\
             pub use self::a::{A as Alias, *};\n\
             use crate::b::B as _;\n",
        ),
        (
            "src/a.rs",
            "use crate::b::B;\n\
             /// [`crate::c::C`] is a doc link, not a reference.\n\
             pub struct A;\n\
             const S: &str = \"crate::c::C \\\" crate::d\";\n\
             const R: &str = r#\"crate::c \"# ;\n\
             /* block /* nested crate::c */ crate::d */\n\
             fn quote() -> char { '\"' }\n\
             fn life<'a>(x: &'a str) -> &'a str { x } // crate::c\n\
             #[cfg(test)]\n\
             mod tests {\n    use crate::c::C;\n    fn t() { crate::d::f(); }\n}\n\
             #[cfg(test)]\n\
             fn helper() -> crate::c::C { crate::c::C }\n",
        ),
        (
            "src/b/mod.rs",
            "mod inner;\n\
             pub struct B;\n\
             pub(crate) fn f() {}\n",
        ),
        (
            "src/b/inner.rs",
            if back {
                "use super::super::{b::B as _, a::A};\nuse super::f;\n"
            } else {
                "use super::super::b::B as _;\nuse super::f;\n"
            },
        ),
        (
            "src/c.rs",
            "pub struct C;\n\
             use crate::{a::A as _, d as _};\n\
             pub(crate) fn g() {}\n",
        ),
    ];
    files
        .into_iter()
        .map(|(p, t)| (PathBuf::from(p), t.to_string()))
        .collect()
}

fn edge_list(g: &ModuleGraph) -> Vec<(String, String, usize)> {
    g.edges
        .iter()
        .flat_map(|(f, to)| to.iter().map(move |(t, s)| (f.clone(), t.clone(), s.line)))
        .collect()
}

#[test]
fn detector_finds_a_planted_cycle_and_nothing_else() {
    let files = synthetic(true);
    let g = scan_crate("synthetic", Path::new("src/lib.rs"), &|p| {
        files.get(p).cloned()
    });
    assert_eq!(
        g.modules,
        ["a", "b", "c", "d"].map(String::from).into_iter().collect()
    );
    let e = |f: &str, t: &str, l: usize| (f.to_string(), t.to_string(), l);
    assert_eq!(
        edge_list(&g),
        vec![
            e("a", "b", 1),
            e("b", "a", 1),
            e("c", "a", 2),
            e("c", "d", 2),
            e("d", "a", 9),
        ]
    );
    let found = cycles(&g);
    assert_eq!(found.len(), 1, "{found:#?}");
    assert_eq!(found[0].path, ["a", "b"]);
    assert_eq!(found[0].component, ["a", "b"]);
    assert_eq!(
        found[0].sites[1],
        Site {
            file: PathBuf::from("src/b/inner.rs"),
            line: 1
        }
    );
    let report = found[0].to_string();
    assert!(
        report.contains("b -> a: src/b/inner.rs:1   <- closes the cycle"),
        "{report}"
    );

    let files = synthetic(false);
    let g = scan_crate("synthetic", Path::new("src/lib.rs"), &|p| {
        files.get(p).cloned()
    });
    assert!(cycles(&g).is_empty(), "{:#?}", cycles(&g));
}

#[test]
fn lexing_blanks_comments_literals_and_test_items_only() {
    let src = "let a = \"x // y\"; // crate::c\n\
               let b = '\\''; let c: &'static str = r##\"a\"# b\"##;\n\
               /** doc /* nested */ still doc */ let d = crate::e;\n\
               #[cfg(test)] mod t { fn f() { let _ = crate::z; } }\n\
               # [ cfg ( test ) ]\nuse crate::y;\n\
               #[cfg(not(test))] use crate::w;\n";
    let (code, with_strings) = lex(src);
    assert_eq!(code.len(), src.len());
    assert_eq!(code.lines().count(), src.lines().count());
    assert!(with_strings.contains("\"x // y\""));
    assert!(with_strings.contains("r##\"a\"# b\"##"));
    let code = drop_test_items(&code);
    let spaces =
        |t: &str| -> String { t.chars().map(|c| if c == '\n' { c } else { ' ' }).collect() };
    let mut expected = src.to_string();
    for part in [
        "x // y",
        "// crate::c",
        "\\'",
        "a\"# b",
        "/** doc /* nested */ still doc */",
        "#[cfg(test)] mod t { fn f() { let _ = crate::z; } }",
        "# [ cfg ( test ) ]\nuse crate::y;",
    ] {
        assert!(expected.contains(part), "{part}");
        expected = expected.replacen(part, &spaces(part), 1);
    }
    assert_eq!(code, expected);
    let refs = read_file(&code, &code, 0).refs;
    let names: Vec<&str> = refs.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["e", "w"]);
}
