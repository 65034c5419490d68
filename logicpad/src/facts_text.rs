//! One ground fact per line, `Pred(a, b)`: the text KB form shared with
//! the paper's reference and the KB benchmark. One parser serves
//! [`crate::FactBase::add_text`] and logicrag's fact files, so both accept
//! and refuse exactly the same lines.

/// One ground fact as written in a text KB.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct TextFact {
    /// Predicate name, e.g. `Vehicles`.
    pub predicate: String,
    /// Constant arguments in order; empty for a 0-ary fact.
    pub args: Vec<String>,
}

impl std::fmt::Display for TextFact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}(", self.predicate)?;
        for (i, a) in self.args.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            f.write_str(a)?;
        }
        f.write_str(")")
    }
}

/// A line of a `.facts` text that is not a fact: where it is and what
/// was expected there. logicpad's [`crate::FactError::Syntax`] and
/// logicrag's fact-file error both carry it (each words it its own way).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FactSyntax {
    /// File (or `<input>`) the line came from.
    pub file: String,
    /// 1-based line number.
    pub line: usize,
    /// 1-based column of the offending character in the line as written.
    pub column: usize,
    /// What was expected there.
    pub message: String,
    /// The line as written (surrounding whitespace included).
    pub text: String,
}

impl FactSyntax {
    /// The line without its surrounding whitespace.
    pub fn trimmed(&self) -> &str {
        self.text.trim()
    }

    /// Byte offset of the offending character in [`FactSyntax::trimmed`].
    pub fn offset(&self) -> usize {
        let leading = self.text.len() - self.text.trim_start().len();
        self.column.saturating_sub(1 + leading)
    }
}

/// Calls `f(predicate, args)` for each fact line of `text`, in order, with
/// names borrowed from `text` (one argument buffer serves every line);
/// blank lines and lines starting with `#` or `%` are skipped. A line that
/// is not a fact stops the walk with its [`FactSyntax`] (`file` names the
/// text). Returns the number of lines in `text`.
pub fn for_each_fact_line<'t, E: From<FactSyntax>>(
    text: &'t str,
    file: &str,
    mut f: impl FnMut(&'t str, &[&'t str]) -> Result<(), E>,
) -> Result<usize, E> {
    let mut args: Vec<&'t str> = Vec::with_capacity(4);
    let mut lines = 0;
    for (i, raw) in text.lines().enumerate() {
        lines = i + 1;
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with('%') {
            continue;
        }
        let predicate = parse_fact_parts(line, &mut args).map_err(|(col, message)| FactSyntax {
            file: file.to_string(),
            line: i + 1,
            column: col + 1 + (raw.len() - raw.trim_start().len()),
            message,
            text: raw.to_string(),
        })?;
        f(predicate, &args)?;
    }
    Ok(lines)
}

/// Characters of a predicate name or a constant.
pub fn is_ident_char(c: char) -> bool {
    c.is_alphanumeric() || matches!(c, '_' | '-' | '.' | '\'')
}

/// Parses one trimmed line; on error returns (byte column, expectation).
pub fn parse_fact_line(line: &str) -> Result<TextFact, (usize, String)> {
    let mut args = Vec::new();
    let predicate = parse_fact_parts(line, &mut args)?;
    Ok(TextFact {
        predicate: predicate.to_string(),
        args: args.into_iter().map(str::to_string).collect(),
    })
}

/// [`parse_fact_line`] without allocating: returns the predicate and leaves
/// the arguments in `args` (cleared first), both borrowed from `line`.
///
/// Why a second entry point: a text KB of millions of lines was parsed into
/// a `String` per name, which cost more than reasoning over it; callers that
/// intern the names reuse one `args` buffer for every line. Both entry points
/// accept and refuse exactly the same lines, with the same columns.
pub fn parse_fact_parts<'a>(
    line: &'a str,
    args: &mut Vec<&'a str>,
) -> Result<&'a str, (usize, String)> {
    if let Some(predicate) = parse_plain_ascii(line, args) {
        return Ok(predicate);
    }
    parse_fact_parts_general(line, args)
}

/// Whether byte `b` is an ASCII character of a name ([`is_ident_char`] on
/// ASCII).
#[inline(always)]
fn is_ascii_ident(b: u8) -> bool {
    b.is_ascii_alphanumeric() || matches!(b, b'_' | b'-' | b'.' | b'\'')
}

/// The common line, read byte by byte: `Pred(a, b)` with ASCII names, no
/// quotes, no space before `(`, no trailing `.`. `None` for anything else,
/// which [`parse_fact_parts_general`] then reads (and for a bad line,
/// words the error); for a line it accepts, the result is the general
/// reader's.
///
/// Why: the general reader walks each line several times by `char`
/// (search, trim, split, validate), and that was most of the time to read
/// a two-million-line KB.
#[inline]
fn parse_plain_ascii<'a>(line: &'a str, args: &mut Vec<&'a str>) -> Option<&'a str> {
    let bytes = line.as_bytes();
    let open = bytes.iter().position(|&b| !is_ascii_ident(b))?;
    if open == 0 || bytes.get(open) != Some(&b'(') || bytes.last() != Some(&b')') {
        return None;
    }
    args.clear();
    let inner_end = bytes.len() - 1;
    if inner_end == open + 1 {
        return line.get(..open);
    }
    let mut start = open + 1;
    for at in open + 1..=inner_end {
        let b = *bytes.get(at)?;
        if at < inner_end && b != b',' {
            if !is_ascii_ident(b) && b != b' ' {
                return None;
            }
            continue;
        }
        // One argument: `start..at`, spaces trimmed.
        let mut lo = start;
        let mut hi = at;
        while lo < hi && bytes.get(lo) == Some(&b' ') {
            lo += 1;
        }
        while hi > lo && bytes.get(hi - 1) == Some(&b' ') {
            hi -= 1;
        }
        if lo == hi {
            args.clear();
            return None;
        }
        args.push(line.get(lo..hi)?);
        start = at + 1;
    }
    line.get(..open)
}

/// [`parse_fact_parts`] for any line (the reader that words the errors).
fn parse_fact_parts_general<'a>(
    line: &'a str,
    args: &mut Vec<&'a str>,
) -> Result<&'a str, (usize, String)> {
    args.clear();
    let line = line.strip_suffix('.').unwrap_or(line).trim_end();
    // `ok_or_else`: the message is built only for a bad line (built
    // eagerly, it was an allocation per fact of a two-million-line file).
    let open = line.find('(').ok_or_else(|| {
        (
            line.len(),
            "expected `(` after the predicate name, as in `Pred(a, b)`".to_string(),
        )
    })?;
    let predicate = line[..open].trim();
    if predicate.is_empty() || !predicate.chars().all(is_ident_char) {
        return Err((
            0,
            format!("expected a predicate name before `(`, found `{predicate}`"),
        ));
    }
    if !line.ends_with(')') {
        return Err((
            line.len(),
            "expected `)` at the end of the fact".to_string(),
        ));
    }
    let inner = &line[open + 1..line.len() - 1];
    if !inner.trim().is_empty() {
        let mut offset = open + 1;
        for part in inner.split(',') {
            let arg = part.trim();
            let arg = arg
                .strip_prefix('"')
                .and_then(|a| a.strip_suffix('"'))
                .unwrap_or(arg);
            if arg.is_empty() {
                return Err((offset, "expected an argument (a constant) here".to_string()));
            }
            if let Some(bad) = arg.chars().find(|c| !is_ident_char(*c) && *c != ' ') {
                return Err((offset, format!("unexpected `{bad}` in argument `{arg}`")));
            }
            args.push(arg);
            offset += part.len() + 1;
        }
    }
    Ok(predicate)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Lines near the fact syntax: names, spaces, commas, parentheses,
    /// quotes, a dot, a tab and a non-ASCII letter.
    fn near_fact_line() -> impl Strategy<Value = String> {
        let piece = prop_oneof![
            4 => "[A-Za-z0-9_]{1,6}",
            2 => Just(", ".to_string()),
            1 => Just(",".to_string()),
            1 => Just(" ".to_string()),
            1 => Just("(".to_string()),
            1 => Just(")".to_string()),
            1 => Just("\"".to_string()),
            1 => Just(".".to_string()),
            1 => Just("'-".to_string()),
            1 => Just("\t".to_string()),
            1 => Just("é".to_string()),
        ];
        (
            "[A-Za-z][A-Za-z0-9_]{0,6}",
            prop::collection::vec(piece, 0..8),
            prop::bool::ANY,
        )
            .prop_map(|(pred, parts, close)| {
                let mut s = format!("{pred}({}", parts.concat());
                if close {
                    s.push(')');
                }
                s
            })
    }

    proptest! {
        /// The byte-level reader accepts only lines the general reader
        /// accepts, with the same predicate and arguments; the entry point
        /// gives the general reader's result (errors included) on every
        /// line.
        #[test]
        fn the_ascii_reader_agrees_with_the_general_one(line in near_fact_line()) {
            let (mut fast, mut general) = (Vec::new(), Vec::new());
            let want = parse_fact_parts_general(&line, &mut general);
            if let Some(pred) = parse_plain_ascii(&line, &mut fast) {
                prop_assert_eq!(Ok(pred), want.clone(), "{}", line);
                prop_assert_eq!(&fast, &general, "{}", line);
            }
            let mut both = Vec::new();
            prop_assert_eq!(parse_fact_parts(&line, &mut both), want);
            prop_assert_eq!(both, general);
        }
    }

    #[test]
    fn a_bad_line_is_named_by_file_line_and_column_of_the_line_as_written() {
        let mut seen = Vec::new();
        let err = for_each_fact_line("# c\nA(x)\n\n   Near(a,,b)\n", "w.facts", |p, _| {
            seen.push(p);
            Ok::<(), FactSyntax>(())
        })
        .expect_err("line 4 is bad");
        assert_eq!(seen, ["A"]);
        assert_eq!((err.line, err.column, err.offset()), (4, 11, 7));
        assert_eq!(err.trimmed(), "Near(a,,b)");
        assert_eq!(
            crate::FactError::from(err).to_string(),
            "w.facts:4:11: cannot read fact `Near(a,,b)`: expected an argument (a constant) here"
        );
        let lines = for_each_fact_line("A(x)\n# c\n", "w", |_, _| Ok::<(), FactSyntax>(()));
        assert_eq!(lines, Ok(2));
    }

    #[test]
    fn the_ascii_reader_takes_the_common_lines() {
        let mut args = Vec::new();
        assert_eq!(
            parse_plain_ascii("Near(car_1, ped-2)", &mut args),
            Some("Near")
        );
        assert_eq!(args, ["car_1", "ped-2"]);
        assert_eq!(parse_plain_ascii("Danger()", &mut args), Some("Danger"));
        assert!(args.is_empty());
        for other in [
            "Near(a).",
            "Near (a)",
            "Near(\"a\")",
            "Near(a,,b)",
            "Near(é)",
        ] {
            assert_eq!(parse_plain_ascii(other, &mut args), None, "{other}");
        }
    }
}
