//! The module graph of one crate root, its cycles (Tarjan), and how a cycle is reported.

use crate::facts::{line_of, read_file, FileFacts};
use crate::lex::{drop_test_items, lex};
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::path::{Path, PathBuf};

/// Where a reference from one module to another was first seen.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Site {
    pub(crate) file: PathBuf,
    pub(crate) line: usize,
}

/// One crate root's top-level modules and the references between them.
#[derive(Debug, Default)]
pub(crate) struct ModuleGraph {
    /// The crate and its root file, for messages.
    pub(crate) name: String,
    pub(crate) modules: BTreeSet<String>,
    /// `from -> to -> ` the first reference's place (to != from, both top-level modules).
    pub(crate) edges: BTreeMap<String, BTreeMap<String, Site>>,
    /// Every file read (the root included).
    pub(crate) files: Vec<PathBuf>,
}

/// A cycle of top-level modules: `path[0] -> path[1] -> ... -> path[0]`, each step's site,
/// and every module of its strongly connected component.
#[derive(Debug)]
pub(crate) struct Cycle {
    pub(crate) krate: String,
    pub(crate) path: Vec<String>,
    pub(crate) sites: Vec<Site>,
    pub(crate) component: Vec<String>,
}

impl std::fmt::Display for Cycle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut ring = self.path.clone();
        ring.push(self.path[0].clone());
        writeln!(f, "{}: {}", self.krate, ring.join(" -> "))?;
        for (k, site) in self.sites.iter().enumerate() {
            let closes = if k + 1 == self.sites.len() {
                "   <- closes the cycle"
            } else {
                ""
            };
            writeln!(
                f,
                "    {} -> {}: {}:{}{closes}",
                ring[k],
                ring[k + 1],
                site.file.display(),
                site.line
            )?;
        }
        if self.component.len() > self.path.len() {
            writeln!(
                f,
                "    (modules tangled with it: {})",
                self.component.join(", ")
            )?;
        }
        Ok(())
    }
}

/// Reads the crate whose root file is `root` through `read` (a file's text, `None` if there is
/// no such file), following its non-test `mod` declarations.
pub(crate) fn scan_crate(
    name: &str,
    root: &Path,
    read: &dyn Fn(&Path) -> Option<String>,
) -> ModuleGraph {
    let mut g = ModuleGraph {
        name: name.to_string(),
        ..Default::default()
    };
    let mut raw: Vec<(String, String, Site)> = Vec::new();
    // What the root imports: `crate::name` is then a reference to `module`.
    let mut root_uses: BTreeMap<String, String> = BTreeMap::new();
    // (file, its top-level module (None: the root), its depth, whether it is mod-rs-like).
    let mut queue: VecDeque<(PathBuf, Option<String>, usize, bool)> = VecDeque::new();
    queue.push_back((root.to_path_buf(), None, 0, true));
    while let Some((file, top, depth, mod_rs)) = queue.pop_front() {
        let src = read(&file).unwrap_or_else(|| panic!("cannot read `{}`", file.display()));
        let (code, with_strings) = lex(&src);
        let code = drop_test_items(&code);
        let FileFacts { decls, refs, uses } = read_file(&code, &with_strings, depth);
        if top.is_none() {
            root_uses.extend(uses.into_iter().map(|(m, name)| (name, m)));
        }
        g.files.push(file.clone());
        let dir = file.parent().unwrap_or(Path::new("")).to_path_buf();
        for d in decls {
            let child_top = top
                .clone()
                .unwrap_or_else(|| d.inline.first().cloned().unwrap_or_else(|| d.name.clone()));
            if top.is_none() {
                g.modules.insert(child_top.clone());
            }
            let mut base = if mod_rs {
                dir.clone()
            } else {
                dir.join(file.file_stem().expect("a file name"))
            };
            base.extend(&d.inline);
            let depth = depth + d.inline.len() + 1;
            let (child, child_mod_rs) = match &d.path {
                Some(p) if d.inline.is_empty() => (dir.join(p), true),
                Some(p) => (base.join(p), true),
                None => {
                    let flat = base.join(format!("{}.rs", d.name));
                    if read(&flat).is_some() {
                        (flat, false)
                    } else {
                        (base.join(&d.name).join("mod.rs"), true)
                    }
                }
            };
            assert!(
                read(&child).is_some(),
                "`mod {}` of `{}`:{}: no file `{}`",
                d.name,
                file.display(),
                line_of(&code, d.offset),
                child.display()
            );
            queue.push_back((child, Some(child_top), depth, child_mod_rs));
        }
        for r in refs {
            let Some(from) = top.clone().or(r.inline_top) else {
                continue; // the root's own code
            };
            if top.is_none() {
                g.modules.insert(from.clone());
            }
            raw.push((
                from,
                r.name,
                Site {
                    file: file.clone(),
                    line: line_of(&code, r.offset),
                },
            ));
        }
    }
    for (from, name, site) in raw {
        let to = if g.modules.contains(&name) {
            name
        } else {
            match root_uses.get(&name) {
                Some(m) => m.clone(),
                None => continue,
            }
        };
        if from != to && g.modules.contains(&to) {
            g.edges.entry(from).or_default().entry(to).or_insert(site);
        }
    }
    g
}

/// The cycles of every strongly connected component of more than one module (Tarjan): the
/// shortest through each of its modules, each set of modules once.
pub(crate) fn cycles(g: &ModuleGraph) -> Vec<Cycle> {
    let names: Vec<&String> = g.modules.iter().collect();
    let id: BTreeMap<&String, usize> = names.iter().enumerate().map(|(i, n)| (*n, i)).collect();
    let succ: Vec<Vec<usize>> = names
        .iter()
        .map(|n| {
            g.edges
                .get(*n)
                .map(|e| e.keys().map(|t| id[t]).collect())
                .unwrap_or_default()
        })
        .collect();
    struct Tarjan<'a> {
        succ: &'a [Vec<usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        stack: Vec<usize>,
        on: Vec<bool>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    impl Tarjan<'_> {
        fn visit(&mut self, v: usize) {
            self.index[v] = Some(self.next);
            self.low[v] = self.next;
            self.next += 1;
            self.stack.push(v);
            self.on[v] = true;
            for &w in &self.succ[v] {
                match self.index[w] {
                    None => {
                        self.visit(w);
                        self.low[v] = self.low[v].min(self.low[w]);
                    }
                    Some(i) if self.on[w] => self.low[v] = self.low[v].min(i),
                    Some(_) => {}
                }
            }
            if Some(self.low[v]) == self.index[v] {
                let mut comp = Vec::new();
                loop {
                    let w = self.stack.pop().expect("v is on the stack");
                    self.on[w] = false;
                    comp.push(w);
                    if w == v {
                        break;
                    }
                }
                comp.sort_unstable();
                self.out.push(comp);
            }
        }
    }
    let n = names.len();
    let mut t = Tarjan {
        succ: &succ,
        index: vec![None; n],
        low: vec![0; n],
        stack: Vec::new(),
        on: vec![false; n],
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if t.index[v].is_none() {
            t.visit(v);
        }
    }
    // The shortest cycle through `start` inside `comp` (breadth first, back to `start`).
    let through = |start: usize, comp: &[usize]| -> Vec<usize> {
        let mut parent: BTreeMap<usize, usize> = BTreeMap::new();
        let mut queue = VecDeque::from([start]);
        let mut last = None;
        'bfs: while let Some(v) = queue.pop_front() {
            for &w in &succ[v] {
                if w == start {
                    last = Some(v);
                    break 'bfs;
                }
                if comp.contains(&w) && !parent.contains_key(&w) {
                    parent.insert(w, v);
                    queue.push_back(w);
                }
            }
        }
        let mut path = vec![last.expect("a component of several modules has a cycle")];
        while *path.last().unwrap() != start {
            path.push(parent[path.last().unwrap()]);
        }
        path.reverse();
        path
    };
    let mut found = Vec::new();
    for comp in t.out.into_iter().filter(|c| c.len() > 1) {
        // The shortest cycle through each module of the component, each set of modules once.
        let mut seen: BTreeSet<Vec<usize>> = BTreeSet::new();
        for &start in &comp {
            let path = through(start, &comp);
            let mut key = path.clone();
            key.sort_unstable();
            if !seen.insert(key) {
                continue;
            }
            let path: Vec<String> = path.into_iter().map(|v| names[v].clone()).collect();
            let sites = (0..path.len())
                .map(|k| g.edges[&path[k]][&path[(k + 1) % path.len()]].clone())
                .collect();
            found.push(Cycle {
                krate: g.name.clone(),
                path,
                sites,
                component: comp.iter().map(|&v| names[v].clone()).collect(),
            });
        }
    }
    found
}
