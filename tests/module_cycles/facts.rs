//! Tokens, and what one file says: its `mod` declarations and its references to crate-root
//! names.

use crate::lex::is_ident;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Tok<'a> {
    Ident(&'a str),
    PathSep,
    Punct(u8),
}

pub(crate) fn tokens(code: &str) -> Vec<(Tok<'_>, usize)> {
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
pub(crate) struct RootRef {
    pub(crate) name: String,
    pub(crate) offset: usize,
    /// The outermost inline module around it (`mod x { .. }`), for references in a root file.
    pub(crate) inline_top: Option<String>,
}

/// An outline module declaration `mod name;`.
#[derive(Debug, PartialEq)]
pub(crate) struct ModDecl {
    pub(crate) name: String,
    pub(crate) offset: usize,
    /// The inline modules around it, outermost first.
    pub(crate) inline: Vec<String>,
    /// Its `#[path = ".."]`, if any.
    pub(crate) path: Option<String>,
}

/// What one file says.
#[derive(Debug, Default)]
pub(crate) struct FileFacts {
    pub(crate) decls: Vec<ModDecl>,
    pub(crate) refs: Vec<RootRef>,
    /// `(module, name)` for each `use module::..::name` (or `.. as name`) outside any block:
    /// in a root file, `crate::name` then names something of `module`.
    pub(crate) uses: Vec<(String, String)>,
}

/// What one file (lexed, test items dropped) declares and references. `depth` is its module's
/// depth below the crate root (0 for the root file), to resolve `super::`.
pub(crate) fn read_file(code: &str, with_strings: &str, depth: usize) -> FileFacts {
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
pub(crate) fn use_leaves(
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
pub(crate) fn path_attr(code: &str, with_strings: &str, off: usize) -> Option<String> {
    let start = code[..off].rfind([';', '{', '}']).map_or(0, |p| p + 1);
    let attrs = &with_strings[start..off];
    let at = attrs.find("#[path")?;
    let rest = &attrs[at..];
    let open = rest.find('"')? + 1;
    let close = open + rest[open..].find('"')?;
    Some(rest[open..close].to_string())
}

pub(crate) fn line_of(text: &str, offset: usize) -> usize {
    text[..offset].bytes().filter(|&b| b == b'\n').count() + 1
}
