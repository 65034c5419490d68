//! Parsing a temporal query: the joiners (`THEN`, `BEFORE`, `AFTER`) and
//! prefixes (`EVER:`, `THROUGHOUT:`, `STILL:`), each part prepared as an
//! existential query, errors as diagnostics with spans.

use super::{Form, Part, TemporalQuery};
use crate::engine::Prepared;
use logicpad::{DiagKind, Diagnostic, LogicPad, ParsedQuery, Severity, SourceFile, Span};
use std::sync::Arc;

/// The keywords that join two queries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Joiner {
    Then,
    Before,
    After,
}

impl Joiner {
    fn word(self) -> &'static str {
        match self {
            Joiner::Then => "THEN",
            Joiner::Before => "BEFORE",
            Joiner::After => "AFTER",
        }
    }
}

/// A joining keyword found in a text: where, which, and at what depth of
/// parentheses.
#[derive(Debug, Clone, Copy)]
struct Found {
    span: Span,
    joiner: Joiner,
    depth: usize,
    /// Written in capitals (`THEN`): only those count inside parentheses,
    /// where a lower-case `then` could be a variable.
    capitals: bool,
}

/// The joining keywords of `text` (whole words; a word followed at once by
/// `(` is a predicate, unless it is written in capitals).
fn joiners(text: &str) -> Vec<Found> {
    let mut out = Vec::new();
    let mut depth = 0usize;
    let mut word_start: Option<usize> = None;
    let bytes = text.as_bytes();
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    let close_word = |start: usize, end: usize, depth: usize, out: &mut Vec<Found>| {
        let w = &text[start..end];
        let joiner = match w.to_ascii_uppercase().as_str() {
            "THEN" => Joiner::Then,
            "BEFORE" => Joiner::Before,
            "AFTER" => Joiner::After,
            _ => return,
        };
        let capitals = w.chars().all(|c| c.is_ascii_uppercase());
        if bytes.get(end) == Some(&b'(') && !capitals {
            return;
        }
        out.push(Found {
            span: Span::new(start, end),
            joiner,
            depth,
            capitals,
        });
    };
    for (i, c) in text.char_indices() {
        if is_word(c) {
            word_start.get_or_insert(i);
            continue;
        }
        if let Some(s) = word_start.take() {
            close_word(s, i, depth, &mut out);
        }
        match c {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    if let Some(s) = word_start {
        close_word(s, text.len(), depth, &mut out);
    }
    out
}

/// A prefix form (`EVER:`, `THROUGHOUT:`, `STILL:`) at the start of
/// `text`: the form, the keyword's span and the offset after the colon.
fn prefix(text: &str) -> Option<(Form, Span, usize)> {
    let start = text.len() - text.trim_start().len();
    let rest = &text[start..];
    let end = rest
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(rest.len());
    let form = match rest[..end].to_ascii_uppercase().as_str() {
        "EVER" => Form::Ever,
        "THROUGHOUT" => Form::Throughout,
        "STILL" => Form::Still,
        _ => return None,
    };
    let after = &rest[end..];
    let colon = after.len() - after.trim_start().len();
    after[colon..]
        .starts_with(':')
        .then(|| (form, Span::new(start, start + end), start + end + colon + 1))
}

/// The byte range of `text[range]` without surrounding whitespace and
/// without one pair of parentheses that encloses all of it.
fn unwrap(text: &str, start: usize, end: usize) -> (usize, usize) {
    let s = &text[start..end];
    let lead = s.len() - s.trim_start().len();
    let (start, end) = (start + lead, start + lead + s.trim().len());
    if text[start..end].starts_with('(')
        && text[start..end].ends_with(')')
        && closing_paren(text, start) == Some(end - 1)
    {
        let (a, b) = (start + 1, end - 1);
        let inner = &text[a..b];
        let lead = inner.len() - inner.trim_start().len();
        return (a + lead, a + lead + inner.trim().len());
    }
    (start, end)
}

/// The offset of the `)` that closes the `(` at `open`.
fn closing_paren(text: &str, open: usize) -> Option<usize> {
    let mut depth = 0usize;
    for (i, c) in text[open..].char_indices() {
        match c {
            '(' => depth += 1,
            ')' => {
                depth = depth.checked_sub(1)?;
                if depth == 0 {
                    return Some(open + i);
                }
            }
            _ => {}
        }
    }
    None
}

/// True when `text` is written in a temporal form (whether or not it is
/// well formed): [`parse`] reads it, not the LogicPad's query parser.
pub(crate) fn is_temporal(text: &str) -> bool {
    prefix(text).is_some() || joiners(text).iter().any(|f| f.depth == 0 || f.capitals)
}

/// The diagnostic of a temporal query's text.
pub(super) fn diag(
    source: &Arc<SourceFile>,
    span: Span,
    kind: DiagKind,
    message: String,
) -> Diagnostic {
    Diagnostic::new(kind, Severity::Error, source, span, message)
}

/// The help of every syntax error of a temporal query.
const FORMS_HELP: &str = "temporal queries are `(Q1) THEN (Q2)`, `(Q1) BEFORE (Q2)`, `(Q1) AFTER (Q2)`, `EVER: Q`, `THROUGHOUT: Q` and `STILL: Q`, each Q an existential query";

/// Parses a temporal query and checks its parts against the LogicPad:
/// `None` when `text` is not temporal (`is_temporal`), else the query
/// or the diagnostics (spans in `text`) that make it invalid.
pub fn parse(pad: &LogicPad, text: &str) -> Option<Result<TemporalQuery, Vec<Diagnostic>>> {
    if !is_temporal(text) {
        return None;
    }
    let source = SourceFile::new("<query>", text);
    Some(parse_in(pad, &source, 0, text.len()))
}

/// Parses `source.text[start..end]` as a temporal query.
fn parse_in(
    pad: &LogicPad,
    source: &Arc<SourceFile>,
    start: usize,
    end: usize,
) -> Result<TemporalQuery, Vec<Diagnostic>> {
    let text = &source.text;
    let slice = &text[start..end];
    if let Some((form, kw, after)) = prefix(slice) {
        let kw = kw.shifted(start);
        let (a, b) = unwrap(text, start + after, end);
        let keyword = text[kw.start..kw.end].to_ascii_uppercase();
        if a == b {
            return Err(vec![
                diag(
                    source,
                    kw,
                    DiagKind::FolSyntax,
                    format!("expected a query after `{keyword}:`"),
                )
                .with_help(FORMS_HELP),
            ]);
        }
        if is_temporal(&text[a..b]) {
            // "Ever" adds nothing to a claim that already looks over
            // every window; any other nesting has no meaning here.
            let inner = parse_in(pad, source, a, b)?;
            if form == Form::Ever && matches!(inner.form, Form::Then | Form::Ever) {
                return Ok(inner);
            }
            return Err(vec![
                diag(
                    source,
                    kw,
                    DiagKind::Unsupported,
                    format!(
                        "`{keyword}:` cannot wrap `{}`: temporal forms do not nest",
                        inner.keyword
                    ),
                )
                .with_help(FORMS_HELP),
            ]);
        }
        let part = parse_part(pad, source, a, b, &keyword)?;
        return Ok(TemporalQuery {
            form,
            parts: vec![part],
            keyword,
            source: Arc::clone(source),
            keyword_span: kw,
        });
    }
    let found: Vec<Found> = joiners(slice)
        .into_iter()
        .map(|f| Found {
            span: f.span.shifted(start),
            ..f
        })
        .collect();
    let top: Vec<Found> = found.iter().copied().filter(|f| f.depth == 0).collect();
    if top.is_empty() {
        let (a, b) = unwrap(text, start, end);
        if (a, b) != (start, end) && a > start {
            // `((Q1) THEN (Q2))`: the whole query in parentheses.
            return parse_in(pad, source, a, b);
        }
        let at = found.first().map_or(Span::new(start, end), |f| f.span);
        let word = found.first().map_or("THEN", |f| f.joiner.word());
        return Err(vec![
            diag(
                source,
                at,
                DiagKind::FolSyntax,
                format!("`{word}` must stand between two whole queries, outside their parentheses"),
            )
            .with_label("inside a query")
            .with_help(format!("write `(Q1) {word} (Q2)`")),
        ]);
    }
    let first = top[0];
    if let Some(other) = top
        .iter()
        .find(|f| (f.joiner == Joiner::After) != (first.joiner == Joiner::After))
    {
        return Err(vec![
            diag(
                source,
                other.span,
                DiagKind::Unsupported,
                format!(
                    "`{}` and `{}` in one chain leave the order ambiguous",
                    first.joiner.word(),
                    other.joiner.word()
                ),
            )
            .with_help("write the chain in one direction: `(Q1) THEN (Q2) THEN (Q3)`"),
        ]);
    }
    let mut parts = Vec::with_capacity(top.len() + 1);
    let mut errors = Vec::new();
    let mut from = start;
    let bounds = top
        .iter()
        .map(|f| (f.span.start, Some(*f)))
        .chain(std::iter::once((end, None)));
    let mut before: Option<Found> = None;
    for (to, next) in bounds {
        let (a, b) = unwrap(text, from, to);
        let keyword = next.or(before).map_or("THEN", |f| f.joiner.word());
        if a == b {
            let (at, msg) = match (before, next) {
                (Some(f), _) => (
                    f.span,
                    format!("expected a query after `{}`", f.joiner.word()),
                ),
                (None, Some(f)) => (
                    f.span,
                    format!("expected a query before `{}`", f.joiner.word()),
                ),
                (None, None) => (Span::new(start, end), "expected a query".to_string()),
            };
            errors.push(diag(source, at, DiagKind::FolSyntax, msg).with_help(FORMS_HELP));
        } else {
            match parse_part(pad, source, a, b, keyword) {
                Ok(p) => parts.push(p),
                Err(d) => errors.extend(d),
            }
        }
        if let Some(f) = next {
            from = f.span.end;
        }
        before = next;
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    if first.joiner == Joiner::After {
        parts.reverse();
    }
    Ok(TemporalQuery {
        form: Form::Then,
        parts,
        keyword: first.joiner.word().to_string(),
        source: Arc::clone(source),
        keyword_span: first.span,
    })
}

/// Parses and checks one wrapped query, `source.text[a..b]`, its
/// diagnostics moved to where it stands in the whole text.
fn parse_part(
    pad: &LogicPad,
    source: &Arc<SourceFile>,
    a: usize,
    b: usize,
    keyword: &str,
) -> Result<Part, Vec<Diagnostic>> {
    let text = &source.text[a..b];
    let span = Span::new(a, b);
    if is_temporal(text) {
        return Err(vec![
            diag(
                source,
                span,
                DiagKind::Unsupported,
                format!("a temporal form cannot stand inside `{keyword}`"),
            )
            .with_help(FORMS_HELP),
        ]);
    }
    let moved = |d: Diagnostic| -> Diagnostic {
        // Only a diagnostic about the part's own text is moved; one that
        // points elsewhere (the LogicPad) stays as it is.
        if d.source.text != text {
            return d;
        }
        let mut d = d;
        d.span = d.span.shifted(a);
        for l in &mut d.related {
            l.span = l.span.shifted(a);
        }
        d.source = Arc::clone(source);
        d
    };
    let parsed = crate::ask::prepare(pad, text)
        .map_err(|ds| ds.into_iter().map(moved).collect::<Vec<_>>())?;
    if matches!(parsed, ParsedQuery::Forall(_)) {
        return Err(vec![
            diag(
                source,
                span,
                DiagKind::Unsupported,
                format!("a universal query (`∀`) cannot stand inside `{keyword}`"),
            )
            .with_help("wrap existential queries; say \"every\" with `THROUGHOUT:` or a `¬∃` inside the query"),
        ]);
    }
    Ok(Part {
        text: text.to_string(),
        span,
        prepared: Prepared {
            question: None,
            query: text.to_string(),
            notes: Vec::new(),
            intent: crate::translate::Intent::YesNo,
            parsed: Ok(parsed),
            temporal: None,
        },
    })
}
