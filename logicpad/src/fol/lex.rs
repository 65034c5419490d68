//! The tokens of the FOL text and the lexer that reads them, with the
//! syntax error every stage of reading reports.

use crate::diag::Span;

/// A lexical token.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum Tok {
    Name(String),
    QVar(String),
    Quoted(String),
    LParen,
    RParen,
    Comma,
    Colon,
    Dot,
    Forall,
    Exists,
    Not,
    And,
    Or,
    Implies,
    Eq,
    Neq,
    Eof,
}

impl Tok {
    pub(super) fn describe(&self) -> String {
        match self {
            Tok::Name(n) => format!("`{n}`"),
            Tok::QVar(n) => format!("`?{n}`"),
            Tok::Quoted(s) => format!("\"{s}\""),
            Tok::LParen => "`(`".into(),
            Tok::RParen => "`)`".into(),
            Tok::Comma => "`,`".into(),
            Tok::Colon => "`:`".into(),
            Tok::Dot => "`.`".into(),
            Tok::Forall => "`∀`".into(),
            Tok::Exists => "`∃`".into(),
            Tok::Not => "`¬`".into(),
            Tok::And => "`∧`".into(),
            Tok::Or => "`∨`".into(),
            Tok::Implies => "`==>`".into(),
            Tok::Eq => "`=`".into(),
            Tok::Neq => "`≠`".into(),
            Tok::Eof => "the end of the formula".into(),
        }
    }
}

/// A syntax error in a formula.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SyntaxError {
    /// Where (within the formula text).
    pub span: Span,
    /// What went wrong.
    pub message: String,
    /// What the caret says.
    pub label: String,
}

fn is_name_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_' || c == '\'' || c == '-'
}

pub(super) fn lex(text: &str) -> Result<Vec<(Tok, Span)>, SyntaxError> {
    let mut toks = Vec::with_capacity(text.len() / 3 + 2);
    let mut it = text.char_indices().peekable();
    while let Some(&(i, c)) = it.peek() {
        let single = |t: Tok| (t, Span::new(i, i + c.len_utf8()));
        if c.is_whitespace() {
            it.next();
            continue;
        }
        let rest = text.get(i..).unwrap_or("");
        let multi: &[(&str, Tok)] = &[
            ("==>", Tok::Implies),
            ("=>", Tok::Implies),
            ("->", Tok::Implies),
            ("!=", Tok::Neq),
            ("/=", Tok::Neq),
            ("&&", Tok::And),
            ("||", Tok::Or),
        ];
        if let Some((s, t)) = multi.iter().find(|(s, _)| rest.starts_with(s)) {
            toks.push((t.clone(), Span::new(i, i + s.len())));
            for _ in 0..s.chars().count() {
                it.next();
            }
            continue;
        }
        let tok = match c {
            '(' => Some(Tok::LParen),
            ')' => Some(Tok::RParen),
            ',' => Some(Tok::Comma),
            ':' => Some(Tok::Colon),
            '.' => Some(Tok::Dot),
            '∀' => Some(Tok::Forall),
            '∃' => Some(Tok::Exists),
            '¬' | '~' | '!' => Some(Tok::Not),
            '∧' | '&' | '^' => Some(Tok::And),
            '∨' | '|' => Some(Tok::Or),
            '→' | '⇒' | '⟹' | '⊃' => Some(Tok::Implies),
            '=' => Some(Tok::Eq),
            '≠' => Some(Tok::Neq),
            _ => None,
        };
        if let Some(t) = tok {
            toks.push(single(t));
            it.next();
            continue;
        }
        if c == '"' {
            it.next();
            let mut value = String::new();
            let mut end = None;
            while let Some((j, d)) = it.next() {
                if d == '"' {
                    end = Some(j + 1);
                    break;
                }
                if d == '\\' {
                    if let Some((_, e)) = it.next() {
                        value.push(e);
                    }
                    continue;
                }
                value.push(d);
            }
            let Some(end) = end else {
                return Err(SyntaxError {
                    span: Span::new(i, text.len()),
                    message: "unterminated quoted constant".into(),
                    label: "this `\"` is never closed".into(),
                });
            };
            toks.push((Tok::Quoted(value), Span::new(i, end)));
            continue;
        }
        if c == '?' {
            it.next();
            let start = i + 1;
            let mut end = start;
            while let Some(&(j, d)) = it.peek() {
                if is_name_char(d) {
                    end = j + d.len_utf8();
                    it.next();
                } else {
                    break;
                }
            }
            if end == start {
                return Err(SyntaxError {
                    span: Span::new(i, i + 1),
                    message: "`?` must be followed by a variable name".into(),
                    label: "expected a name after `?`".into(),
                });
            }
            toks.push((
                Tok::QVar(text.get(start..end).unwrap_or("").to_string()),
                Span::new(i, end),
            ));
            continue;
        }
        if is_name_char(c) && c != '\'' && c != '-' {
            let mut end = i;
            while let Some(&(j, d)) = it.peek() {
                // `->` is an arrow, not part of a name.
                if d == '-' && text.get(j..).is_some_and(|r| r.starts_with("->")) {
                    break;
                }
                if is_name_char(d) {
                    end = j + d.len_utf8();
                    it.next();
                } else {
                    break;
                }
            }
            let word = text.get(i..end).unwrap_or("");
            let t = match word {
                "forall" => Tok::Forall,
                "exists" => Tok::Exists,
                "not" => Tok::Not,
                "and" => Tok::And,
                "or" => Tok::Or,
                "implies" => Tok::Implies,
                _ => Tok::Name(word.to_string()),
            };
            toks.push((t, Span::new(i, end)));
            continue;
        }
        return Err(SyntaxError {
            span: Span::new(i, i + c.len_utf8()),
            message: format!("unexpected character `{c}`"),
            label: "not part of the FOL syntax".into(),
        });
    }
    toks.push((Tok::Eof, Span::new(text.len(), text.len())));
    Ok(toks)
}
