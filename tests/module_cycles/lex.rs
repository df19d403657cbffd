//! Lexing: comments and literals blanked, lengths and line breaks kept; test items dropped.

pub(crate) fn is_ident(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// The length of the UTF-8 character starting with byte `b`.
pub(crate) fn char_len(b: u8) -> usize {
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
pub(crate) fn lex(src: &str) -> (String, String) {
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
pub(crate) fn matching(s: &[u8], open: usize) -> usize {
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
pub(crate) fn drop_test_items(code: &str) -> String {
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
