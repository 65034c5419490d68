//! The text KB form shared with the paper's reference: one ground fact per line,
//! `Pred(arg1, arg2)`, arguments separated by commas.
//!
//! Blank lines and lines starting with `#` or `%` are comments. Anything else
//! that is not a well-formed fact is an error naming the file and line: a KB
//! that silently lost a fact would answer "no" where the truth is "yes".

use std::fmt::Write as _;
use std::path::Path;

pub use logicpad::facts_text::{TextFact, parse_fact_line};

/// Errors of the text KB reader.
#[derive(Debug, thiserror::Error)]
pub enum FactsTextError {
    /// Occurs when a line is not of the form `Pred(a, b)`.
    #[error("{file}:{line}:{column}: {message}\n  | {text}")]
    Syntax {
        /// File (or `<input>`) the line came from.
        file: String,
        /// 1-based line number.
        line: usize,
        /// 1-based column of the offending character.
        column: usize,
        /// What was expected there.
        message: String,
        /// The offending line.
        text: String,
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
    let text = perception::textfile::read_text_file(path).map_err(|source| FactsTextError::Io {
        file: path.display().to_string(),
        source,
    })?;
    parse_facts(&text, &path.display().to_string())
}

/// Parses a text KB; `file` names the input in error messages.
pub fn parse_facts(text: &str, file: &str) -> Result<Vec<TextFact>, FactsTextError> {
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with('%') {
            continue;
        }
        let fact = parse_fact_line(line).map_err(|(col, message)| FactsTextError::Syntax {
            file: file.to_string(),
            line: i + 1,
            column: col + 1 + (raw.len() - raw.trim_start().len()),
            message,
            text: excerpt(raw, col),
        })?;
        out.push(fact);
    }
    Ok(out)
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

    use super::*;

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
}
