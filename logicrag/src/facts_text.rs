//! The text KB form shared with the paper's reference: one ground fact per line,
//! `Pred(arg1, arg2)`, arguments separated by commas.
//!
//! Blank lines and lines starting with `#` or `%` are comments. Anything else
//! that is not a well-formed fact is an error naming the file and line: a KB
//! that silently lost a fact would answer "no" where the truth is "yes".

use std::fmt::Write as _;
use std::path::Path;

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
    let text = std::fs::read_to_string(path).map_err(|source| FactsTextError::Io {
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
            text: raw.to_string(),
        })?;
        out.push(fact);
    }
    Ok(out)
}

fn is_ident_char(c: char) -> bool {
    c.is_alphanumeric() || matches!(c, '_' | '-' | '.' | '\'')
}

/// Parses one trimmed line; on error returns (byte column, expectation).
pub fn parse_fact_line(line: &str) -> Result<TextFact, (usize, String)> {
    let line = line.strip_suffix('.').unwrap_or(line).trim_end();
    let open = line.find('(').ok_or((
        line.len(),
        "expected `(` after the predicate name, as in `Pred(a, b)`".to_string(),
    ))?;
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
    let mut args = Vec::new();
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
            args.push(arg.to_string());
            offset += part.len() + 1;
        }
    }
    Ok(TextFact {
        predicate: predicate.to_string(),
        args,
    })
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
