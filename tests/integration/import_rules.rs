//! The import rules the docs write down, checked against the code, so the
//! docs cannot drift from it again:
//! - **Crates** (docs/architecture.md, "**Crates.**"): each workspace
//!   crate's `[dependencies]` (and `[target.*.dependencies]`; not
//!   dev-dependencies) among the workspace's own crates are exactly those
//!   the table lists; an extra or a missing one fails, naming the
//!   Cargo.toml.
//! - **Module layers** of a crate (kanren: docs/kanren.md, "### Layers";
//!   logicrag: docs/architecture.md, "**logicrag's modules.**"): the table
//!   says which module may import which, and [`check_layers`] reads it and
//!   every `src/**/*.rs`, finds each module's references to other modules
//!   (`use crate::…`, a `crate::…` path anywhere in the code, `super::…`,
//!   names the crate root re-exports; a submodule counts as its top-level
//!   module), and fails naming the file, the line and the forbidden import
//!   when a module imports a layer below its own, on a module the table does
//!   not list and on a row naming no module. Test code (`tests.rs` files,
//!   modules declared under `#[cfg(test)]`, items under `#[cfg(test)]`) may
//!   import anything; `lib.rs` and the binary's files are exempt.
//!
//! The unit checks at the end run the same parsers on made-up sources and
//! manifests, so that a parser that finds nothing cannot pass for a clean
//! workspace.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

/// The workspace root (this crate is `tests/`).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The rows of the first Markdown table after the line that starts with
/// `marker` (a heading such as `### Layers`, or a bold lead such as
/// `**Crates.**`), each split into trimmed cells (the leading and trailing
/// empty cells dropped); the header row and the separator included. Empty
/// when there is no such line or a heading comes before any table.
fn table_after<'a>(doc: &'a str, marker: &str) -> Vec<Vec<&'a str>> {
    let mut rows = Vec::new();
    let mut lines = doc
        .lines()
        .skip_while(|l| !l.trim_start().starts_with(marker));
    if lines.next().is_none() {
        return rows;
    }
    for line in lines {
        if line.starts_with('|') {
            let mut cells: Vec<&str> = line.split('|').skip(1).map(str::trim).collect();
            if cells.last() == Some(&"") {
                cells.pop();
            }
            rows.push(cells);
        } else if !rows.is_empty() || line.starts_with('#') {
            break;
        }
    }
    rows
}

/// The backticked names of a table cell: `` `a`, `b` `` → `[a, b]`.
fn backticked(cell: &str) -> Vec<String> {
    cell.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// One layer of a module table: its number (1 is the top, what the others
/// build on), its name and its modules.
#[derive(Debug)]
struct Layer {
    rank: usize,
    name: String,
    modules: Vec<String>,
}

/// Reads the rows `| N name | `m1`, `m2` | … |` of the table after the line
/// starting with `marker` in `doc` (named `doc_name` in the error).
fn parse_layers(doc: &str, marker: &str, doc_name: &str) -> Result<Vec<Layer>, String> {
    let mut layers = Vec::new();
    for cells in table_after(doc, marker) {
        let (Some(head), Some(mods)) = (cells.first(), cells.get(1)) else {
            continue;
        };
        let mut words = head.split_whitespace();
        let (Some(rank), Some(name)) = (words.next(), words.next()) else {
            continue;
        };
        let Ok(rank) = rank.parse::<usize>() else {
            continue; // the header row and the separator
        };
        layers.push(Layer {
            rank,
            name: name.to_string(),
            modules: backticked(mods),
        });
    }
    if layers.is_empty() {
        return Err(format!(
            "{doc_name} has no layer table after a line starting with {marker:?}"
        ));
    }
    Ok(layers)
}

/// `src` with comments and the contents of string and character literals
/// blanked out (newlines kept, so byte offsets and line numbers stay).
fn strip(src: &str) -> String {
    let b = src.as_bytes();
    let mut out: Vec<u8> = b.to_vec();
    let blank = |out: &mut Vec<u8>, from: usize, to: usize| {
        for c in out.iter_mut().take(to).skip(from) {
            if *c != b'\n' {
                *c = b' ';
            }
        }
    };
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'/' if b.get(i + 1) == Some(&b'/') => {
                let end = b[i..]
                    .iter()
                    .position(|&c| c == b'\n')
                    .map_or(b.len(), |p| i + p);
                blank(&mut out, i, end);
                i = end;
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                let (mut depth, mut j) = (1, i + 2);
                while j < b.len() && depth > 0 {
                    if b[j] == b'/' && b.get(j + 1) == Some(&b'*') {
                        depth += 1;
                        j += 2;
                    } else if b[j] == b'*' && b.get(j + 1) == Some(&b'/') {
                        depth -= 1;
                        j += 2;
                    } else {
                        j += 1;
                    }
                }
                blank(&mut out, i, j);
                i = j;
            }
            b'r' if (b.get(i + 1) == Some(&b'"') || b.get(i + 1) == Some(&b'#'))
                && (i == 0 || !is_ident(b[i - 1])) =>
            {
                // A raw string: r"…", r#"…"#, …
                let hashes = b[i + 1..].iter().take_while(|&&c| c == b'#').count();
                if b.get(i + 1 + hashes) != Some(&b'"') {
                    i += 1;
                    continue;
                }
                let body = i + 2 + hashes;
                let close: Vec<u8> = std::iter::once(b'"')
                    .chain(std::iter::repeat_n(b'#', hashes))
                    .collect();
                let end = b[body..]
                    .windows(close.len())
                    .position(|w| w == close.as_slice())
                    .map_or(b.len(), |p| body + p);
                blank(&mut out, body, end);
                i = end + close.len();
            }
            b'"' => {
                let mut j = i + 1;
                while j < b.len() && b[j] != b'"' {
                    j += if b[j] == b'\\' { 2 } else { 1 };
                }
                blank(&mut out, i + 1, j.min(b.len()));
                i = j + 1;
            }
            b'\'' => {
                // A character literal ('x', '\n', '\u{…}', '{'), not a
                // lifetime ('a).
                let end = if b.get(i + 1) == Some(&b'\\') {
                    b[i + 2..]
                        .iter()
                        .position(|&c| c == b'\'')
                        .map(|p| i + 2 + p)
                } else {
                    let ch = src[i + 1..].chars().next().map_or(1, char::len_utf8);
                    (b.get(i + 1 + ch) == Some(&b'\'')).then_some(i + 1 + ch)
                };
                match end {
                    Some(e) => {
                        blank(&mut out, i + 1, e);
                        i = e + 1;
                    }
                    None => i += 1,
                }
            }
            _ => i += 1,
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// A token of stripped source: an identifier, `::`, or one punctuation
/// byte; with its byte offset.
fn tokens(s: &str) -> Vec<(usize, &str)> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if is_ident(c) {
            let start = i;
            while i < b.len() && is_ident(b[i]) {
                i += 1;
            }
            out.push((start, &s[start..i]));
        } else if c == b':' && b.get(i + 1) == Some(&b':') {
            out.push((i, "::"));
            i += 2;
        } else {
            let len = s[i..].chars().next().map_or(1, char::len_utf8);
            out.push((i, &s[i..i + len]));
            i += len;
        }
    }
    out
}

/// The byte ranges of the items under `#[cfg(test)]` in stripped source.
fn test_spans(s: &str) -> Vec<(usize, usize)> {
    let b = s.as_bytes();
    let mut spans = Vec::new();
    let mut from = 0;
    while let Some(p) = s[from..].find("#[cfg(test)]") {
        let start = from + p;
        let mut j = start + "#[cfg(test)]".len();
        // The item ends at its first `;` outside braces, or at the brace
        // that closes its first `{`.
        let mut depth = 0usize;
        while j < b.len() {
            match b[j] {
                b'{' => depth += 1,
                b'}' => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        break;
                    }
                }
                b';' if depth == 0 => break,
                _ => {}
            }
            j += 1;
        }
        spans.push((start, j + 1));
        from = j + 1;
    }
    spans
}

/// A reference from one module to another.
#[derive(Debug, PartialEq)]
struct Import {
    /// 1-based.
    line: usize,
    /// The top-level module referred to.
    target: String,
}

/// The modules the code of the module at `path` (its file's module path,
/// e.g. `["facts", "goal"]`) refers to, outside test code. `modules` are the
/// crate's top-level modules; `reexports` maps each name the crate root
/// re-exports to the top-level module it comes from.
fn imports(
    src: &str,
    path: &[&str],
    modules: &BTreeSet<String>,
    reexports: &HashMap<String, String>,
) -> Vec<Import> {
    let s = strip(src);
    let spans = test_spans(&s);
    let toks = tokens(&s);
    let line_of = |off: usize| s[..off].bytes().filter(|&c| c == b'\n').count() + 1;
    // The top-level module a path's first segment after the crate root
    // names: a module, or a re-exported name.
    let resolve = |name: &str| -> Option<String> {
        if modules.contains(name) {
            Some(name.to_string())
        } else {
            reexports.get(name).cloned()
        }
    };
    let mut out = Vec::new();
    let mut i = 0;
    while i < toks.len() {
        let (off, tok) = toks[i];
        if spans.iter().any(|&(a, b)| off >= a && off < b) {
            i += 1;
            continue;
        }
        let path_start = (tok == "crate" || tok == "super")
            && toks.get(i + 1).map(|t| t.1) == Some("::")
            && (i == 0 || toks[i - 1].1 != "::");
        if !path_start {
            i += 1;
            continue;
        }
        // Where the path starts: the crate root, or an ancestor module.
        let mut j = i;
        let mut base: Vec<&str> = Vec::new();
        if tok == "super" {
            let mut ups = 0;
            while toks.get(j).map(|t| t.1) == Some("super")
                && toks.get(j + 1).map(|t| t.1) == Some("::")
            {
                ups += 1;
                j += 2;
            }
            base = path[..path.len().saturating_sub(ups)].to_vec();
        } else {
            j += 2;
        }
        if let Some(top) = base.first() {
            out.push(Import {
                line: line_of(off),
                target: (*top).to_string(),
            });
            i = j;
            continue;
        }
        // From the crate root: one name, or a `{…}` group of paths, each
        // resolved by its first segment.
        let mut firsts: Vec<(usize, &str)> = Vec::new();
        match toks.get(j) {
            Some(&(_, "{")) => {
                let mut depth = 0;
                let mut expect_first = true;
                while let Some(&(o, t)) = toks.get(j) {
                    match t {
                        "{" => {
                            depth += 1;
                            expect_first = depth == 1;
                        }
                        "}" => {
                            depth -= 1;
                            if depth == 0 {
                                break;
                            }
                        }
                        "," if depth == 1 => expect_first = true,
                        _ if expect_first && depth == 1 => {
                            firsts.push((o, t));
                            expect_first = false;
                        }
                        _ => {}
                    }
                    j += 1;
                }
            }
            Some(&(o, t)) => firsts.push((o, t)),
            None => {}
        }
        for (o, name) in firsts {
            if let Some(target) = resolve(name) {
                out.push(Import {
                    line: line_of(o),
                    target,
                });
            }
        }
        i = j + 1;
    }
    out
}

/// The names `lib.rs` re-exports (`pub use module::{A, B as C}`), each
/// mapped to its top-level module.
fn reexports(lib: &str, modules: &BTreeSet<String>) -> HashMap<String, String> {
    let s = strip(lib);
    let toks = tokens(&s);
    let mut map = HashMap::new();
    let mut i = 0;
    while i + 1 < toks.len() {
        if toks[i].1 == "pub" && toks[i + 1].1 == "use" {
            let mut j = i + 2;
            let Some(&(_, module)) = toks.get(j) else {
                break;
            };
            let stmt_end = toks[j..]
                .iter()
                .position(|t| t.1 == ";")
                .map_or(toks.len(), |p| j + p);
            if modules.contains(module) {
                // The leaves: a name followed by `,`, `}` or `;` (after an
                // `as`, the new name).
                while j < stmt_end {
                    let next = toks.get(j + 1).map(|t| t.1);
                    if matches!(next, Some("," | "}" | ";")) && toks[j].1 != "}" {
                        map.insert(toks[j].1.to_string(), module.to_string());
                    }
                    j += 1;
                }
            }
            i = stmt_end;
        }
        i += 1;
    }
    map
}

/// A source file of the crate: its path below `src`, and its module path.
fn module_files(src: &Path) -> Vec<(PathBuf, Vec<String>)> {
    let mut out = Vec::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let rel = p.strip_prefix(src).unwrap_or(&p).to_path_buf();
                let mut parts: Vec<String> = rel
                    .with_extension("")
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                if parts.last().is_some_and(|l| l == "mod" || l == "lib") {
                    parts.pop();
                }
                out.push((rel, parts));
            }
        }
    }
    out.sort();
    out
}

/// A crate's layer table and what its check needs besides the sources.
struct Rules<'a> {
    /// The doc the table comes from, as messages name it.
    doc: &'a str,
    /// The crate's source folder as messages name it (`kanren/src`).
    src: &'a str,
    /// Top-level names of `src` outside the table, never checked: the
    /// binary's (`main.rs`, `cli/`). `lib.rs`, the crate root, declares
    /// and re-exports all modules and is always exempt.
    exempt: &'a [&'a str],
    layers: Vec<Layer>,
}

/// The module paths declared under `#[cfg(test)]` (`#[cfg(test)] mod x;`
/// in a file of module path `p` declares `p::x`): their files are test code.
fn test_modules(files: &[(String, Vec<String>, String)]) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for (_, path, text) in files {
        let s = strip(text);
        for (a, b) in test_spans(&s) {
            let toks = tokens(&s[a..b.min(s.len())]);
            for w in toks.windows(3) {
                if w[0].1 == "mod" && w[2].1 == ";" && w[1].1.bytes().all(is_ident) {
                    let mut child = path.clone();
                    child.push(w[1].1.to_string());
                    out.push(child);
                }
            }
        }
    }
    out
}

/// Whether a file (its path below `src`, its module path) is test code.
fn is_test_file(file: &str, path: &[String], test_mods: &[Vec<String>]) -> bool {
    file == "tests.rs"
        || file.ends_with("/tests.rs")
        || path.iter().any(|p| p == "tests")
        || test_mods.iter().any(|t| path.starts_with(t))
}

/// Every breach of the layer table in the crate's sources, one line each.
fn violations(rules: &Rules, files: &[(String, Vec<String>, String)]) -> Vec<String> {
    let (doc, src) = (rules.doc, rules.src);
    let rank: BTreeMap<&str, (usize, &str)> = rules
        .layers
        .iter()
        .flat_map(|l| {
            l.modules
                .iter()
                .map(move |m| (m.as_str(), (l.rank, l.name.as_str())))
        })
        .collect();
    let modules: BTreeSet<String> = files
        .iter()
        .filter_map(|(_, p, _)| p.first().cloned())
        .filter(|m| !rules.exempt.contains(&m.as_str()))
        .collect();
    let lib = files
        .iter()
        .find(|(_, p, _)| p.is_empty())
        .map_or("", |f| f.2.as_str());
    let reexports = reexports(lib, &modules);
    let test_mods = test_modules(files);
    let mut out = Vec::new();
    for m in &modules {
        if !rank.contains_key(m.as_str()) {
            out.push(format!(
                "{src}: module `{m}` is in no layer of {doc}'s table"
            ));
        }
    }
    for name in rank.keys() {
        if !modules.contains(*name) {
            out.push(format!(
                "{doc}: the layer table lists `{name}`, which is no module of {src}"
            ));
        }
    }
    for (file, path, text) in files {
        let Some(own) = path.first() else {
            continue; // lib.rs: the crate root declares and re-exports all
        };
        if !modules.contains(own) || is_test_file(file, path, &test_mods) {
            continue;
        }
        let Some(&(own_rank, own_layer)) = rank.get(own.as_str()) else {
            continue;
        };
        let path: Vec<&str> = path.iter().map(String::as_str).collect();
        for imp in imports(text, &path, &modules, &reexports) {
            let Some(&(r, layer)) = rank.get(imp.target.as_str()) else {
                continue;
            };
            if r > own_rank {
                let code = text.lines().nth(imp.line - 1).unwrap_or("").trim();
                out.push(format!(
                    "{src}/{file}:{}: `{own}` (layer {own_rank} {own_layer}) imports `{}` \
                     (layer {r} {layer}), a layer below it: {code}",
                    imp.line, imp.target
                ));
            }
        }
    }
    out
}

/// Per module of the table, how many imports of a layer above its own the
/// parser finds in its non-test code: a parser that finds nothing would
/// pass any crate, so the checks below require some.
fn upward_imports(
    rules: &Rules,
    files: &[(String, Vec<String>, String)],
) -> BTreeMap<String, usize> {
    let rank: BTreeMap<&str, usize> = rules
        .layers
        .iter()
        .flat_map(|l| l.modules.iter().map(move |m| (m.as_str(), l.rank)))
        .collect();
    let modules: BTreeSet<String> = files
        .iter()
        .filter_map(|(_, p, _)| p.first().cloned())
        .filter(|m| !rules.exempt.contains(&m.as_str()))
        .collect();
    let lib = files
        .iter()
        .find(|(_, p, _)| p.is_empty())
        .map_or("", |f| f.2.as_str());
    let reexports = reexports(lib, &modules);
    let test_mods = test_modules(files);
    let mut seen: BTreeMap<String, usize> = rank.keys().map(|m| (m.to_string(), 0)).collect();
    for (file, path, text) in files {
        let Some(own) = path.first() else { continue };
        let Some(&own_rank) = rank.get(own.as_str()) else {
            continue;
        };
        if !modules.contains(own) || is_test_file(file, path, &test_mods) {
            continue;
        }
        let p: Vec<&str> = path.iter().map(String::as_str).collect();
        let n = imports(text, &p, &modules, &reexports)
            .iter()
            .filter(|i| rank.get(i.target.as_str()).is_some_and(|&r| r < own_rank))
            .count();
        *seen.entry(own.clone()).or_default() += n;
    }
    seen
}

/// Checks the crate at `crate_dir` (relative to the workspace root) against
/// the layer table after the line starting with `marker` in `doc`:
/// returns every breach, one line each. `exempt` are the binary's top-level
/// names of `src`. Every layer below the first must be seen importing a
/// layer above it somewhere, and every module of the layers in
/// `each_imports_above` on its own (else the parser is broken).
fn check_layers(
    crate_dir: &str,
    doc: &str,
    marker: &str,
    exempt: &[&str],
    each_imports_above: &[usize],
) -> Vec<String> {
    let layers = parse_layers(&read(doc), marker, doc).unwrap_or_else(|e| panic!("{e}"));
    let src_rel = format!("{crate_dir}/src");
    let src = root().join(&src_rel);
    let files: Vec<(String, Vec<String>, String)> = module_files(&src)
        .into_iter()
        .map(|(rel, path)| {
            let text = std::fs::read_to_string(src.join(&rel))
                .unwrap_or_else(|e| panic!("{src_rel}/{}: {e}", rel.display()));
            (rel.to_string_lossy().replace('\\', "/"), path, text)
        })
        .collect();
    let rules = Rules {
        doc,
        src: &src_rel,
        exempt,
        layers,
    };
    let mut bad = violations(&rules, &files);
    let seen = upward_imports(&rules, &files);
    for layer in rules.layers.iter().filter(|l| l.rank > 1) {
        let counts: Vec<(&String, usize)> = layer
            .modules
            .iter()
            .map(|m| (m, seen.get(m).copied().unwrap_or(0)))
            .collect();
        if counts.iter().all(|&(_, n)| n == 0) {
            bad.push(format!(
                "parser: no module of layer {} {} of {src_rel} seen importing a layer above",
                layer.rank, layer.name
            ));
        }
        if each_imports_above.contains(&layer.rank) {
            for (m, _) in counts.iter().filter(|&&(_, n)| n == 0) {
                bad.push(format!(
                    "parser: found no import of a layer above in `{m}` of {src_rel}"
                ));
            }
        }
    }
    bad
}

#[test]
fn kanren_modules_import_only_their_own_layer_and_those_above() {
    // Every store module imports the core.
    let bad = check_layers("kanren", "docs/kanren.md", "### Layers", &[], &[2]);
    assert!(
        bad.is_empty(),
        "kanren's import rules broken:\n{}",
        bad.join("\n")
    );
}

#[test]
fn logicrag_modules_import_only_their_own_layer_and_those_above() {
    // `main.rs` and `cli/` are the binary's: it sits on top of all.
    let bad = check_layers(
        "logicrag",
        "docs/architecture.md",
        "**logicrag's modules.**",
        &["main", "cli"],
        &[],
    );
    assert!(
        bad.is_empty(),
        "logicrag's import rules broken:\n{}",
        bad.join("\n")
    );
}

/// Workspace members outside the crate table: test harnesses, which depend
/// on every crate to test it (`tests/`, the integration tests; `fuzz/`,
/// the parsers' fuzz harness).
const HARNESSES: &[&str] = &["tests", "fuzz"];

/// `line` without its `#` comment (a `#` inside a quoted string stays).
fn uncomment(line: &str) -> &str {
    let mut quote = None;
    for (i, c) in line.char_indices() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), _) if c == q => quote = None,
            (None, '#') => return &line[..i],
            _ => {}
        }
    }
    line
}

/// A dotted TOML key split into its parts, quotes removed:
/// `target.'cfg(unix)'.dependencies` → `[target, cfg(unix), dependencies]`.
fn key_parts(key: &str) -> Vec<String> {
    let mut parts = vec![String::new()];
    let mut quote = None;
    for c in key.chars() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), _) if c == q => quote = None,
            (None, '.') => parts.push(String::new()),
            (None, c) if c.is_whitespace() => {}
            (_, c) => {
                if let Some(last) = parts.last_mut() {
                    last.push(c);
                }
            }
        }
    }
    parts
}

/// The string value of `key = "…"` inside `text` (an inline table or a
/// line), if any.
fn string_value(text: &str, key: &str) -> Option<String> {
    let mut from = 0;
    while let Some(p) = text[from..].find(key) {
        let at = from + p;
        from = at + key.len();
        let before_ok = text[..at]
            .chars()
            .next_back()
            .is_none_or(|c| !(c.is_ascii_alphanumeric() || c == '_' || c == '-'));
        let rest = text[from..].trim_start();
        if let (true, Some(rest)) = (before_ok, rest.strip_prefix('='))
            && let Some(rest) = rest.trim_start().strip_prefix('"')
        {
            return rest.find('"').map(|e| rest[..e].to_string());
        }
    }
    None
}

/// The package name of a manifest (`[package] name = "…"`).
fn package_name(manifest: &str) -> Option<String> {
    let mut in_package = false;
    for line in manifest.lines().map(|l| uncomment(l).trim()) {
        if line.starts_with('[') {
            in_package = line == "[package]";
        } else if in_package && key_parts(line.split('=').next().unwrap_or("")) == ["name"] {
            return string_value(line, "name");
        }
    }
    None
}

/// The packages a manifest depends on through `[dependencies]`,
/// `[dependencies.NAME]`, `[target.*.dependencies]` and
/// `[target.*.dependencies.NAME]`, a renamed one (`package = "…"`) by its
/// package; dev- and build-dependencies not.
fn dependencies(manifest: &str) -> BTreeSet<String> {
    // Each dependency key with its package, where renamed.
    let mut deps: BTreeMap<String, Option<String>> = BTreeMap::new();
    // In a dependency list; or in one dependency's own table.
    let mut in_list = false;
    let mut in_table: Option<String> = None;
    let mut entry = String::new();
    let balance = |s: &str| s.matches('{').count() as isize - s.matches('}').count() as isize;
    for line in manifest.lines().map(uncomment) {
        let trimmed = line.trim();
        if entry.is_empty() && trimmed.starts_with('[') {
            let header = trimmed.trim_start_matches('[').trim_end_matches(']');
            let parts = key_parts(header);
            let parts: Vec<&str> = parts.iter().map(String::as_str).collect();
            let (list, table) = match parts.as_slice() {
                ["dependencies"] | ["target", _, "dependencies"] => (true, None),
                ["dependencies", name] | ["target", _, "dependencies", name] => {
                    (false, Some(name.to_string()))
                }
                _ => (false, None),
            };
            in_list = list;
            in_table = table;
            if let Some(name) = &in_table {
                deps.entry(name.clone()).or_default();
            }
            continue;
        }
        if let Some(name) = &in_table {
            if key_parts(trimmed.split('=').next().unwrap_or("")) == ["package"] {
                deps.insert(name.clone(), string_value(trimmed, "package"));
            }
            continue;
        }
        if !in_list || (entry.is_empty() && trimmed.is_empty()) {
            continue;
        }
        // An entry may be an inline table over several lines.
        entry.push_str(line);
        entry.push('\n');
        if balance(&entry) > 0 {
            continue;
        }
        let key = key_parts(entry.split('=').next().unwrap_or(""));
        if let Some(name) = key.first().filter(|n| !n.is_empty()) {
            let renamed = if key.get(1).is_some_and(|k| k == "package") {
                string_value(&entry, "package")
            } else if key.len() == 1 {
                entry
                    .find('{')
                    .and_then(|b| string_value(&entry[b..], "package"))
            } else {
                None
            };
            let slot = deps.entry(name.clone()).or_default();
            if renamed.is_some() {
                *slot = renamed;
            }
        }
        entry.clear();
    }
    deps.into_iter().map(|(k, p)| p.unwrap_or(k)).collect()
}

/// The rows of the crate table after `**Crates.**` in docs/architecture.md:
/// each crate and the crates of ours it depends on.
fn crate_table(doc: &str) -> BTreeMap<String, BTreeSet<String>> {
    table_after(doc, "**Crates.**")
        .iter()
        .filter_map(|cells| {
            let name = backticked(cells.first()?).into_iter().next()?;
            let deps = cells.get(1).map(|c| backticked(c)).unwrap_or_default();
            Some((name, deps.into_iter().collect()))
        })
        .collect()
}

/// The members of the workspace manifest (`members = [ … ]`).
fn members(workspace: &str) -> Vec<String> {
    let Some((at, _)) = workspace
        .match_indices("members")
        .find(|&(i, _)| workspace[..i].ends_with('\n') || i == 0)
    else {
        return Vec::new();
    };
    let rest = &workspace[at..];
    let (Some(open), Some(close)) = (rest.find('['), rest.find(']')) else {
        return Vec::new();
    };
    rest[open + 1..close]
        .split(',')
        .map(|m| m.trim().trim_matches('"').to_string())
        .filter(|m| !m.is_empty())
        .collect()
}

/// Every difference between the crate table and the members' manifests
/// (each a member folder and its Cargo.toml's text), one line each.
fn crate_violations(
    table: &BTreeMap<String, BTreeSet<String>>,
    manifests: &[(String, String)],
) -> Vec<String> {
    const DOC: &str = "docs/architecture.md";
    let names: Vec<(&str, String)> = manifests
        .iter()
        .map(|(dir, text)| {
            (
                dir.as_str(),
                package_name(text).unwrap_or_else(|| dir.clone()),
            )
        })
        .collect();
    // Ours: the members and every crate the table names.
    let ours: BTreeSet<&str> = names
        .iter()
        .map(|(_, n)| n.as_str())
        .chain(
            table
                .iter()
                .flat_map(|(k, v)| std::iter::once(k.as_str()).chain(v.iter().map(String::as_str))),
        )
        .collect();
    let mut out = Vec::new();
    for ((dir, text), (_, name)) in manifests.iter().zip(&names) {
        if HARNESSES.contains(&dir.as_str()) {
            continue;
        }
        let Some(listed) = table.get(name) else {
            out.push(format!(
                "{dir}/Cargo.toml: crate `{name}` is in no row of {DOC}'s crate table"
            ));
            continue;
        };
        let actual: BTreeSet<String> = dependencies(text)
            .into_iter()
            .filter(|d| ours.contains(d.as_str()))
            .collect();
        for d in actual.difference(listed) {
            out.push(format!(
                "{dir}/Cargo.toml: `{name}` depends on `{d}`, which {DOC}'s crate table does not list"
            ));
        }
        for d in listed.difference(&actual) {
            out.push(format!(
                "{dir}/Cargo.toml: `{name}` does not depend on `{d}`, which {DOC}'s crate table lists"
            ));
        }
    }
    for name in table.keys() {
        if !names.iter().any(|(_, n)| n == name) {
            out.push(format!(
                "{DOC}: the crate table lists `{name}`, which is no workspace member"
            ));
        }
    }
    out
}

#[test]
fn crates_depend_on_exactly_the_crates_the_docs_list() {
    let table = crate_table(&read("docs/architecture.md"));
    assert!(
        table.len() >= 4,
        "docs/architecture.md: no crate table after \"**Crates.**\": {table:?}"
    );
    let manifests: Vec<(String, String)> = members(&read("Cargo.toml"))
        .into_iter()
        .map(|dir| {
            let text = read(&format!("{dir}/Cargo.toml"));
            (dir, text)
        })
        .collect();
    assert!(
        manifests.len() >= 4,
        "no workspace members found: {manifests:?}"
    );
    let bad = crate_violations(&table, &manifests);
    assert!(
        bad.is_empty(),
        "crate dependencies broken:\n{}",
        bad.join("\n")
    );
}

/// The layers and modules of the unit checks below.
fn toy_layers() -> Vec<Layer> {
    let layer = |rank, name: &str, mods: &[&str]| Layer {
        rank,
        name: name.into(),
        modules: mods.iter().map(|m| m.to_string()).collect(),
    };
    vec![
        layer(1, "core", &["term", "goal"]),
        layer(2, "store", &["facts", "join"]),
        layer(3, "client", &["classic"]),
    ]
}

/// The toy table's rules, with `main.rs` and `cli/` as the binary's.
fn toy_rules(layers: Vec<Layer>) -> Rules<'static> {
    Rules {
        doc: "docs/kanren.md",
        src: "src",
        exempt: &["main", "cli"],
        layers,
    }
}

fn toy() -> Rules<'static> {
    toy_rules(toy_layers())
}

fn toy_crate(extra: &[(&str, &[&str], &str)]) -> Vec<(String, Vec<String>, String)> {
    let mut files: Vec<(String, Vec<String>, String)> = vec![
        (
            "lib.rs".into(),
            vec![],
            "pub mod facts;\npub use facts::{Relation, fact as fact_goal};\npub use term::Term;\n"
                .into(),
        ),
        ("term.rs".into(), vec!["term".into()], String::new()),
        ("goal.rs".into(), vec!["goal".into()], String::new()),
        ("facts.rs".into(), vec!["facts".into()], String::new()),
        ("join.rs".into(), vec!["join".into()], String::new()),
        ("classic.rs".into(), vec!["classic".into()], String::new()),
    ];
    for (file, path, text) in extra {
        files.retain(|f| f.0 != *file);
        files.push((
            file.to_string(),
            path.iter().map(|p| p.to_string()).collect(),
            text.to_string(),
        ));
    }
    files
}

#[test]
fn a_core_module_importing_the_store_is_caught_with_file_and_line() {
    let src = "//! A core module.\nuse crate::term::Term;\nuse crate::facts::Relation;\n";
    let bad = violations(&toy(), &toy_crate(&[("goal.rs", &["goal"], src)]));
    assert_eq!(bad.len(), 1, "{bad:?}");
    assert!(
        bad[0].starts_with("src/goal.rs:3: `goal` (layer 1 core) imports `facts` (layer 2 store)"),
        "{bad:?}"
    );
    assert!(bad[0].ends_with("use crate::facts::Relation;"), "{bad:?}");
}

#[test]
fn groups_inline_paths_reexports_and_super_are_all_seen() {
    let src = "use crate::{term::Term, join::Cursor};\n\
               fn f() { let _ = crate::facts::Relation::new(\"r\", 1); }\n\
               use crate::{Relation};\n\
               use crate::fact_goal;\n";
    let bad = violations(&toy(), &toy_crate(&[("goal.rs", &["goal"], src)]));
    let lines: Vec<&str> = bad
        .iter()
        .map(|b| &b[..b.find(": `").unwrap_or(0)])
        .collect();
    assert_eq!(
        lines,
        [
            "src/goal.rs:1",
            "src/goal.rs:2",
            "src/goal.rs:3",
            "src/goal.rs:4"
        ],
        "{bad:?}"
    );
    // `super::super::classic` from a file two levels down in `join`.
    let nested = "use super::super::classic::zebrao;\nuse super::Cursor;\n";
    let bad = violations(
        &toy(),
        &toy_crate(&[("join/plan/x.rs", &["join", "plan", "x"], nested)]),
    );
    assert!(
        bad.is_empty(),
        "super::super from join/plan/x is join: {bad:?}"
    );
    let up = "use super::super::classic::zebrao;\n";
    let bad = violations(&toy(), &toy_crate(&[("join/x.rs", &["join", "x"], up)]));
    assert_eq!(bad.len(), 1, "{bad:?}");
    assert!(bad[0].contains("imports `classic`"), "{bad:?}");
}

#[test]
fn comments_strings_test_code_and_upward_imports_pass() {
    let src = "// use crate::facts::Relation;\n\
               /* crate::join::Cursor */\n\
               const S: &str = \"crate::facts::fact\";\n\
               const R: &str = r#\"crate::join\"#;\n\
               const C: char = '{';\n\
               fn g<'a>(x: &'a str) -> &'a str { x }\n\
               #[cfg(test)]\n\
               mod tests {\n    use crate::facts::Relation;\n    fn h() { let _ = '}'; }\n}\n\
               #[cfg(test)]\n\
               use crate::join::Cursor;\n\
               use crate::term::Term;\n";
    let bad = violations(&toy(), &toy_crate(&[("goal.rs", &["goal"], src)]));
    assert!(bad.is_empty(), "{bad:?}");
    // The same test module after the real code: still only test code.
    let found = imports(
        src,
        &["goal"],
        &["term", "goal", "facts", "join", "classic"]
            .iter()
            .map(|s| s.to_string())
            .collect(),
        &HashMap::new(),
    );
    assert_eq!(
        found,
        [Import {
            line: 14,
            target: "term".into()
        }]
    );
    // A store module may import the core and its own layer; a client both.
    let store = "use crate::term::Term;\nuse crate::facts::Relation;\n";
    let client = "use crate::join::Cursor;\nuse crate::goal::Goal;\n";
    let bad = violations(
        &toy(),
        &toy_crate(&[
            ("join.rs", &["join"], store),
            ("classic.rs", &["classic"], client),
        ]),
    );
    assert!(bad.is_empty(), "{bad:?}");
}

#[test]
fn modules_missing_from_the_table_and_stale_rows_are_caught() {
    let mut layers = toy_layers();
    layers[1].modules.push("gone".into());
    let bad = violations(
        &toy_rules(layers),
        &toy_crate(&[("goal.rs", &["goal"], ""), ("extra.rs", &["extra"], "")]),
    );
    assert!(
        bad.iter().any(|b| b.contains("`extra` is in no layer")),
        "{bad:?}"
    );
    assert!(bad.iter().any(|b| b.contains("lists `gone`")), "{bad:?}");
    let doc = "# x\n### Layers\n| layer | modules |\n|---|---|\n| 1 core | `term`, `goal` |\n\
               | 2 store | `facts` |\n## Next\n| 3 nope | `x` |\n";
    let parsed = parse_layers(doc, "### Layers", "x.md").unwrap_or_default();
    let got: Vec<(usize, &str, usize)> = parsed
        .iter()
        .map(|l| (l.rank, l.name.as_str(), l.modules.len()))
        .collect();
    assert_eq!(got, [(1, "core", 2), (2, "store", 1)]);
    assert!(parse_layers("# no table\n", "### Layers", "x.md").is_err());
    assert!(
        parse_layers(
            "### Layers\n## Next\n| 1 core | `a` |\n",
            "### Layers",
            "x.md"
        )
        .is_err()
    );
    // A table after a bold lead, as docs/architecture.md writes logicrag's;
    // the table before it and the text after it are not read.
    let doc = "**Crates.** x\n\n| crate | deps |\n|---|---|\n| `a` | `b` |\n\n\
               **logicrag's modules.** A module may…\n\n\
               | layer | modules | what |\n|---|---|---|\n\
               | 1 text | `translate`, `facts_text` | q |\n| 2 core | `kb`, `llm` | k |\n\
               \nAfter.\n| 3 nope | `x` |\n";
    let parsed = parse_layers(doc, "**logicrag's modules.**", "x.md").unwrap_or_default();
    let got: Vec<(usize, &str, Vec<String>)> = parsed
        .iter()
        .map(|l| (l.rank, l.name.as_str(), l.modules.clone()))
        .collect();
    assert_eq!(
        got,
        [
            (
                1,
                "text",
                vec!["translate".to_string(), "facts_text".into()]
            ),
            (2, "core", vec!["kb".to_string(), "llm".into()])
        ]
    );
}

#[test]
fn submodules_count_as_their_module_and_the_binary_and_test_modules_are_exempt() {
    // `join/plan.rs` is `join` (layer 2): importing `classic` is caught.
    let sub = "use crate::classic::zebrao;\n";
    let bad = violations(
        &toy(),
        &toy_crate(&[("join/plan.rs", &["join", "plan"], sub)]),
    );
    assert_eq!(bad.len(), 1, "{bad:?}");
    assert!(
        bad[0].starts_with("src/join/plan.rs:1: `join` (layer 2 store) imports `classic`"),
        "{bad:?}"
    );
    // The binary's files import anything and are in no layer.
    let bin = "use crate::cli::run;\nfn main() { crate::classic::zebrao(); }\n";
    let bad = violations(
        &toy(),
        &toy_crate(&[
            ("main.rs", &["main"], bin),
            ("cli/mod.rs", &["cli"], "use crate::classic::zebrao;\n"),
            (
                "cli/ask.rs",
                &["cli", "ask"],
                "use super::super::term::Term;\n",
            ),
        ]),
    );
    assert!(bad.is_empty(), "{bad:?}");
    // A module declared under `#[cfg(test)]` is test code, in any file;
    // declared without it, its file is checked.
    let parent = "#[cfg(test)]\nmod type_tests;\n";
    let child = "use crate::facts::Relation;\n";
    let bad = violations(
        &toy(),
        &toy_crate(&[
            ("goal.rs", &["goal"], parent),
            ("goal/type_tests.rs", &["goal", "type_tests"], child),
        ]),
    );
    assert!(bad.is_empty(), "{bad:?}");
    let bad = violations(
        &toy(),
        &toy_crate(&[
            ("goal.rs", &["goal"], "mod type_tests;\n"),
            ("goal/type_tests.rs", &["goal", "type_tests"], child),
        ]),
    );
    assert_eq!(bad.len(), 1, "{bad:?}");
    assert!(bad[0].starts_with("src/goal/type_tests.rs:1:"), "{bad:?}");
}

#[test]
fn the_parser_sanity_count_sees_upward_imports_only() {
    let files = toy_crate(&[
        (
            "facts.rs",
            &["facts"],
            "use crate::term::Term;\nuse crate::join::X;\n",
        ),
        (
            "classic.rs",
            &["classic"],
            "#[cfg(test)]\nuse crate::goal::Goal;\n",
        ),
    ]);
    let seen = upward_imports(&toy(), &files);
    assert_eq!(seen.get("facts"), Some(&1), "{seen:?}");
    assert_eq!(seen.get("join"), Some(&0), "{seen:?}");
    assert_eq!(seen.get("classic"), Some(&0), "{seen:?}");
}

/// A made-up member manifest.
const TOY_MANIFEST: &str = r#"
[package]
name = "toy" # the crate
version = "0.1.0"

[features]
default = ["kanren"] # not a dependency

[dependencies]
kanren.workspace = true
serde = { workspace = true, features = ["derive"] }
lp = { path = "../logicpad",
       package = "logicpad" }
"pad#" = "1"

[dependencies.vision]
package = "perception"
optional = true

[target.'cfg(unix)'.dependencies]
logicrag = { path = "../logicrag", default-features = false }

[dev-dependencies]
logicrag-py.workspace = true

[build-dependencies]
kanren-build = "1"

[[bench]]
name = "logicrag"
"#;

#[test]
fn manifests_are_read_for_dependencies_renames_and_target_tables() {
    assert_eq!(package_name(TOY_MANIFEST).as_deref(), Some("toy"));
    let deps: Vec<String> = dependencies(TOY_MANIFEST).into_iter().collect();
    assert_eq!(
        deps,
        [
            "kanren",
            "logicpad",
            "logicrag",
            "pad#",
            "perception",
            "serde"
        ],
        "dev- and build-dependencies, features and targets are not dependencies"
    );
    let ws = "[workspace]\nresolver = \"3\"\nmembers = [\"kanren\", \"tests\",\n  \"toy\"]\n\
              default-members = [\"x\"]\n";
    assert_eq!(members(ws), ["kanren", "tests", "toy"]);
}

#[test]
fn extra_missing_and_unlisted_crate_dependencies_are_caught() {
    let doc = "x\n**Crates.** Each crate…\n\n| crate | depends on (of ours) |\n|---|---|\n\
               | `kanren` | — |\n| `toy` | `kanren`, `logicpad`, `logicrag`, `perception` |\n\
               | `gone` | `kanren` |\n\n**Next.**\n| `late` | — |\n";
    let table = crate_table(doc);
    assert_eq!(table.keys().collect::<Vec<_>>(), ["gone", "kanren", "toy"]);
    assert!(table["kanren"].is_empty());
    let kanren = (
        "kanren".to_string(),
        "[package]\nname = \"kanren\"\n".to_string(),
    );
    let toy = ("toy".to_string(), TOY_MANIFEST.to_string());
    let harness = (
        "tests".to_string(),
        "[package]\nname = \"integration-tests\"\n[dependencies]\nkanren.workspace = true\n"
            .to_string(),
    );
    let other = (
        "logicpad".to_string(),
        "[package]\nname = \"logicpad\"\n[dependencies]\nkanren.workspace = true\n".to_string(),
    );
    let manifests = [kanren.clone(), toy.clone(), harness.clone(), other];
    let bad = crate_violations(&table, &manifests);
    assert_eq!(
        bad,
        [
            "logicpad/Cargo.toml: crate `logicpad` is in no row of docs/architecture.md's crate table",
            "docs/architecture.md: the crate table lists `gone`, which is no workspace member",
        ]
    );
    // An extra and a missing dependency, each naming the Cargo.toml.
    let mut table = table;
    table.remove("gone");
    table.insert("logicrag".into(), BTreeSet::new());
    table.insert(
        "toy".into(),
        ["kanren", "logicpad", "perception", "logicpad-extra"]
            .iter()
            .map(|s| s.to_string())
            .collect(),
    );
    let logicrag = (
        "logicrag".to_string(),
        "[package]\nname = \"logicrag\"\n".to_string(),
    );
    let bad = crate_violations(&table, &[kanren, toy, harness, logicrag]);
    assert_eq!(
        bad,
        [
            "toy/Cargo.toml: `toy` depends on `logicrag`, which docs/architecture.md's crate table does not list",
            "toy/Cargo.toml: `toy` does not depend on `logicpad-extra`, which docs/architecture.md's crate table lists",
        ]
    );
}
