//! The crate's import rules, checked against its sources: the layer table
//! of `docs/kanren.md` (section "Layers") says which module may import
//! which, and this test reads that table and every `src/**/*.rs`, finds each
//! module's references to other modules (`use crate::…`, a `crate::…` path
//! anywhere in the code, `super::…`, names the crate root re-exports), and
//! fails naming the file, the line and the forbidden import when a module
//! imports a layer below its own. Test code (`tests.rs` files and items
//! under `#[cfg(test)]`) may import anything. The unit checks at the end run
//! the same parser on made-up sources, so that a parser that finds nothing
//! cannot pass for a clean crate.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

/// One layer of the table: its number (1 is the bottom, the core), its
/// name and its modules.
#[derive(Debug)]
struct Layer {
    rank: usize,
    name: String,
    modules: Vec<String>,
}

/// Reads the rows `| N name | `m1`, `m2` | … |` of the table under the
/// heading that ends with "Layers".
fn parse_layers(doc: &str) -> Result<Vec<Layer>, String> {
    let mut in_section = false;
    let mut layers = Vec::new();
    for line in doc.lines() {
        if line.starts_with('#') {
            in_section = line.trim_end().ends_with("Layers");
            continue;
        }
        if !in_section || !line.starts_with('|') {
            continue;
        }
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let (Some(head), Some(mods)) = (cells.get(1), cells.get(2)) else {
            continue;
        };
        let mut words = head.split_whitespace();
        let (Some(rank), Some(name)) = (words.next(), words.next()) else {
            continue;
        };
        let Ok(rank) = rank.parse::<usize>() else {
            continue; // the header row and the separator
        };
        let modules: Vec<String> = mods
            .split('`')
            .skip(1)
            .step_by(2)
            .map(str::to_string)
            .collect();
        layers.push(Layer {
            rank,
            name: name.to_string(),
            modules,
        });
    }
    if layers.is_empty() {
        return Err(
            "docs/kanren.md has no layer table under a heading ending in \"Layers\"".into(),
        );
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

/// Every breach of the layer table in the crate's sources, one line each.
fn violations(layers: &[Layer], files: &[(String, Vec<String>, String)]) -> Vec<String> {
    let rank: BTreeMap<&str, (usize, &str)> = layers
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
        .collect();
    let lib = files
        .iter()
        .find(|(_, p, _)| p.is_empty())
        .map_or("", |f| f.2.as_str());
    let reexports = reexports(lib, &modules);
    let mut out = Vec::new();
    for m in &modules {
        if !rank.contains_key(m.as_str()) {
            out.push(format!(
                "src: module `{m}` is in no layer of docs/kanren.md's table"
            ));
        }
    }
    for name in rank.keys() {
        if !modules.contains(*name) {
            out.push(format!(
                "docs/kanren.md: the layer table lists `{name}`, which is no module of src"
            ));
        }
    }
    for (file, path, text) in files {
        let Some(own) = path.first() else {
            continue; // lib.rs: the crate root declares and re-exports all
        };
        if file == "tests.rs" || file.ends_with("/tests.rs") || path.iter().any(|p| p == "tests") {
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
                    "src/{file}:{}: `{own}` (layer {own_rank} {own_layer}) imports `{}` \
                     (layer {r} {layer}), a layer below it: {code}",
                    imp.line, imp.target
                ));
            }
        }
    }
    out
}

#[test]
fn modules_import_only_their_own_layer_and_those_above() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = std::fs::read_to_string(root.join("../docs/kanren.md"))
        .unwrap_or_else(|e| panic!("docs/kanren.md: {e}"));
    let layers = parse_layers(&doc).unwrap_or_else(|e| panic!("{e}"));
    let src = root.join("src");
    let files: Vec<(String, Vec<String>, String)> = module_files(&src)
        .into_iter()
        .map(|(rel, path)| {
            let text = std::fs::read_to_string(src.join(&rel))
                .unwrap_or_else(|e| panic!("{}: {e}", rel.display()));
            (rel.to_string_lossy().replace('\\', "/"), path, text)
        })
        .collect();
    // The parser must see the imports that are allowed, too: every store
    // module imports the core, so finding none means a broken parser.
    let modules: BTreeSet<String> = files
        .iter()
        .filter_map(|(_, p, _)| p.first().cloned())
        .collect();
    let core: BTreeSet<&str> = layers
        .iter()
        .filter(|l| l.rank == 1)
        .flat_map(|l| l.modules.iter().map(String::as_str))
        .collect();
    for store in layers
        .iter()
        .filter(|l| l.rank == 2)
        .flat_map(|l| &l.modules)
    {
        let seen: usize = files
            .iter()
            .filter(|(_, p, _)| p.first() == Some(store))
            .map(|(_, p, text)| {
                let path: Vec<&str> = p.iter().map(String::as_str).collect();
                imports(text, &path, &modules, &HashMap::new())
                    .iter()
                    .filter(|i| core.contains(i.target.as_str()))
                    .count()
            })
            .sum();
        assert!(
            seen > 0,
            "the parser found no import of the core in `{store}`"
        );
    }
    let bad = violations(&layers, &files);
    assert!(bad.is_empty(), "import rules broken:\n{}", bad.join("\n"));
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
    let bad = violations(&toy_layers(), &toy_crate(&[("goal.rs", &["goal"], src)]));
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
    let bad = violations(&toy_layers(), &toy_crate(&[("goal.rs", &["goal"], src)]));
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
        &toy_layers(),
        &toy_crate(&[("join/plan/x.rs", &["join", "plan", "x"], nested)]),
    );
    assert!(
        bad.is_empty(),
        "super::super from join/plan/x is join: {bad:?}"
    );
    let up = "use super::super::classic::zebrao;\n";
    let bad = violations(
        &toy_layers(),
        &toy_crate(&[("join/x.rs", &["join", "x"], up)]),
    );
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
    let bad = violations(&toy_layers(), &toy_crate(&[("goal.rs", &["goal"], src)]));
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
        &toy_layers(),
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
        &layers,
        &toy_crate(&[("goal.rs", &["goal"], ""), ("extra.rs", &["extra"], "")]),
    );
    assert!(
        bad.iter().any(|b| b.contains("`extra` is in no layer")),
        "{bad:?}"
    );
    assert!(bad.iter().any(|b| b.contains("lists `gone`")), "{bad:?}");
    let doc = "# x\n### Layers\n| layer | modules |\n|---|---|\n| 1 core | `term`, `goal` |\n\
               | 2 store | `facts` |\n## Next\n| 3 nope | `x` |\n";
    let parsed = parse_layers(doc).unwrap_or_default();
    let got: Vec<(usize, &str, usize)> = parsed
        .iter()
        .map(|l| (l.rank, l.name.as_str(), l.modules.len()))
        .collect();
    assert_eq!(got, [(1, "core", 2), (2, "store", 1)]);
    assert!(parse_layers("# no table\n").is_err());
}
