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
