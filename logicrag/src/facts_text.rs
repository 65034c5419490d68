//! The text KB form shared with the paper's reference: one ground fact per line,
//! `Pred(arg1, arg2)`, arguments separated by commas.
//!
//! Blank lines and lines starting with `#` or `%` are comments. Anything else
//! that is not a well-formed fact is an error naming the file and line: a KB
//! that silently lost a fact would answer "no" where the truth is "yes".

use std::fmt::Write as _;
use std::path::Path;

use kanren::Sym;
pub use logicpad::facts_text::{FactSyntax, TextFact, parse_fact_line, parse_fact_parts};
use rustc_hash::FxHashMap;

/// Errors of the text KB reader.
#[derive(Debug, thiserror::Error)]
pub enum FactsTextError {
    /// Occurs when a line is not of the form `Pred(a, b)` (logicpad's
    /// [`FactSyntax`], worded with an excerpt of the line under it).
    #[error("{}:{}:{}: {}\n  | {}", .0.file, .0.line, .0.column, .0.message, excerpt(&.0.text, .0.offset()))]
    Syntax(FactSyntax),
    /// Occurs when a text holds more than `u32::MAX` arguments in all (far
    /// past the largest file read).
    #[error("{file}: too many facts for one window")]
    TooLarge {
        /// File (or `<input>`) the facts came from.
        file: String,
    },
    /// Occurs when the file cannot be read.
    #[error("cannot read facts file {file}: {source}")]
    Io {
        /// The file.
        file: String,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
}

/// Reads a text KB file.
pub fn read_facts_file(path: &Path) -> Result<Vec<TextFact>, FactsTextError> {
    let text = read_text(path)?;
    parse_facts(&text, &path.display().to_string())
}

/// Reads a text KB file straight into interned symbols (see [`ParsedFacts`]).
///
/// The file is read in pieces of whole lines ([`READ_CHUNK_BYTES`]), each
/// parsed as it comes, so a file is never held whole; errors name the
/// line in the file, as when it is parsed at once.
pub(crate) fn read_facts_file_interned(path: &Path) -> Result<ParsedFacts, FactsTextError> {
    read_interned_in_chunks(path, READ_CHUNK_BYTES)
}

fn read_interned_in_chunks(path: &Path, chunk: usize) -> Result<ParsedFacts, FactsTextError> {
    let file = path.display().to_string();
    let mut out = ParsedFacts::default();
    // Room for the facts a file of this size holds, give or take: growing
    // by doubling copied the columns of a large file again and again, each
    // copy into fresh pages the kernel had to zero. (Unused room is never
    // touched, so it costs address space, not memory.)
    if let Ok(meta) = std::fs::metadata(path) {
        let bytes = usize::try_from(meta.len()).unwrap_or(0);
        out.facts.reserve(bytes / BYTES_PER_FACT_GUESS);
        out.args.reserve(bytes / BYTES_PER_FACT_GUESS * 2);
    }
    let mut lines_before = 0;
    perception::textfile::read_text_chunks(
        path,
        chunk,
        |source| FactsTextError::Io {
            file: file.clone(),
            source,
        },
        |text| {
            lines_before += parse_into(&mut out, text, &file, lines_before)?;
            Ok(())
        },
    )?;
    Ok(out)
}

/// A short fact line, for reserving room: `Vehicles(car_3)` and a newline.
const BYTES_PER_FACT_GUESS: usize = 16;

/// How much of a text KB file is read and parsed at a time: large enough
/// that each piece splits across the threads, small enough to stay in
/// memory the parser has already touched.
pub(crate) const READ_CHUNK_BYTES: usize = 8 << 20;

fn read_text(path: &Path) -> Result<String, FactsTextError> {
    perception::textfile::read_text_file(path).map_err(|source| FactsTextError::Io {
        file: path.display().to_string(),
        source,
    })
}

/// Parses a text KB; `file` names the input in error messages.
pub fn parse_facts(text: &str, file: &str) -> Result<Vec<TextFact>, FactsTextError> {
    let mut out = Vec::new();
    for_each_fact(text, file, |predicate, args| {
        out.push(TextFact {
            predicate: predicate.to_string(),
            args: args.iter().map(|a| (*a).to_string()).collect(),
        });
        Ok(())
    })?;
    Ok(out)
}

/// Parses a text KB into interned symbols, without a `String` per name:
/// the same lines are accepted and refused as by [`parse_facts`], with the
/// same messages (the first bad line in the text is the one reported);
/// `file` names the input in error messages.
pub fn parse_facts_interned(text: &str, file: &str) -> Result<ParsedFacts, FactsTextError> {
    let mut out = ParsedFacts::default();
    parse_into(&mut out, text, file, 0)?;
    Ok(out)
}

/// Parses `text` (whole lines, the first being line `lines_before + 1` of
/// `file`) and appends its facts to `out`; returns how many lines it had.
fn parse_into(
    out: &mut ParsedFacts,
    text: &str,
    file: &str,
    lines_before: usize,
) -> Result<usize, FactsTextError> {
    use rayon::prelude::*;
    // A large text is cut at line ends into one piece per thread: lines are
    // independent, and a two-million-line window is one file, so the
    // loader's parallelism over files does not help it.
    let pieces = split_at_lines(
        text,
        rayon::current_num_threads().min(text.len() / PARALLEL_BYTES),
    );
    let parsed: Vec<Result<(ParsedFacts, usize), FactsTextError>> = pieces
        .par_iter()
        .map(|piece| parse_piece(piece, file))
        .collect();
    let mut lines_before = lines_before;
    let mut lines_here = 0;
    for piece in parsed {
        match piece {
            Ok((facts, lines)) => {
                out.append(facts).map_err(|()| FactsTextError::TooLarge {
                    file: file.to_string(),
                })?;
                lines_before += lines;
                lines_here += lines;
            }
            // A piece numbers its lines from 1.
            Err(FactsTextError::Syntax(mut s)) => {
                s.line += lines_before;
                return Err(FactsTextError::Syntax(s));
            }
            Err(e) => return Err(e),
        }
    }
    Ok(lines_here)
}

/// Texts of at least this many bytes per thread are parsed in pieces.
const PARALLEL_BYTES: usize = 1 << 20;

/// `text` cut into at most `n` pieces (at least one), each ending just
/// after a `\n` (the last one at the text's end), so every piece holds
/// whole lines and their `lines()` together are the text's.
fn split_at_lines(text: &str, n: usize) -> Vec<&str> {
    let mut pieces = Vec::with_capacity(n.max(1));
    let mut start = 0;
    for i in 1..n {
        let target = (text.len() / n * i).max(start);
        // `\n` is never part of a multi-byte character, so the byte after
        // it starts one.
        let Some(nl) = text
            .as_bytes()
            .get(target..)
            .and_then(|rest| rest.iter().position(|&b| b == b'\n'))
        else {
            break;
        };
        let end = target + nl + 1;
        if let Some(piece) = text.get(start..end) {
            pieces.push(piece);
            start = end;
        }
    }
    pieces.push(text.get(start..).unwrap_or_default());
    pieces
}

/// Parses one piece: its facts and its number of lines.
fn parse_piece(text: &str, file: &str) -> Result<(ParsedFacts, usize), FactsTextError> {
    let mut out = ParsedFacts::default();
    // Names repeat (a few predicates, an object per many facts): a piece
    // keeps its own map from name to symbol, so the shared interner and
    // its lock are met once per distinct name, not once per argument.
    let mut seen: FxHashMap<&str, Sym> = FxHashMap::default();
    let mut intern = |name| *seen.entry(name).or_insert_with(|| Sym::new(name));
    let lines = for_each_fact(text, file, |predicate, args| {
        let pred = intern(predicate);
        let start = out.args.len();
        out.args.extend(args.iter().map(|a| intern(a)));
        out.close(pred, start)
            .map_err(|()| FactsTextError::TooLarge {
                file: file.to_string(),
            })
    })?;
    Ok((out, lines))
}

/// logicpad's [`logicpad::facts_text::for_each_fact_line`], its errors
/// this module's; returns the number of lines in `text`.
fn for_each_fact<'t>(
    text: &'t str,
    file: &str,
    f: impl FnMut(&'t str, &[&'t str]) -> Result<(), FactsTextError>,
) -> Result<usize, FactsTextError> {
    logicpad::facts_text::for_each_fact_line(text, file, f)
}

impl From<FactSyntax> for FactsTextError {
    fn from(s: FactSyntax) -> FactsTextError {
        FactsTextError::Syntax(s)
    }
}

/// The facts of a text KB, interned as they are read.
///
/// Invariants: facts are in file order, duplicates kept (the KB drops them);
/// fact `i` is `facts[i].0` applied to `args[facts[i].1..e]`, where `e` is
/// the next fact's start (or `args.len()` for the last fact), so starts
/// ascend. Why columns of symbols: a text KB of two million lines was read
/// into a `String` per name first, which cost more time and memory than
/// reasoning over it.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ParsedFacts {
    /// Per fact: its predicate and where its arguments start in `args`.
    facts: Vec<(Sym, u32)>,
    /// Every fact's arguments, one after another.
    args: Vec<Sym>,
}

impl ParsedFacts {
    /// Ends a fact whose arguments were appended to `args` from `start`
    /// on; `Err(())` (and those arguments dropped) past `u32::MAX`
    /// arguments in all.
    fn close(&mut self, pred: Sym, start: usize) -> Result<(), ()> {
        match (u32::try_from(start), u32::try_from(self.args.len())) {
            (Ok(start), Ok(_)) => {
                self.facts.push((pred, start));
                Ok(())
            }
            _ => {
                self.args.truncate(start);
                Err(())
            }
        }
    }

    /// Moves `other`'s facts after this one's; `Err(())` (nothing moved)
    /// past `u32::MAX` arguments in all.
    fn append(&mut self, other: ParsedFacts) -> Result<(), ()> {
        // Moved whole only when that keeps the room reserved here.
        if self.facts.is_empty() && self.facts.capacity() <= other.facts.capacity() {
            *self = other;
            return Ok(());
        }
        let shift = u32::try_from(self.args.len()).map_err(|_| ())?;
        u32::try_from(self.args.len() + other.args.len()).map_err(|_| ())?;
        self.facts
            .extend(other.facts.into_iter().map(|(p, start)| (p, start + shift)));
        self.args.extend(other.args);
        Ok(())
    }

    /// Listed facts interned, in their order; an error past `u32::MAX`
    /// arguments in all.
    pub(crate) fn intern(facts: &[perception::Fact]) -> Result<ParsedFacts, logicpad::FactError> {
        // Sized once: growing by doubling touched fresh pages over and
        // over, a window at a time.
        let mut out = ParsedFacts {
            facts: Vec::with_capacity(facts.len()),
            args: Vec::with_capacity(facts.iter().map(|f| f.args.len()).sum()),
        };
        // A window names a few objects and values many times over: each
        // name goes to the shared interner (a lock and a SipHash) once.
        let mut seen: FxHashMap<&str, Sym> = FxHashMap::default();
        let mut intern = |name| *seen.entry(name).or_insert_with(|| Sym::new(name));
        for f in facts {
            let start = out.args.len();
            out.args.extend(f.args.iter().map(|a| intern(a)));
            out.close(intern(&f.predicate), start)
                .map_err(|()| logicpad::FactError::Store {
                    pred: f.predicate.clone(),
                    message: "more than u32::MAX arguments in one window".into(),
                })?;
        }
        Ok(out)
    }

    /// Number of facts (duplicates counted).
    pub fn len(&self) -> usize {
        self.facts.len()
    }

    /// True when there is no fact.
    pub fn is_empty(&self) -> bool {
        self.facts.is_empty()
    }

    /// The facts in file order: predicate and arguments.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = (Sym, &[Sym])> + '_ {
        self.facts.iter().enumerate().map(|(i, &(pred, start))| {
            let end = self
                .facts
                .get(i + 1)
                .map_or(self.args.len(), |&(_, next)| next as usize);
            (pred, self.args.get(start as usize..end).unwrap_or_default())
        })
    }
}

/// The characters of an error's line shown with it: a 50 MB line was
/// echoed whole into the message.
const EXCERPT_CHARS: usize = 120;

/// Up to [`EXCERPT_CHARS`] characters of `line` around byte `at`, with `…`
/// where it was cut.
fn excerpt(line: &str, at: usize) -> String {
    if line.chars().count() <= EXCERPT_CHARS {
        return line.to_string();
    }
    let at_char = line.get(..at).map_or(0, |p| p.chars().count());
    let start = at_char.saturating_sub(EXCERPT_CHARS / 2);
    let shown: String = line.chars().skip(start).take(EXCERPT_CHARS).collect();
    let before = if start > 0 { "…" } else { "" };
    let after = if start + EXCERPT_CHARS < line.chars().count() {
        "…"
    } else {
        ""
    };
    format!("{before}{shown}{after}")
}

/// Renders facts one per line, sorted and deduplicated.
pub fn render_facts<'a>(facts: impl IntoIterator<Item = &'a TextFact>) -> String {
    let mut v: Vec<&TextFact> = facts.into_iter().collect();
    v.sort();
    v.dedup();
    let mut s = String::new();
    for f in v {
        let _ = writeln!(s, "{f}");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reading_in_pieces_equals_reading_whole() {
        let dir = std::env::temp_dir().join(format!("logicrag-chunks-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let mut text = String::from("\u{feff}");
        for i in 0..500 {
            text.push_str(&format!(
                "Vehicles(car_{i})\n# a comment\n\nColorOf(car_{i}, Réd)\r\n"
            ));
        }
        text.push_str("TypeOf(car_0, Car)"); // no final newline
        let good = dir.join("good.facts");
        std::fs::write(&good, &text).expect("write");
        let whole = parse_facts_interned(
            text.trim_start_matches('\u{feff}'),
            &good.display().to_string(),
        )
        .expect("parses");
        // Pieces smaller than a line, of a few lines, and of everything.
        for chunk in [1, 7, 100, 4096, 1 << 20] {
            let pieces = read_interned_in_chunks(&good, chunk).expect("reads");
            assert_eq!(pieces, whole, "chunk {chunk}");
        }
        // A bad line is reported at its line in the file, whatever piece
        // it falls in.
        let bad_text = text.replacen("ColorOf(car_300, Réd)", "ColorOf(car_300, Réd", 1);
        let bad = dir.join("bad.facts");
        std::fs::write(&bad, &bad_text).expect("write");
        let expected = parse_facts_interned(
            bad_text.trim_start_matches('\u{feff}'),
            &bad.display().to_string(),
        )
        .expect_err("bad line")
        .to_string();
        assert!(expected.contains(":1204:"), "{expected}");
        for chunk in [1, 7, 100, 4096] {
            let e = read_interned_in_chunks(&bad, chunk).expect_err("bad line");
            assert_eq!(e.to_string(), expected, "chunk {chunk}");
        }
        // Invalid UTF-8 is an error, not a skipped piece.
        let invalid = dir.join("invalid.facts");
        std::fs::write(&invalid, b"Vehicles(a)\nVehicles(\xff)\n").expect("write");
        let e = read_interned_in_chunks(&invalid, 4).expect_err("not UTF-8");
        assert!(e.to_string().contains("UTF-8"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_huge_bad_line_is_not_echoed_whole() {
        // Regression: a 50 MB malformed line was echoed into the error.
        let line = format!("Vehicles({}", "a".repeat(1_000_000));
        let e = parse_facts(&line, "big.facts").expect_err("unclosed");
        let text = e.to_string();
        assert!(text.starts_with("big.facts:1:"), "{}", &text[..80]);
        assert!(text.len() < 600, "{} bytes", text.len());
        assert!(text.contains('…'));
    }

    #[test]
    fn parses_reference_lines() {
        let facts = parse_facts(
            "Vehicles(Vehicles_3)\n\n# comment\nColorOf(Vehicles_3, White)\nNotDistanceIncrease(car_3, pedestrian_1).\n",
            "kb",
        )
        .unwrap();
        assert_eq!(facts.len(), 3);
        assert_eq!(facts[1].args, vec!["Vehicles_3", "White"]);
        assert_eq!(
            facts[2].to_string(),
            "NotDistanceIncrease(car_3, pedestrian_1)"
        );
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let err = parse_facts("Vehicles(a)\nColorOf(a,, White)\n", "w.facts").unwrap_err();
        let msg = err.to_string();
        assert!(msg.starts_with("w.facts:2:"), "{msg}");
        assert!(msg.contains("expected an argument"), "{msg}");
        let err = parse_facts("Vehicles a\n", "w.facts").unwrap_err();
        assert!(err.to_string().contains("w.facts:1:"), "{err}");
        let err = parse_facts("Vehicles(a\n", "w.facts").unwrap_err();
        assert!(err.to_string().contains("expected `)`"), "{err}");
    }

    #[test]
    fn round_trips() {
        let facts = parse_facts("B(x, y)\nA(z)\nA(z)\n", "kb").unwrap();
        let text = render_facts(&facts);
        assert_eq!(text, "A(z)\nB(x, y)\n");
        assert_eq!(parse_facts(&text, "kb").unwrap().len(), 2);
    }

    /// The facts of a parsed text as `Pred(a, b)` lines.
    fn lines_of(parsed: &ParsedFacts) -> Vec<String> {
        parsed
            .iter()
            .map(|(p, args)| {
                let args: Vec<&str> = args.iter().map(|a| a.as_str()).collect();
                format!("{}({})", p.as_str(), args.join(", "))
            })
            .collect()
    }

    #[test]
    fn the_interned_reader_reads_what_the_string_reader_reads() {
        let text = "Vehicles(car_1)\n\n# c\nColorOf(car_1, White)\n  P()\nColorOf(car_1, White)\nQ(\"a b\", c).\n";
        let listed: Vec<String> = parse_facts(text, "kb")
            .unwrap()
            .iter()
            .map(ToString::to_string)
            .collect();
        let interned = parse_facts_interned(text, "kb").unwrap();
        assert_eq!(interned.len(), 5, "duplicates are kept");
        assert_eq!(lines_of(&interned), listed);
        for bad in [
            "Vehicles(a)\nColorOf(a,, White)\n",
            "Vehicles a\n",
            "ok(a)\n   Vehicles(a\n",
        ] {
            let a = parse_facts(bad, "w.facts").unwrap_err().to_string();
            let b = parse_facts_interned(bad, "w.facts")
                .unwrap_err()
                .to_string();
            assert_eq!(a, b);
        }
    }

    #[test]
    fn pieces_hold_whole_lines_and_all_of_them() {
        let text = "A(1)\nB(2)\r\nC(3)\n\nD(é)\nE(5)";
        for n in 0..8 {
            let pieces = split_at_lines(text, n);
            assert!(
                !pieces.is_empty() && pieces.len() <= n.max(1),
                "{n}: {pieces:?}"
            );
            assert_eq!(pieces.concat(), text);
            let lines: Vec<&str> = pieces.iter().flat_map(|p| p.lines()).collect();
            assert_eq!(lines, text.lines().collect::<Vec<_>>(), "{n}");
        }
    }

    #[test]
    fn a_large_text_read_in_pieces_keeps_order_and_line_numbers() {
        // Past the size read in parallel, whatever the thread count: the
        // facts come back in file order, and an error deep in a later
        // piece names its line in the whole file.
        let mut text = String::new();
        let n = 3 * PARALLEL_BYTES / 20;
        for i in 0..n {
            text.push_str(&format!("Edge(n{i}, n{})\n", i + 1));
        }
        let parsed = parse_facts_interned(&text, "big.facts").unwrap();
        assert_eq!(parsed.len(), n);
        let lines = lines_of(&parsed);
        assert_eq!(lines[0], "Edge(n0, n1)");
        assert_eq!(lines[n - 1], format!("Edge(n{}, n{n})", n - 1));
        let pieces = split_at_lines(&text, 4);
        assert_eq!(pieces.len(), 4);
        let total: usize = pieces.iter().map(|p| parse_piece(p, "x").unwrap().1).sum();
        assert_eq!(total, n);
        let bad_line = n - 7;
        let mut bad = text.clone();
        let at = bad
            .match_indices('\n')
            .nth(bad_line - 2)
            .map(|(i, _)| i + 1)
            .unwrap();
        bad.insert_str(at, "Broken(\n");
        let a = parse_facts(&bad, "big.facts").unwrap_err().to_string();
        let b = parse_facts_interned(&bad, "big.facts")
            .unwrap_err()
            .to_string();
        assert!(a.starts_with(&format!("big.facts:{bad_line}:")), "{a}");
        assert_eq!(a, b);
    }
}
