//! The house rules of `../shared/DESIGN.md`, read from the source: imports run down
//! `cli → pipeline → spec → surface → flatten → pattern → nest → toolpath → output → device →
//! profile, geom` and never up it; a stage reaches an earlier stage only through its public
//! (`pub`, not `pub(crate)`) items; no cycle between the files of one module; no file under
//! `src/` over 1,000 lines of code (its `#[cfg(test)]` module not counted) and no function over
//! 150 lines.
//!
//! The scan is textual: comments and string literals are blanked, then every `crate::…` path
//! (including `use crate::{a, b::c}` groups) and every `super::…` path is resolved to the
//! module it names.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The modules in import order: a module may use those after it (with the exceptions in
/// [`allowed`]).
const ORDER: &[&str] = &[
    "cli", "pipeline", "spec", "surface", "flatten", "pattern", "nest", "toolpath", "output",
    "device", "profile", "geom",
];
const STAGES: &[&str] = &[
    "surface", "flatten", "pattern", "nest", "toolpath", "output", "device",
];

fn rank(m: &str) -> Option<usize> {
    ORDER.iter().position(|x| *x == m)
}

/// Whether module `from` may use module `to` (`to` = "" is the crate root: `crate::Error`).
fn allowed(from: &str, to: &str) -> bool {
    if from == to {
        return true;
    }
    match from {
        "cli" => true,
        "pipeline" => to != "cli",
        "spec" => STAGES.contains(&to) || to == "profile" || to == "geom",
        "profile" => to == "geom",
        "geom" => false,
        _ if STAGES.contains(&from) => {
            to == "profile" || to == "geom" || (STAGES.contains(&to) && rank(to) < rank(from))
        }
        _ => true, // lib.rs, main.rs
    }
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .expect("read src")
        .map(|e| e.expect("dir entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// The module path of a file: `src/surface/boundary/search.rs` → `["surface", "boundary",
/// "search"]`, `src/surface/mod.rs` → `["surface"]`, `src/lib.rs` → `[]`.
fn module_of(file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src()).expect("under src");
    let mut parts: Vec<String> = rel
        .iter()
        .map(|s| s.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().unwrap_or_default();
    let stem = last.trim_end_matches(".rs").to_string();
    if !matches!(stem.as_str(), "mod" | "lib" | "main") {
        parts.push(stem);
    }
    parts
}

/// The text with comments, string and char literals blanked (newlines kept, so line numbers
/// stay).
fn code_only(text: &str) -> String {
    let b: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < b.len() && b[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    if b[i] == '\n' {
                        out.push('\n');
                    }
                    i += 1;
                }
            }
        } else if c == 'r' && (next == Some('"') || (next == Some('#') && !prev_ident(&b, i))) {
            // raw string r"…" / r#"…"#
            let mut j = i + 1;
            let mut hashes = 0;
            while b.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&'"') || prev_ident(&b, i) {
                out.push(c);
                i += 1;
                continue;
            }
            j += 1;
            out.push_str("\"\"");
            loop {
                if j >= b.len() {
                    break;
                }
                if b[j] == '"' && (0..hashes).all(|k| b.get(j + 1 + k) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                if b[j] == '\n' {
                    out.push('\n');
                }
                j += 1;
            }
            i = j;
        } else if c == '"' {
            i += 1;
            out.push_str("\"\"");
            while i < b.len() && b[i] != '"' {
                if b[i] == '\\' {
                    i += 1;
                }
                if b.get(i) == Some(&'\n') {
                    out.push('\n');
                }
                i += 1;
            }
            i += 1;
        } else if c == '\'' && !prev_ident(&b, i) {
            // a char literal ('a', '\n', '\u{..}') but not a lifetime ('a)
            let close = if next == Some('\\') {
                (i + 2..b.len().min(i + 12)).find(|&k| b[k] == '\'')
            } else if b.get(i + 2) == Some(&'\'') {
                Some(i + 2)
            } else {
                None
            };
            match close {
                Some(k) => {
                    out.push_str("' '");
                    i = k + 1;
                }
                None => {
                    out.push(c);
                    i += 1;
                }
            }
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

fn prev_ident(b: &[char], i: usize) -> bool {
    i > 0 && (b[i - 1].is_alphanumeric() || b[i - 1] == '_')
}

/// Expand a path tail after `crate::` / `super::`: `a::b`, `{a, b::{c, d}}`, `a::{b, c}`.
fn expand(s: &str) -> Vec<String> {
    fn group(s: &[char], mut i: usize, prefix: &str, out: &mut Vec<String>) -> usize {
        // s[i] == '{'
        i += 1;
        loop {
            while i < s.len() && (s[i].is_whitespace() || s[i] == ',') {
                i += 1;
            }
            if i >= s.len() || s[i] == '}' {
                return i + 1;
            }
            i = path(s, i, prefix, out);
        }
    }
    fn path(s: &[char], mut i: usize, prefix: &str, out: &mut Vec<String>) -> usize {
        let mut cur = prefix.to_string();
        loop {
            while i < s.len() && s[i].is_whitespace() {
                i += 1;
            }
            if i < s.len() && s[i] == '{' {
                return group(s, i, &cur, out);
            }
            let start = i;
            while i < s.len() && (s[i].is_alphanumeric() || s[i] == '_') {
                i += 1;
            }
            let seg: String = s[start..i].iter().collect();
            if seg.is_empty() {
                if !cur.is_empty() {
                    out.push(cur);
                }
                return i + usize::from(i < s.len() && s[i] != '}' && s[i] != ',');
            }
            if !cur.is_empty() {
                cur.push_str("::");
            }
            cur.push_str(&seg);
            if s.get(i) == Some(&':') && s.get(i + 1) == Some(&':') {
                i += 2;
            } else {
                out.push(cur);
                // skip `as name`
                while i < s.len() && s[i] != ',' && s[i] != '}' && s[i] != ';' {
                    if s[i] == '{' || s[i] == '(' || s[i] == '\n' {
                        break;
                    }
                    i += 1;
                }
                return i;
            }
        }
    }
    let chars: Vec<char> = s.chars().collect();
    let mut out = Vec::new();
    path(&chars, 0, "", &mut out);
    out
}

/// Every path a file names through `crate::` or `super::`, resolved to a full module path
/// from the crate root, with the 1-based line it is on.
fn references(file: &Path) -> Vec<(usize, Vec<String>)> {
    let text = std::fs::read_to_string(file).expect("read source");
    let code = code_only(&text);
    let me = module_of(file);
    let mut refs = Vec::new();
    let bytes = code.as_bytes();
    let mut i = 0;
    while i < code.len() {
        let rest = &code[i..];
        let after_ident = i > 0 && {
            let c = bytes[i - 1] as char;
            c.is_alphanumeric() || c == '_' || c == ':' || c == '$'
        };
        let (base, len): (Vec<String>, usize) = if rest.starts_with("crate::") && !after_ident {
            (Vec::new(), 7)
        } else if rest.starts_with("super::") && !after_ident {
            // `super` of module a::b (file a/b.rs or a/b/mod.rs) is a.
            let mut base = me.clone();
            let mut n = 0;
            let mut r = rest;
            while let Some(t) = r.strip_prefix("super::") {
                n += 1;
                r = t;
                base.pop();
            }
            (base, 7 * n)
        } else {
            i += rest.chars().next().map_or(1, |c| c.len_utf8());
            continue;
        };
        let line = code[..i].matches('\n').count() + 1;
        let tail_end = code[i + len..]
            .find(';')
            .map_or(code.len(), |k| i + len + k)
            .min(i + len + 4000);
        for p in expand(&code[i + len..tail_end]) {
            let mut full = base.clone();
            full.extend(p.split("::").map(str::to_string));
            refs.push((line, full));
        }
        i += len;
    }
    refs
}

fn all_files() -> Vec<PathBuf> {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    files
}

#[test]
fn imports_run_down_the_pipeline() {
    let mut bad = Vec::new();
    for f in all_files() {
        let me = module_of(&f);
        let Some(from) = me.first() else { continue };
        for (line, path) in references(&f) {
            let to = if path.len() > 1 || rank(&path[0]).is_some() {
                path[0].as_str()
            } else {
                ""
            };
            let to = if rank(to).is_some() { to } else { "" };
            if to.is_empty() && !matches!(from.as_str(), "cli" | "pipeline") {
                // crate-root items: only `crate::Error` and friends, for cli and pipeline
                if path.first().is_some_and(|p| p == "Error") {
                    bad.push(format!(
                        "{}:{line}: {from} uses the crate-wide error `crate::{}`; return the stage's own error",
                        f.strip_prefix(src()).unwrap_or(&f).display(),
                        path.join("::")
                    ));
                }
                continue;
            }
            if !to.is_empty() && !allowed(from, to) {
                bad.push(format!(
                    "{}:{line}: {from} imports {} (up the pipeline)",
                    f.strip_prefix(src()).unwrap_or(&f).display(),
                    path.join("::")
                ));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "{} imports break the order:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn no_subcommand_calls_another() {
    // cli/<sub>.rs files parse their flags and call `pipeline`; what several share lives in
    // cli/mod.rs, cli/args.rs, cli/link.rs and cli/printcut.rs (print-and-cut's flags and
    // send, used by `cut`, and the sheet placement `sim` reads too).
    let shared = ["args", "link", "printcut"];
    let mut bad = Vec::new();
    for f in all_files() {
        let me = module_of(&f);
        if me.len() != 2 || me[0] != "cli" || shared.contains(&me[1].as_str()) {
            continue;
        }
        for (line, path) in references(&f) {
            if path.len() >= 2
                && path[0] == "cli"
                && path[1] != me[1]
                && !shared.contains(&path[1].as_str())
                && module_file(&path[..2]).is_some()
            {
                bad.push(format!(
                    "{}:{line}: cli::{} uses {}",
                    f.strip_prefix(src()).unwrap_or(&f).display(),
                    me[1],
                    path.join("::")
                ));
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// The file that defines module `path` (`["surface", "dcharts"]`), if it is a module.
fn module_file(path: &[String]) -> Option<PathBuf> {
    let mut p = src();
    for s in path {
        p.push(s);
    }
    let a = p.with_extension("rs");
    let b = p.join("mod.rs");
    if a.is_file() {
        Some(a)
    } else if b.is_file() {
        Some(b)
    } else {
        None
    }
}

/// Whether `name` is declared with plain `pub` (not `pub(crate)`) in the file of `module`.
fn is_public(module: &[String], name: &str) -> bool {
    let Some(file) = module_file(module) else {
        return true;
    };
    let code = code_only(&std::fs::read_to_string(file).unwrap_or_default());
    let kinds = [
        "fn", "struct", "enum", "type", "const", "static", "trait", "mod", "union",
    ];
    for line in code.lines() {
        let t = line.trim_start();
        let Some(rest) = t.strip_prefix("pub ") else {
            continue;
        };
        let rest = rest.trim_start();
        if let Some(u) = rest.strip_prefix("use ") {
            // `pub use a::b::{c, name}` or `pub use x as name`
            if u.split(|c: char| !(c.is_alphanumeric() || c == '_'))
                .any(|w| w == name || w == "*")
            {
                return true;
            }
            continue;
        }
        for k in kinds {
            let decl = rest
                .strip_prefix("const ")
                .filter(|_| k == "fn")
                .unwrap_or(rest);
            let decl = decl.strip_prefix("unsafe ").unwrap_or(decl);
            if let Some(after) = decl.strip_prefix(k).and_then(|r| r.strip_prefix(' ')) {
                let ident: String = after
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if ident == name {
                    return true;
                }
            }
        }
    }
    false
}

#[test]
fn stages_use_only_public_items_of_other_modules() {
    let mut bad = Vec::new();
    for f in all_files() {
        let me = module_of(&f);
        let Some(from) = me.first() else { continue };
        if !STAGES.contains(&from.as_str()) && from != "spec" && from != "profile" {
            continue;
        }
        for (line, path) in references(&f) {
            if path.len() < 2
                || path[0] == *from
                || rank(&path[0]).is_none()
                || path.last().is_some_and(|s| s == "self")
            {
                continue;
            }
            // walk down the module files; the first segment that is no module is the item
            let mut k = 1;
            while k < path.len() && module_file(&path[..=k]).is_some() {
                if !is_public(&path[..k], &path[k]) {
                    break;
                }
                k += 1;
            }
            if k >= path.len() {
                continue; // a whole public module
            }
            if !is_public(&path[..k], &path[k]) {
                bad.push(format!(
                    "{}:{line}: {from} reaches into {} (not a public item of {})",
                    f.strip_prefix(src()).unwrap_or(&f).display(),
                    path.join("::"),
                    path[..k].join("::")
                ));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "{} internal reaches:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn no_cycle_between_the_files_of_a_module() {
    // Edges between sibling submodules (`nest::solve::improve` → `nest::solve::separate`); a module's
    // mod.rs (its parent) is left out: children naming their parent's types is no cycle.
    let mut edges: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for f in all_files() {
        let me = module_of(&f);
        if me.len() < 2 {
            continue;
        }
        for (_, path) in references(&f) {
            // the deepest module prefix of `path` that shares `me`'s parent
            for depth in 2..=path.len().min(me.len()) {
                if path[..depth - 1] == me[..depth - 1]
                    && path[depth - 1] != me[depth - 1]
                    && module_file(&path[..depth]).is_some()
                {
                    edges
                        .entry(me[..depth].to_vec())
                        .or_default()
                        .insert(path[..depth].to_vec());
                }
            }
        }
    }
    let mut cycles = Vec::new();
    let nodes: Vec<_> = edges.keys().cloned().collect();
    for start in &nodes {
        // a path from a successor of `start` back to `start`
        for next in &edges[start] {
            let mut seen = BTreeSet::new();
            let mut stack = vec![vec![next.clone()]];
            while let Some(trail) = stack.pop() {
                let last = trail.last().cloned().unwrap_or_default();
                if last == *start {
                    let names: Vec<String> = std::iter::once(start)
                        .chain(&trail)
                        .map(|m| m.join("::"))
                        .collect();
                    cycles.push(names.join(" → "));
                    break;
                }
                if !seen.insert(last.clone()) {
                    continue;
                }
                for n in edges.get(&last).into_iter().flatten() {
                    let mut t = trail.clone();
                    t.push(n.clone());
                    stack.push(t);
                }
            }
        }
    }
    cycles.sort();
    cycles.dedup();
    assert!(cycles.is_empty(), "import cycles:\n{}", cycles.join("\n"));
}

/// Lines of code of a file outside its `#[cfg(test)] mod …` block (blank and comment lines not
/// counted), and its functions longer than `max_fn` lines (name, first line, length).
fn sizes(text: &str, max_fn: usize) -> (usize, Vec<(String, usize, usize)>) {
    let code = code_only(text);
    let lines: Vec<&str> = code.lines().collect();
    let mut depth: i64 = 0;
    let mut test_depth: Option<i64> = None;
    let mut cfg_test = false;
    let mut count = 0;
    let mut open: Vec<(String, usize, i64)> = Vec::new();
    let mut long = Vec::new();
    for (i, l) in lines.iter().enumerate() {
        let t = l.trim();
        if t.starts_with("#[cfg(test)]") {
            cfg_test = true;
        }
        let is_mod =
            t.starts_with("mod ") || t.starts_with("pub mod ") || t.starts_with("pub(crate) mod ");
        if cfg_test && is_mod && test_depth.is_none() {
            test_depth = Some(depth);
            cfg_test = false;
        } else if cfg_test && !t.is_empty() && !t.starts_with("#[") {
            cfg_test = false;
        }
        if test_depth.is_none() {
            if let Some(p) = t.find("fn ") {
                let before = &t[..p];
                if before.split_whitespace().all(|w| {
                    matches!(
                        w,
                        "pub" | "pub(crate)" | "pub(super)" | "const" | "async" | "unsafe"
                    )
                }) {
                    let name: String = t[p + 3..]
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect();
                    open.push((name, i, depth));
                }
            }
            if !t.is_empty() {
                count += 1;
            }
        }
        depth += l.matches('{').count() as i64 - l.matches('}').count() as i64;
        if let Some(d) = test_depth {
            if depth <= d && l.contains('}') {
                test_depth = None;
            }
        }
        while let Some((_, _, d)) = open.last() {
            if depth <= *d && (l.contains('}') || t.ends_with(';')) {
                let (name, start, _) = open.pop().unwrap_or_default();
                if i + 1 - start > max_fn {
                    long.push((name, start + 1, i + 1 - start));
                }
            } else {
                break;
            }
        }
    }
    (count, long)
}

#[test]
fn no_god_files_and_no_long_functions() {
    let mut bad = Vec::new();
    for f in all_files() {
        let text = std::fs::read_to_string(&f).expect("read source");
        let (count, long) = sizes(&text, 150);
        let name = f.strip_prefix(src()).unwrap_or(&f).display().to_string();
        if count > 1000 {
            bad.push(format!("{name}: {count} lines of code (at most 1,000)"));
        }
        for (fun, line, n) in long {
            bad.push(format!(
                "{name}:{line}: fn {fun} is {n} lines (at most 150)"
            ));
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

#[test]
fn the_scanner_sees_what_it_should() {
    // The checks above are only as good as the scan: it must find a path in a use group,
    // ignore one in a comment or a string, and count a long function.
    assert_eq!(
        expand("{a::b, c::{d, e}, f as g}"),
        vec!["a::b", "c::d", "c::e", "f"]
    );
    assert_eq!(expand("surface::Surface;"), vec!["surface::Surface"]);
    let code = code_only("let s = \"crate::cli\"; // crate::cli\nuse crate::geom; 'c'; 'a");
    assert!(!code.contains("crate::cli"));
    assert!(code.contains("crate::geom"));
    let long = format!("fn f() {{\n{}}}\n", "    x();\n".repeat(160));
    let (count, fns) = sizes(&long, 150);
    assert_eq!(count, 162);
    assert_eq!(fns, vec![("f".to_string(), 1, 162)]);
    let test_mod = format!(
        "fn a() {{}}\n#[cfg(test)]\nmod tests {{\n{}}}\n",
        "x\n".repeat(2000)
    );
    assert_eq!(sizes(&test_mod, 150).0, 2);
}
