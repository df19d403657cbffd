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

use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::path::{Path, PathBuf};

/// Where a reference from one module to another was first seen.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Site {
    file: PathBuf,
    line: usize,
}

/// One crate root's top-level modules and the references between them.
#[derive(Debug, Default)]
struct ModuleGraph {
    /// The crate and its root file, for messages.
    name: String,
    modules: BTreeSet<String>,
    /// `from -> to -> ` the first reference's place (to != from, both top-level modules).
    edges: BTreeMap<String, BTreeMap<String, Site>>,
    /// Every file read (the root included).
    files: Vec<PathBuf>,
}

/// A cycle of top-level modules: `path[0] -> path[1] -> ... -> path[0]`, each step's site,
/// and every module of its strongly connected component.
#[derive(Debug)]
struct Cycle {
    krate: String,
    path: Vec<String>,
    sites: Vec<Site>,
    component: Vec<String>,
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

// ---------------------------------------------------------------------------------------
// Lexing: comments and literals blanked, lengths and line breaks kept.
// ---------------------------------------------------------------------------------------

fn is_ident(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// The length of the UTF-8 character starting with byte `b`.
fn char_len(b: u8) -> usize {
    match b {
        0xF0..=0xFF => 4,
        0xE0..=0xEF => 3,
        0xC0..=0xDF => 2,
        _ => 1,
    }
}

/// `src` with every comment (line, block, nested block, doc) blanked, and (in the first of
/// the two texts) the contents of every string and character literal too; the second keeps
/// the literals (for `#[path = "..."]`). Both are as long as `src`, with the same lines.
fn lex(src: &str) -> (String, String) {
    let s = src.as_bytes();
    let mut code = s.to_vec();
    let mut with_strings = s.to_vec();
    let blank = |v: &mut Vec<u8>, from: usize, to: usize| {
        for b in &mut v[from..to] {
            if *b != b'\n' {
                *b = b' ';
            }
        }
    };
    let mut i = 0;
    while i < s.len() {
        let at = |k: usize| s.get(k).copied().unwrap_or(0);
        let prev_ident = i > 0 && is_ident(s[i - 1]);
        if s[i] == b'/' && at(i + 1) == b'/' {
            let end = s[i..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(s.len(), |p| i + p);
            blank(&mut code, i, end);
            blank(&mut with_strings, i, end);
            i = end;
        } else if s[i] == b'/' && at(i + 1) == b'*' {
            let (mut depth, mut j) = (1, i + 2);
            while j < s.len() && depth > 0 {
                if s[j] == b'/' && at(j + 1) == b'*' {
                    depth += 1;
                    j += 2;
                } else if s[j] == b'*' && at(j + 1) == b'/' {
                    depth -= 1;
                    j += 2;
                } else {
                    j += 1;
                }
            }
            blank(&mut code, i, j);
            blank(&mut with_strings, i, j);
            i = j;
        } else if !prev_ident
            && (s[i] == b'r' || ((s[i] == b'b' || s[i] == b'c') && at(i + 1) == b'r'))
        {
            // A raw string r"..", r#".."#, br"..", cr"..": else an identifier.
            let r = if s[i] == b'r' { i } else { i + 1 };
            let hashes = s[r + 1..].iter().take_while(|&&b| b == b'#').count();
            if at(r + 1 + hashes) == b'"' {
                let open = r + 1 + hashes + 1;
                let mut close = String::from("\"");
                close.push_str(&"#".repeat(hashes));
                let end = src[open..]
                    .find(&close)
                    .map_or(s.len(), |p| open + p + close.len());
                blank(&mut code, open, end.saturating_sub(1 + hashes).max(open));
                i = end;
            } else {
                while i < s.len() && is_ident(s[i]) {
                    i += 1;
                }
            }
        } else if s[i] == b'"' {
            let mut j = i + 1;
            while j < s.len() && s[j] != b'"' {
                j += if s[j] == b'\\' { 2 } else { 1 };
            }
            blank(&mut code, i + 1, j.min(s.len()));
            i = j + 1;
        } else if s[i] == b'\'' {
            // A character literal ('x', '\n', '\u{..}', '"'), or a lifetime or label ('a).
            if at(i + 1) == b'\\' {
                // The escaped character itself may be a quote: the search starts after it.
                let from = (i + 3).min(s.len());
                let end = s[from..]
                    .iter()
                    .position(|&b| b == b'\'')
                    .map_or(s.len(), |p| from + p);
                blank(&mut code, i + 1, end);
                i = end + 1;
            } else if i + 1 < s.len() && at(i + 1 + char_len(s[i + 1])) == b'\'' {
                let end = i + 1 + char_len(s[i + 1]);
                blank(&mut code, i + 1, end);
                i = end + 1;
            } else {
                i += 1;
            }
        } else if is_ident(s[i]) {
            while i < s.len() && is_ident(s[i]) {
                i += 1;
            }
        } else {
            i += 1;
        }
    }
    let text = |v: Vec<u8>| String::from_utf8(v).expect("blanking whole characters keeps UTF-8");
    (text(code), text(with_strings))
}

/// The end (exclusive) of the bracketed group opening at `open` (`(`, `[` or `{`).
fn matching(s: &[u8], open: usize) -> usize {
    let mut depth = 0usize;
    for (k, &b) in s.iter().enumerate().skip(open) {
        match b {
            b'(' | b'[' | b'{' => depth += 1,
            b')' | b']' | b'}' => {
                depth -= 1;
                if depth == 0 {
                    return k + 1;
                }
            }
            _ => {}
        }
    }
    s.len()
}

/// `code` (already lexed) with every `#[cfg(test)]` item blanked: the attribute, the
/// attributes after it and the item up to its `;` or the end of its first `{ }` block (or
/// the end of the scope it sits in). `#![cfg(test)]` blanks the whole file.
fn drop_test_items(code: &str) -> String {
    let s = code.as_bytes();
    let mut out = s.to_vec();
    let blank = |v: &mut Vec<u8>, from: usize, to: usize| {
        for b in &mut v[from..to] {
            if *b != b'\n' {
                *b = b' ';
            }
        }
    };
    let mut i = 0;
    while i < s.len() {
        if s[i] != b'#' {
            i += 1;
            continue;
        }
        let mut j = i + 1;
        let inner = s.get(j) == Some(&b'!');
        if inner {
            j += 1;
        }
        while j < s.len() && s[j].is_ascii_whitespace() {
            j += 1;
        }
        if s.get(j) != Some(&b'[') {
            i += 1;
            continue;
        }
        let attr_end = matching(s, j);
        let attr: String = code[j + 1..attr_end - 1]
            .chars()
            .filter(|c| !c.is_whitespace())
            .collect();
        if attr != "cfg(test)" {
            i = attr_end;
            continue;
        }
        if inner {
            blank(&mut out, 0, s.len());
            break;
        }
        let mut end = attr_end;
        let mut depth = 0i64;
        while end < s.len() {
            match s[end] {
                b'(' | b'[' | b'{' => depth += 1,
                b')' | b']' => depth -= 1,
                b'}' => {
                    depth -= 1;
                    if depth == 0 {
                        end += 1;
                        break;
                    }
                }
                b';' if depth == 0 => {
                    end += 1;
                    break;
                }
                _ => {}
            }
            if depth < 0 {
                break;
            }
            end += 1;
        }
        blank(&mut out, i, end);
        i = end;
    }
    String::from_utf8(out).expect("blanking whole characters keeps UTF-8")
}

// ---------------------------------------------------------------------------------------
// Tokens and what a file says: its `mod` declarations and its references to crate-root names.
// ---------------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Tok<'a> {
    Ident(&'a str),
    PathSep,
    Punct(u8),
}

fn tokens(code: &str) -> Vec<(Tok<'_>, usize)> {
    let s = code.as_bytes();
    let mut v = Vec::new();
    let mut i = 0;
    while i < s.len() {
        let b = s[i];
        if b.is_ascii_whitespace() {
            i += 1;
        } else if is_ident(b) || b >= 0x80 {
            let start = i;
            while i < s.len() && (is_ident(s[i]) || s[i] >= 0x80) {
                i += 1;
            }
            v.push((Tok::Ident(&code[start..i]), start));
        } else if b == b':' && s.get(i + 1) == Some(&b':') {
            v.push((Tok::PathSep, i));
            i += 2;
        } else {
            v.push((Tok::Punct(b), i));
            i += 1;
        }
    }
    v
}

/// A name at the crate root that a path names (`crate::name`, `super::super::name`).
#[derive(Debug, PartialEq)]
struct RootRef {
    name: String,
    offset: usize,
    /// The outermost inline module around it (`mod x { .. }`), for references in a root file.
    inline_top: Option<String>,
}

/// An outline module declaration `mod name;`.
#[derive(Debug, PartialEq)]
struct ModDecl {
    name: String,
    offset: usize,
    /// The inline modules around it, outermost first.
    inline: Vec<String>,
    /// Its `#[path = ".."]`, if any.
    path: Option<String>,
}

/// What one file says.
#[derive(Debug, Default)]
struct FileFacts {
    decls: Vec<ModDecl>,
    refs: Vec<RootRef>,
    /// `(module, name)` for each `use module::..::name` (or `.. as name`) outside any block:
    /// in a root file, `crate::name` then names something of `module`.
    uses: Vec<(String, String)>,
}

/// What one file (lexed, test items dropped) declares and references. `depth` is its module's
/// depth below the crate root (0 for the root file), to resolve `super::`.
fn read_file(code: &str, with_strings: &str, depth: usize) -> FileFacts {
    let toks = tokens(code);
    let (mut decls, mut refs, mut uses) = (Vec::new(), Vec::new(), Vec::new());
    // The open braces: `Some(name)` for those of inline modules.
    let mut braces: Vec<Option<String>> = Vec::new();
    let mut pending_mod: Option<String> = None;
    // The names a path at token `k` (just after `crate::` or the last `super::`) reaches.
    let names_at = |k: usize| -> Vec<(String, usize)> {
        match toks.get(k) {
            Some((Tok::Ident(n), off)) => vec![(n.to_string(), *off)],
            Some((Tok::Punct(b'{'), _)) => {
                // `{a, b::c, d::{e, f}}`: the first name of each top-level entry.
                let mut found = Vec::new();
                let (mut level, mut fresh) = (0usize, true);
                for (t, off) in &toks[k..] {
                    match t {
                        Tok::Punct(b'{') => {
                            level += 1;
                            fresh = level == 1;
                        }
                        Tok::Punct(b'}') => {
                            level -= 1;
                            if level == 0 {
                                break;
                            }
                        }
                        Tok::Punct(b',') if level == 1 => fresh = true,
                        Tok::Ident(n) if level == 1 && fresh => {
                            found.push((n.to_string(), *off));
                            fresh = false;
                        }
                        _ => {
                            if level == 1 {
                                fresh = false;
                            }
                        }
                    }
                }
                found
            }
            _ => Vec::new(),
        }
    };
    let mut k = 0;
    while k < toks.len() {
        let (t, off) = toks[k];
        let prev = k.checked_sub(1).map(|p| toks[p].0);
        match t {
            Tok::Punct(b'{') => braces.push(pending_mod.take()),
            Tok::Punct(b'}') => {
                braces.pop();
            }
            Tok::Punct(b';') => pending_mod = None,
            Tok::Ident("use") if braces.is_empty() => {
                let mut j = k + 1;
                use_leaves(&toks, &mut j, None, None, &mut uses);
            }
            Tok::Ident("mod") => {
                if let (Some((Tok::Ident(name), _)), Some((next, _))) =
                    (toks.get(k + 1), toks.get(k + 2))
                {
                    let inline: Vec<String> = braces.iter().flatten().cloned().collect();
                    match next {
                        Tok::Punct(b'{') => pending_mod = Some(name.to_string()),
                        Tok::Punct(b';') => decls.push(ModDecl {
                            name: name.to_string(),
                            offset: off,
                            inline,
                            path: path_attr(code, with_strings, off),
                        }),
                        _ => {}
                    }
                }
            }
            Tok::Ident("crate")
                if prev != Some(Tok::PathSep)
                    && toks.get(k + 1).map(|t| t.0) == Some(Tok::PathSep) =>
            {
                let inline_top = braces.iter().flatten().next().cloned();
                for (name, offset) in names_at(k + 2) {
                    refs.push(RootRef {
                        name,
                        offset,
                        inline_top: inline_top.clone(),
                    });
                }
            }
            Tok::Ident("super") if prev != Some(Tok::PathSep) => {
                let mut climbs = 0;
                let mut j = k;
                while toks.get(j).map(|t| t.0) == Some(Tok::Ident("super"))
                    && toks.get(j + 1).map(|t| t.0) == Some(Tok::PathSep)
                {
                    climbs += 1;
                    j += 2;
                }
                let here = depth + braces.iter().flatten().count();
                if climbs > 0 && climbs == here {
                    let inline_top = braces.iter().flatten().next().cloned();
                    for (name, offset) in names_at(j) {
                        refs.push(RootRef {
                            name,
                            offset,
                            inline_top: inline_top.clone(),
                        });
                    }
                }
                k = j.max(k + 1);
                continue;
            }
            _ => {}
        }
        k += 1;
    }
    FileFacts { decls, refs, uses }
}

/// The leaves of the use tree at `toks[*i]` as `(first segment, name it is used as)`: for
/// `a::{b, c::d as e, f::{self}}`, `(a, b)`, `(a, e)`, `(a, f)`; a leading `crate::` or
/// `self::` is skipped, globs are left out.
fn use_leaves(
    toks: &[(Tok<'_>, usize)],
    i: &mut usize,
    first: Option<&str>,
    parent: Option<&str>,
    out: &mut Vec<(String, String)>,
) {
    let mut first = first.map(str::to_string);
    let mut last: Option<String> = None;
    while let Some((t, _)) = toks.get(*i) {
        let followed_by_sep = toks.get(*i + 1).map(|t| t.0) == Some(Tok::PathSep);
        match t {
            Tok::PathSep => *i += 1,
            Tok::Ident("as") => {
                if let Some((Tok::Ident(alias), _)) = toks.get(*i + 1) {
                    last = Some(alias.to_string());
                }
                *i += 2;
            }
            Tok::Ident("crate" | "self") if first.is_none() && followed_by_sep => *i += 1,
            Tok::Ident("self") => {
                last = last.clone().or(parent.map(str::to_string));
                *i += 1;
            }
            Tok::Ident(n) => {
                if first.is_none() {
                    first = Some(n.to_string());
                }
                last = Some(n.to_string());
                *i += 1;
            }
            Tok::Punct(b'{') => {
                *i += 1;
                loop {
                    use_leaves(toks, i, first.as_deref(), last.as_deref(), out);
                    match toks.get(*i).map(|t| t.0) {
                        Some(Tok::Punct(b',')) => *i += 1,
                        Some(Tok::Punct(b'}')) => {
                            *i += 1;
                            return;
                        }
                        _ => return,
                    }
                }
            }
            Tok::Punct(b'*') => {
                last = None;
                *i += 1;
            }
            _ => break,
        }
    }
    if let (Some(f), Some(l)) = (first, last) {
        out.push((f, l));
    }
}

/// The `#[path = ".."]` among the attributes before the `mod` at `off`.
fn path_attr(code: &str, with_strings: &str, off: usize) -> Option<String> {
    let start = code[..off].rfind([';', '{', '}']).map_or(0, |p| p + 1);
    let attrs = &with_strings[start..off];
    let at = attrs.find("#[path")?;
    let rest = &attrs[at..];
    let open = rest.find('"')? + 1;
    let close = open + rest[open..].find('"')?;
    Some(rest[open..close].to_string())
}

fn line_of(text: &str, offset: usize) -> usize {
    text[..offset].bytes().filter(|&b| b == b'\n').count() + 1
}

// ---------------------------------------------------------------------------------------
// The module tree of one crate root, and the graph of its top-level modules.
// ---------------------------------------------------------------------------------------

/// Reads the crate whose root file is `root` through `read` (a file's text, `None` if there is
/// no such file), following its non-test `mod` declarations.
fn scan_crate(name: &str, root: &Path, read: &dyn Fn(&Path) -> Option<String>) -> ModuleGraph {
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
fn cycles(g: &ModuleGraph) -> Vec<Cycle> {
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

// ---------------------------------------------------------------------------------------
// The workspace.
// ---------------------------------------------------------------------------------------

/// Every crate root of the workspace: `(name, root file)`.
fn crate_roots(workspace: &Path) -> Vec<(String, PathBuf)> {
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

fn rs_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).expect("a readable source folder") {
        let p = e.expect("a folder entry").path();
        if p.is_dir() {
            rs_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

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

// ---------------------------------------------------------------------------------------
// The detector itself, on a small crate written out here.
// ---------------------------------------------------------------------------------------

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
