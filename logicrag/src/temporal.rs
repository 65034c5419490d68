//! Time across a video's windows: `(Q1) THEN (Q2)`, `(Q1) BEFORE (Q2)`,
//! `(Q1) AFTER (Q2)`, `EVER: Q`, `THROUGHOUT: Q` and `STILL: Q` wrap
//! existential queries, and are answered once per video from every
//! window's answer to each wrapped query (docs/temporal.md).
//!
//! ```text
//! text ──parse──▶ TemporalQuery { form, parts (time order) }         (once)
//! (part, window) ──Engine::ask──▶ AskResult                           (per window and part)
//! [[AskResult]] ──evaluate──▶ TemporalAnswer { AskResult for the video, timelines }
//! ```
//!
//! A window's answer to a part says *whether* the part holds in the
//! window's frames and with which bindings; the time of an answer is its
//! window's frame range, never finer. So `Q1 THEN Q2` is proved for a
//! binding only by two windows in order (Q1's ends before Q2's starts);
//! one window, or overlapping windows, cannot order what they both see.

use crate::ask::{AskOptions, AskResult, Outcome};
use crate::engine::{Engine, Prepared};
use crate::kb::WindowKb;
use logicpad::{DiagKind, Diagnostic, LogicPad, ParsedQuery, Severity, SourceFile, Span};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

/// Which temporal claim a query makes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Form {
    /// `(Q1) THEN (Q2)` (also `BEFORE`, and `AFTER` with the parts
    /// swapped): the parts hold with the same shared objects in windows
    /// that follow each other.
    Then,
    /// `EVER: Q`: Q holds in some window.
    Ever,
    /// `THROUGHOUT: Q`: Q holds with one binding in every window in which
    /// that binding's objects are seen.
    Throughout,
    /// `STILL: Q`: Q holds with one binding in the last window and in
    /// every window since the first in which it held.
    Still,
}

impl Form {
    /// `"then"`, `"ever"`, `"throughout"` or `"still"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Form::Then => "then",
            Form::Ever => "ever",
            Form::Throughout => "throughout",
            Form::Still => "still",
        }
    }
}

/// One wrapped query of a temporal query.
#[derive(Debug, Clone)]
pub struct Part {
    /// The query as written (without its parentheses).
    pub text: String,
    /// Where it is written in the temporal query's text.
    pub span: Span,
    /// The query, parsed and checked against the LogicPad (never temporal
    /// itself).
    pub prepared: Prepared,
}

/// A temporal query, parsed and checked once for a whole video.
///
/// Invariant: `parts` is in time order (`(A) AFTER (B)` is stored as B
/// then A); a [`Form::Then`] has at least two parts, every other form
/// exactly one; no part is temporal or universal.
#[derive(Debug, Clone)]
pub struct TemporalQuery {
    /// The claim.
    pub form: Form,
    /// The wrapped queries, in time order.
    pub parts: Vec<Part>,
    /// The keyword as written, upper case (`THEN`, `BEFORE`, `AFTER`,
    /// `EVER`, `THROUGHOUT`, `STILL`).
    pub keyword: String,
    /// The whole text, for the diagnostic of a window asked alone.
    source: Arc<SourceFile>,
    /// Where the (first) keyword is written.
    keyword_span: Span,
}

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
pub fn is_temporal(text: &str) -> bool {
    prefix(text).is_some() || joiners(text).iter().any(|f| f.depth == 0 || f.capitals)
}

/// The diagnostic of a temporal query's text.
fn diag(source: &Arc<SourceFile>, span: Span, kind: DiagKind, message: String) -> Diagnostic {
    Diagnostic::new(kind, Severity::Error, source, span, message)
}

/// The help of every syntax error of a temporal query.
const FORMS_HELP: &str = "temporal queries are `(Q1) THEN (Q2)`, `(Q1) BEFORE (Q2)`, `(Q1) AFTER (Q2)`, `EVER: Q`, `THROUGHOUT: Q` and `STILL: Q`, each Q an existential query";

/// Parses a temporal query and checks its parts against the LogicPad:
/// `None` when `text` is not temporal ([`is_temporal`]), else the query
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

impl TemporalQuery {
    /// The answer of one window asked alone: invalid, saying that the
    /// claim is about the order of windows (a batch line, an evaluation
    /// record, a per-window API call).
    pub fn one_window(&self, kb: &WindowKb, query: &str) -> AskResult {
        let d = diag(
            &self.source,
            self.keyword_span,
            DiagKind::Unsupported,
            format!(
                "`{}` is a claim about a video's windows over time: one window alone cannot answer it",
                self.keyword
            ),
        )
        .with_label("answered once per video")
        .with_help(
            "ask it over the whole video (`logicrag ask --source …` without --queries; --window-id W looks back from W)",
        );
        crate::ask::invalid(kb, query, &[d])
    }

    /// The first part's checked query (what [`Prepared::parsed`] holds for
    /// a temporal query).
    pub(crate) fn first_parsed(&self) -> Option<ParsedQuery> {
        self.parts
            .first()
            .and_then(|p| p.prepared.parsed.clone().ok())
    }
}

/// A range of frames, both ends included.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct Frames {
    /// First frame.
    pub first: u32,
    /// Last frame.
    pub last: u32,
}

impl std::fmt::Display for Frames {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.first == self.last {
            write!(f, "frame {}", self.first)
        } else {
            write!(f, "frames {}–{}", self.first, self.last)
        }
    }
}

/// When one part holds for one binding.
#[derive(Debug, Clone, Serialize)]
pub struct PartTimes {
    /// The part as written.
    pub query: String,
    /// Where it holds with the binding: its windows' frames, windows that
    /// touch or overlap merged.
    pub frames: Vec<Frames>,
    /// The window that proves the claim for this part (`THEN`: the
    /// ordered windows; `EVER`/`STILL`: the first window; `THROUGHOUT`:
    /// the first window seen).
    pub witness: Option<Frames>,
}

/// One binding for which the claim holds, with its times.
#[derive(Debug, Clone, Serialize)]
pub struct Timeline {
    /// The shared variables' values, sorted by variable.
    pub binding: Vec<(String, String)>,
    /// Each part's times, in time order.
    pub parts: Vec<PartTimes>,
    /// The claim in words ("x = car_1: `Decelerate(x)` in frames 10–19,
    /// then `Stopped(x)` in frames 20–29").
    pub said: String,
}

/// A temporal query's answer over a video.
///
/// Invariant: `result.answer` is yes exactly when `holds` is not empty;
/// `result.bindings[i]` is `holds[i].binding`.
#[derive(Debug, Clone, Serialize)]
pub struct TemporalAnswer {
    /// The claim.
    pub form: Form,
    /// The keyword as written.
    pub keyword: String,
    /// The parts as written, in time order.
    pub parts: Vec<String>,
    /// Windows looked at.
    pub windows: usize,
    /// The bindings for which the claim holds.
    pub holds: Vec<Timeline>,
    /// The one line that answers the question.
    pub headline: String,
    /// The answer as one result spanning the video: `window` is the
    /// source's label, the frames those of every window looked at.
    #[serde(skip)]
    pub result: AskResult,
}

/// Bindings named in a headline before "and N more".
const HEADLINE_BINDINGS: usize = 2;
/// Timelines said in the notes before "and N more".
const NOTE_TIMELINES: usize = 20;

/// Answers a temporal query over `kbs` (in source order) of the source
/// labelled `label`: each part is asked of each window, then the claim is
/// read from those answers ([`evaluate`]).
pub fn answer(
    engine: &Engine,
    label: &str,
    t: &TemporalQuery,
    query: &str,
    kbs: &[&WindowKb],
    opts: AskOptions,
) -> TemporalAnswer {
    use rayon::prelude::*;
    // Bindings are needed whatever the caller asked for (a count-only
    // batch); why-not of a part in one window says nothing of the claim.
    let sub = AskOptions {
        count_only: false,
        why_not: false,
        ..opts
    };
    let results: Vec<Vec<AskResult>> = t
        .parts
        .iter()
        .map(|p| {
            kbs.par_iter()
                .map(|kb| engine.ask(kb, &p.prepared, sub))
                .collect()
        })
        .collect();
    evaluate(label, t, query, kbs, &results, opts)
}

/// The literals of a conjunction as written: `text` split at the `^`/`∧`
/// outside parentheses, each trimmed.
fn literals(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let (mut depth, mut from) = (0usize, 0usize);
    for (i, c) in text.char_indices() {
        match c {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            '^' | '∧' if depth == 0 => {
                out.push(text[from..i].trim());
                from = i + c.len_utf8();
            }
            _ => {}
        }
    }
    out.push(text[from..].trim());
    out
}

/// Each part said without the literals that every part has (as written),
/// joined by ` ∧ `; a part that would be left empty, or one that is not a
/// plain conjunction, is said whole.
fn distinct_literals(parts: &[Part]) -> Vec<String> {
    let split: Vec<Vec<&str>> = parts.iter().map(|p| literals(&p.text)).collect();
    let common: Vec<&str> = split
        .first()
        .map(|first| {
            first
                .iter()
                .copied()
                .filter(|l| split.iter().all(|s| s.contains(l)))
                .collect()
        })
        .unwrap_or_default();
    parts
        .iter()
        .zip(&split)
        .map(|(p, lits)| {
            let own: Vec<&str> = lits
                .iter()
                .copied()
                .filter(|l| !common.contains(l))
                .collect();
            let plain = !p.text.contains(['∨', '|']) && !p.text.to_lowercase().contains(" or ");
            if own.is_empty() || !plain || own.len() == lits.len() {
                p.text.clone()
            } else {
                own.join(" ∧ ")
            }
        })
        .collect()
}

/// A binding of some variables, sorted by variable.
type Key = Vec<(String, String)>;

/// One part's answers over the windows, read for a claim.
struct PartView<'a> {
    part: &'a Part,
    results: &'a [AskResult],
    /// Per window: the part's bindings projected on the claim's shared
    /// variables, each with the index of its first full binding.
    keys: Vec<BTreeMap<Key, usize>>,
    /// The part's variables that the claim shares.
    shared: Vec<String>,
    /// The part as said in an answer: without the literals every part of
    /// a `THEN` shares (`TypeOf(x, Car)` said once is enough), else as
    /// written.
    short: String,
}

impl PartView<'_> {
    /// The windows (indices) where the part holds with `key` (its
    /// projection of a claim's binding).
    fn windows_of(&self, key: &Key) -> Vec<usize> {
        (0..self.keys.len())
            .filter(|&w| self.keys[w].contains_key(key))
            .collect()
    }

    fn outcome(&self, w: usize) -> Outcome {
        self.results.get(w).map_or(Outcome::Invalid, |r| r.answer)
    }

    /// The probability of the part holding with `key` in window `w`.
    fn probability(&self, w: usize, key: &Key) -> f64 {
        let Some(r) = self.results.get(w) else {
            return 1.0;
        };
        match self.keys[w].get(key) {
            Some(&i) => r
                .binding_probabilities
                .get(i)
                .copied()
                .or(r.probability)
                .unwrap_or(1.0),
            None => 1.0,
        }
    }

    /// The proof of the part holding with `key` in window `w`.
    fn proof(&self, w: usize, key: &Key) -> Vec<crate::proof::ProofNode> {
        let (Some(r), Some(&i)) = (self.results.get(w), self.keys[w].get(key)) else {
            return Vec::new();
        };
        r.proofs.get(i).cloned().unwrap_or_default()
    }
}

/// The answer variables of a part, from its answers (or its query).
fn variables_of(part: &Part, results: &[AskResult]) -> Vec<String> {
    if let Some(r) = results.iter().find(|r| !r.variables.is_empty()) {
        return r.variables.clone();
    }
    match &part.prepared.parsed {
        Ok(ParsedQuery::Exists(ast)) => ast
            .answer_var_names()
            .into_iter()
            .map(str::to_string)
            .collect(),
        _ => Vec::new(),
    }
}

fn project(binding: &[(String, String)], vars: &[String]) -> Key {
    let mut k: Key = binding
        .iter()
        .filter(|(v, _)| vars.contains(v))
        .cloned()
        .collect();
    k.sort();
    k
}

/// `x = car_1, y = car_2` (empty for no variables).
fn binding_text(b: &[(String, String)]) -> String {
    b.iter()
        .map(|(v, c)| format!("{v} = {c}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn with_binding(b: &[(String, String)], said: String) -> String {
    if b.is_empty() {
        said
    } else {
        format!("{}: {said}", binding_text(b))
    }
}

/// Windows' frames merged where they touch or overlap.
fn spans(frames: &[Frames], windows: &[usize]) -> Vec<Frames> {
    let mut out: Vec<Frames> = Vec::new();
    for &w in windows {
        let Some(&f) = frames.get(w) else { continue };
        match out.last_mut() {
            Some(last) if f.first <= last.last.saturating_add(1) => {
                last.last = last.last.max(f.last);
            }
            _ => out.push(f),
        }
    }
    out
}

fn spans_text(s: &[Frames]) -> String {
    match s {
        [] => "no frames".into(),
        [one] => one.to_string(),
        many => {
            let ranges: Vec<String> = many
                .iter()
                .map(|f| format!("{}–{}", f.first, f.last))
                .collect();
            format!("frames {}", ranges.join(", "))
        }
    }
}

/// The earliest windows, one per list in order, each related to the one
/// before by `follows(previous, next)`; `None` when there are none.
/// Earliest-first is enough: windows are in source order, both their
/// first and last frames increasing, and every relation used is monotone
/// in them.
fn chain(
    lists: &[Vec<usize>],
    frames: &[Frames],
    follows: impl Fn(Frames, Frames) -> bool,
) -> Option<Vec<usize>> {
    let mut out: Vec<usize> = Vec::with_capacity(lists.len());
    for list in lists {
        let next = list.iter().copied().find(|&w| match out.last() {
            None => true,
            Some(&p) => follows(frames[p], frames[w]),
        })?;
        out.push(next);
    }
    Some(out)
}

/// Proven order: the earlier window ends before the later one starts.
fn before(a: Frames, b: Frames) -> bool {
    a.last < b.first
}

/// For each window of `windows` (a part's windows for one binding, in
/// source order), the first frame of its *episode*: the run of windows
/// that touch or overlap it in which the part holds too (as `spans`
/// merges them).
fn episode_starts(frames: &[Frames], windows: &[usize]) -> Vec<u32> {
    let mut out: Vec<u32> = Vec::with_capacity(windows.len());
    let mut run: Option<Frames> = None;
    for &w in windows {
        let Some(&f) = frames.get(w) else {
            out.push(u32::MAX);
            continue;
        };
        run = match run {
            Some(r) if f.first <= r.last.saturating_add(1) => Some(Frames {
                first: r.first,
                last: r.last.max(f.last),
            }),
            _ => Some(f),
        };
        out.push(run.map_or(f.first, |r| r.first));
    }
    out
}

/// The earliest windows, one per part, each *after* the one before: it
/// starts after that window ends (`before`), and its part's episode began
/// after the earlier part's episode began. The second condition is what
/// "A, then B" says beyond two windows in order: "did we stop before the
/// pedestrian crossed?" is no when the crossing was already under way
/// (frames 30–79) when we stopped (frames 40–79), though a window of
/// standing (40–49) ends before a window of crossing (50–59) starts.
/// Earliest-first is enough for the same reason as in `chain`: both
/// conditions are monotone in the earlier window.
fn chain_episodes(lists: &[Vec<usize>], frames: &[Frames]) -> Option<Vec<usize>> {
    let starts: Vec<Vec<u32>> = lists.iter().map(|l| episode_starts(frames, l)).collect();
    let mut out: Vec<(usize, u32)> = Vec::with_capacity(lists.len());
    for (list, starts) in lists.iter().zip(&starts) {
        let next =
            list.iter()
                .copied()
                .zip(starts.iter().copied())
                .find(|&(w, start)| match out.last() {
                    None => true,
                    Some(&(p, p_start)) => before(frames[p], frames[w]) && start > p_start,
                })?;
        out.push(next);
    }
    Some(out.into_iter().map(|(w, _)| w).collect())
}

/// Not proven the other way: the later window does not end before the
/// earlier one starts (in order, or overlapping).
fn not_after(a: Frames, b: Frames) -> bool {
    b.last >= a.first
}

/// Reads a temporal claim from every window's answer to each part
/// (`results[part][window]`, windows as in `kbs`, in source order: one
/// list per part, each as long as `kbs`).
pub fn evaluate(
    label: &str,
    t: &TemporalQuery,
    query: &str,
    kbs: &[&WindowKb],
    results: &[Vec<AskResult>],
    opts: AskOptions,
) -> TemporalAnswer {
    // One answer per window and part is the contract; a shorter list
    // (a caller's mistake) shortens the video rather than panicking.
    let windows = results.iter().map(Vec::len).fold(kbs.len(), usize::min);
    let kbs = &kbs[..windows];
    let results: Vec<&[AskResult]> = results.iter().map(|r| &r[..windows]).collect();
    let frames: Vec<Frames> = kbs
        .iter()
        .map(|k| Frames {
            first: k.first_frame,
            last: k.last_frame,
        })
        .collect();
    let all_vars: Vec<Vec<String>> = t
        .parts
        .iter()
        .zip(&results)
        .map(|(p, r)| variables_of(p, r))
        .collect();
    // The claim's variables: for THEN those of two parts or more (a
    // variable of one part only is existential on its side), else the
    // part's own.
    let mut shared: Vec<String> = Vec::new();
    for vars in &all_vars {
        for v in vars {
            let n = all_vars.iter().filter(|vs| vs.contains(v)).count();
            if (t.form != Form::Then || n >= 2) && !shared.contains(v) {
                shared.push(v.clone());
            }
        }
    }
    let views: Vec<PartView<'_>> = t
        .parts
        .iter()
        .zip(results)
        .zip(&all_vars)
        .map(|((part, results), vars)| {
            let own: Vec<String> = vars
                .iter()
                .filter(|v| shared.contains(v))
                .cloned()
                .collect();
            let keys = results
                .iter()
                .map(|r| {
                    let mut m = BTreeMap::new();
                    if r.answer == Outcome::Yes {
                        for (i, b) in r.bindings.iter().enumerate() {
                            m.entry(project(b, &own)).or_insert(i);
                        }
                    }
                    m
                })
                .collect();
            PartView {
                part,
                results,
                keys,
                shared: own,
                short: part.text.clone(),
            }
        })
        .collect();
    let mut views = views;
    if t.form == Form::Then {
        for (v, short) in views.iter_mut().zip(distinct_literals(&t.parts)) {
            v.short = short;
        }
    }
    let mut e = Evaluation {
        frames: &frames,
        kbs,
        views: &views,
        holds: Vec::new(),
        proofs: Vec::new(),
        probabilities: Vec::new(),
        unknown: Vec::new(),
        failed: Vec::new(),
        notes: Vec::new(),
        none: None,
    };
    match t.form {
        _ if e.views.is_empty() => e.unknown.push("no part of the query was asked".into()),
        Form::Then => e.then(opts.max_answers),
        Form::Ever => e.ever(),
        Form::Throughout => e.throughout(),
        Form::Still => e.still(),
    }
    e.finish(label, t, query, &shared, opts)
}

/// The working state of [`evaluate`].
struct Evaluation<'a> {
    frames: &'a [Frames],
    kbs: &'a [&'a WindowKb],
    views: &'a [PartView<'a>],
    /// Bindings for which the claim holds.
    holds: Vec<Timeline>,
    /// Their proofs (the parts' proofs in their witness windows).
    proofs: Vec<Vec<crate::proof::ProofNode>>,
    /// Their probabilities.
    probabilities: Vec<f64>,
    /// Why the claim cannot be told for a binding or at all.
    unknown: Vec<String>,
    /// Candidates for which it fails: what held when, and why it fails.
    failed: Vec<(Key, Vec<String>, String)>,
    /// What else the answer rests on.
    notes: Vec<String>,
    /// Why a "no" has no candidate at all (no binding that any part
    /// holds with), in words.
    none: Option<String>,
}

impl Evaluation<'_> {
    /// Every key of part `i` over all windows.
    fn keys_of(&self, i: usize) -> BTreeSet<Key> {
        self.views[i]
            .keys
            .iter()
            .flat_map(|m| m.keys().cloned())
            .collect()
    }

    /// The claim's bindings that every part can have: the parts' keys
    /// joined on the variables they share (at most `limit`).
    fn candidates(&self, limit: usize) -> (Vec<Key>, bool) {
        let mut partial: Vec<Key> = vec![Vec::new()];
        let mut cut = false;
        for i in 0..self.views.len() {
            let keys = self.keys_of(i);
            let mut next = Vec::new();
            for p in &partial {
                for k in &keys {
                    let agrees = k
                        .iter()
                        .all(|(v, c)| p.iter().all(|(w, d)| w != v || d == c));
                    if agrees {
                        let mut m = p.clone();
                        m.extend(
                            k.iter()
                                .filter(|(v, _)| !p.iter().any(|(w, _)| w == v))
                                .cloned(),
                        );
                        m.sort();
                        next.push(m);
                    }
                }
            }
            next.sort();
            next.dedup();
            // Bounded at every step: a join of many parts over many
            // objects must not grow past the answer limit.
            cut |= next.len() > limit;
            next.truncate(limit);
            partial = next;
        }
        (partial, cut)
    }

    fn part_times(&self, i: usize, key: &Key, witness: Option<usize>) -> PartTimes {
        let v = &self.views[i];
        let k = project(key, &v.shared);
        PartTimes {
            query: v.part.text.clone(),
            frames: spans(self.frames, &v.windows_of(&k)),
            witness: witness.and_then(|w| self.frames.get(w).copied()),
        }
    }

    /// Records a binding that holds, proved by part `i` in window
    /// `witness[i]`.
    fn hold(&mut self, key: Key, witness: &[usize], said: String) {
        let mut proof = Vec::new();
        let mut p = 1.0;
        for (i, &w) in witness.iter().enumerate() {
            let v = &self.views[i.min(self.views.len() - 1)];
            let k = project(&key, &v.shared);
            proof.extend(v.proof(w, &k));
            p *= v.probability(w, &k);
        }
        let parts = (0..self.views.len())
            .map(|i| self.part_times(i, &key, witness.get(i).copied()))
            .collect();
        self.holds.push(Timeline {
            said: with_binding(&key, said),
            binding: key,
            parts,
        });
        self.proofs.push(proof);
        self.probabilities.push(p);
    }

    /// Windows where part `i` cannot tell (unknown, or invalid).
    fn blind(&self, i: usize) -> Vec<usize> {
        (0..self.frames.len())
            .filter(|&w| {
                matches!(
                    self.views[i].outcome(w),
                    Outcome::Unknown | Outcome::Invalid
                )
            })
            .collect()
    }

    fn then(&mut self, limit: usize) {
        let (candidates, cut) = self.candidates(limit);
        if cut {
            self.notes.push(format!(
                "only the first {limit} bindings shared by the parts were looked at"
            ));
        }
        let n = self.views.len();
        if candidates.is_empty() {
            self.none = Some(match (0..n).find(|&i| self.keys_of(i).is_empty()) {
                Some(i) => self.in_no_window(i),
                None => format!(
                    "{} never hold for the same {}",
                    self.views
                        .iter()
                        .map(|v| format!("`{}`", v.short))
                        .collect::<Vec<_>>()
                        .join(" and "),
                    self.shared_names()
                ),
            });
        }
        for key in candidates {
            let lists: Vec<Vec<usize>> = self
                .views
                .iter()
                .map(|v| v.windows_of(&project(&key, &v.shared)))
                .collect();
            if let Some(w) = chain_episodes(&lists, self.frames) {
                let said = (0..n)
                    .map(|i| format!("`{}` in {}", self.views[i].short, self.frames[w[i]]))
                    .collect::<Vec<_>>()
                    .join(", then ");
                self.hold(key, &w, said);
                continue;
            }
            let seen: Vec<String> = (0..n)
                .map(|i| {
                    format!(
                        "`{}` in {}",
                        self.views[i].short,
                        spans_text(&spans(self.frames, &lists[i]))
                    )
                })
                .collect();
            // A candidate comes from the join, so every part holds with
            // it somewhere: what is left is their order.
            let reversed: Vec<Vec<usize>> = lists.iter().rev().cloned().collect();
            let tied = chain(&lists, self.frames, not_after).is_some();
            let opposite = chain(&reversed, self.frames, before).is_some();
            // Two windows in order, but the later part's episode had begun
            // first: it was already going on.
            let ongoing = chain(&lists, self.frames, before).is_some();
            if ongoing {
                self.failed.push((
                    key,
                    seen,
                    "the second was already going on when the first began".to_string(),
                ));
                continue;
            }
            if tied && !opposite {
                self.unknown.push(with_binding(
                    &key,
                    format!(
                        "{}: the windows overlap, and one window cannot tell which came first",
                        seen.join(" and ")
                    ),
                ));
            } else {
                let why = if tied {
                    "the windows show them in the opposite order, and where they overlap one window cannot order them"
                } else {
                    "never in that order"
                };
                self.failed.push((key, seen, why.to_string()));
            }
        }
        if !self.holds.is_empty() || !self.unknown.is_empty() {
            return;
        }
        // A window that cannot tell may hide a binding: unknown when the
        // windows that hold or cannot tell could still be in order.
        let possible: Vec<Vec<usize>> = (0..n)
            .map(|i| {
                (0..self.frames.len())
                    .filter(|&w| {
                        matches!(
                            self.views[i].outcome(w),
                            Outcome::Yes | Outcome::Unknown | Outcome::Invalid
                        )
                    })
                    .collect()
            })
            .collect();
        let blind = (0..n).any(|i| !self.blind(i).is_empty());
        if blind && chain(&possible, self.frames, before).is_some() {
            self.unknown.push(
                "some windows cannot tell whether a part holds, and they could put the parts in order"
                    .into(),
            );
        }
    }

    /// "`Q` holds in none of the 6 windows".
    fn in_no_window(&self, i: usize) -> String {
        let n = self.frames.len();
        format!(
            "`{}` holds in {}",
            self.views[i].short,
            if n == 1 {
                "no window".to_string()
            } else {
                format!("none of the {n} windows")
            }
        )
    }

    /// The variables the parts share ("x", "x and y"), or "objects".
    fn shared_names(&self) -> String {
        let mut vars: Vec<&str> = Vec::new();
        for v in self.views {
            for s in &v.shared {
                if !vars.contains(&s.as_str()) {
                    vars.push(s);
                }
            }
        }
        if vars.is_empty() {
            "objects".into()
        } else {
            vars.join(" and ")
        }
    }

    fn ever(&mut self) {
        if self.keys_of(0).is_empty() {
            self.none = Some(self.in_no_window(0));
        }
        for key in self.keys_of(0) {
            let ws = self.views[0].windows_of(&key);
            let said = format!(
                "`{}` in {}",
                self.views[0].short,
                spans_text(&spans(self.frames, &ws))
            );
            self.hold(key, &ws[..1.min(ws.len())], said);
        }
        if self.holds.is_empty() && !self.blind(0).is_empty() {
            self.unknown
                .push("no window proves it, and some windows cannot tell".into());
        }
    }

    /// The object constants of `key` and of the part's positive atoms:
    /// the objects that must be seen in a window for it to count.
    fn objects_of(&self, key: &Key) -> Vec<String> {
        let all: BTreeSet<&str> = self
            .kbs
            .iter()
            .flat_map(|k| k.objects.iter().copied())
            .collect();
        let mut out: Vec<String> = key.iter().map(|(_, c)| c.clone()).collect();
        if let Ok(ParsedQuery::Exists(ast)) = &self.views[0].part.prepared.parsed {
            for a in ast
                .disjuncts
                .iter()
                .flatten()
                .filter_map(logicpad::fol::Literal::positive)
            {
                for arg in &a.args {
                    if let logicpad::fol::Arg::Const(c) = arg {
                        out.push(c.clone());
                    }
                }
            }
        }
        out.retain(|c| all.contains(c.as_str()));
        out.sort();
        out.dedup();
        out
    }

    /// Checks that part 0 holds with `key` in each of `windows`: the
    /// windows where it fails, and those that cannot tell.
    fn every(&self, key: &Key, windows: &[usize]) -> (Vec<usize>, Vec<usize>) {
        let v = &self.views[0];
        let (mut fails, mut blind) = (Vec::new(), Vec::new());
        for &w in windows {
            if v.keys[w].contains_key(key) {
                continue;
            }
            match v.outcome(w) {
                Outcome::Unknown | Outcome::Invalid => blind.push(w),
                _ => fails.push(w),
            }
        }
        (fails, blind)
    }

    fn throughout(&mut self) {
        let text = self.views[0].short.clone();
        if self.keys_of(0).is_empty() {
            self.none = Some(self.in_no_window(0));
        }
        for key in self.keys_of(0) {
            let objects = self.objects_of(&key);
            let seen: Vec<usize> = (0..self.kbs.len())
                .filter(|&w| {
                    objects
                        .iter()
                        .all(|o| self.kbs[w].objects.contains(o.as_str()))
                })
                .collect();
            let (fails, blind) = self.every(&key, &seen);
            let seen_text = spans_text(&spans(self.frames, &seen));
            let holding = spans(self.frames, &self.views[0].windows_of(&key));
            if fails.is_empty() && blind.is_empty() {
                let whom = match objects.as_slice() {
                    [] => "every window".to_string(),
                    [one] => format!("every window {one} is seen in"),
                    many => format!("every window {} are seen in", many.join(" and ")),
                };
                let said = format!("`{text}` in {whom}: {seen_text}");
                self.hold(key, &seen[..1.min(seen.len())], said);
            } else if fails.is_empty() {
                self.unknown.push(with_binding(
                    &key,
                    format!(
                        "`{text}` holds in {}, and {} cannot tell",
                        spans_text(&holding),
                        spans_text(&spans(self.frames, &blind))
                    ),
                ));
            } else {
                self.failed.push((
                    key,
                    vec![format!("`{text}` in {}", spans_text(&holding))],
                    format!(
                        "not in {}, though {} seen there",
                        spans_text(&spans(self.frames, &fails)),
                        match objects.as_slice() {
                            [] => "everything is".to_string(),
                            [one] => format!("{one} is"),
                            many => format!("{} are", many.join(" and ")),
                        }
                    ),
                ));
            }
        }
        if self.holds.is_empty() && self.unknown.is_empty() && !self.blind(0).is_empty() {
            self.unknown
                .push("no window proves it, and some windows cannot tell".into());
        }
    }

    fn still(&mut self) {
        let text = self.views[0].short.clone();
        if self.keys_of(0).is_empty() {
            self.none = Some(self.in_no_window(0));
        }
        let Some(last) = self.frames.len().checked_sub(1) else {
            return;
        };
        for key in self.keys_of(0) {
            let ws = self.views[0].windows_of(&key);
            let Some(&first) = ws.first() else { continue };
            let since: Vec<usize> = (first..=last).collect();
            let (fails, blind) = self.every(&key, &since);
            let holding = spans(self.frames, &ws);
            if fails.is_empty() && blind.is_empty() {
                let said = format!(
                    "`{text}` since {}, through the last window ({})",
                    self.frames[first], self.frames[last]
                );
                self.hold(key, &[first], said);
            } else if fails.is_empty() {
                self.unknown.push(with_binding(
                    &key,
                    format!(
                        "`{text}` holds in {}, and {} cannot tell",
                        spans_text(&holding),
                        spans_text(&spans(self.frames, &blind))
                    ),
                ));
            } else {
                let why = if fails.contains(&last) {
                    format!("not in the last window ({})", self.frames[last])
                } else {
                    format!(
                        "it stopped holding in {}",
                        spans_text(&spans(self.frames, &fails))
                    )
                };
                self.failed.push((
                    key,
                    vec![format!("`{text}` in {}", spans_text(&holding))],
                    why,
                ));
            }
        }
        if self.holds.is_empty() && self.unknown.is_empty() && !self.blind(0).is_empty() {
            let last_blind = self.blind(0).contains(&last);
            if last_blind || self.failed.is_empty() {
                self.unknown
                    .push("no window proves it, and some windows cannot tell".into());
            }
        }
    }

    /// The answer spanning the video.
    fn finish(
        self,
        label: &str,
        t: &TemporalQuery,
        query: &str,
        shared: &[String],
        opts: AskOptions,
    ) -> TemporalAnswer {
        let windows = self.frames.len();
        let invalid: Vec<&AskResult> = self
            .views
            .iter()
            .flat_map(|v| v.results.iter())
            .filter(|r| r.answer == Outcome::Invalid)
            .collect();
        let answer = if !self.holds.is_empty() {
            Outcome::Yes
        } else if !invalid.is_empty() {
            Outcome::Invalid
        } else if !self.unknown.is_empty() {
            Outcome::Unknown
        } else {
            Outcome::No
        };
        let mut r = AskResult {
            window: label.to_string(),
            first_frame: self.frames.iter().map(|f| f.first).min().unwrap_or(0),
            last_frame: self.frames.iter().map(|f| f.last).max().unwrap_or(0),
            query: query.to_string(),
            answer,
            variables: shared.to_vec(),
            count: self.holds.len(),
            bindings: self.holds.iter().map(|h| h.binding.clone()).collect(),
            proofs: Vec::new(),
            why_not: Vec::new(),
            reasons: Vec::new(),
            diagnostics: Vec::new(),
            notes: Vec::new(),
            too_large: None,
            probability: None,
            binding_probabilities: Vec::new(),
            hinges: Vec::new(),
        };
        if opts.proofs && answer == Outcome::Yes {
            r.proofs = self.proofs;
        }
        for h in self.holds.iter().take(NOTE_TIMELINES) {
            r.notes.push(h.said.clone());
        }
        if self.holds.len() > NOTE_TIMELINES {
            r.notes
                .push(format!("… and {} more", self.holds.len() - NOTE_TIMELINES));
        }
        r.notes.extend(self.notes);
        match answer {
            Outcome::Yes => {
                let best = self.probabilities.iter().copied().fold(0.0, f64::max);
                r.probability = Some(crate::belief::rounded(best));
                if self.probabilities.iter().any(|&p| p < 1.0) {
                    r.binding_probabilities = self
                        .probabilities
                        .iter()
                        .map(|&p| crate::belief::rounded(p))
                        .collect();
                }
            }
            Outcome::No => {
                // A "no" rests on every window's answer: as sure as the
                // least sure of them.
                let least = self
                    .views
                    .iter()
                    .flat_map(|v| v.results.iter())
                    .filter_map(|r| r.probability)
                    .fold(1.0, f64::min);
                r.probability = Some(crate::belief::rounded(least));
                // Why, in words: the first candidates that fail (what held
                // when), or that no candidate exists. Not as why-not
                // entries: those name literals of one window.
                let mut explained: Vec<String> = self
                    .failed
                    .iter()
                    .take(crate::ask::WHY_NOT_CANDIDATES)
                    .map(|(key, seen, why)| {
                        with_binding(key, format!("{} ({why})", seen.join(" and ")))
                    })
                    .collect();
                if self.failed.len() > crate::ask::WHY_NOT_CANDIDATES {
                    explained.push(format!(
                        "… and {} more candidates",
                        self.failed.len() - crate::ask::WHY_NOT_CANDIDATES
                    ));
                }
                explained.extend(self.none.clone());
                r.notes.splice(0..0, explained);
            }
            Outcome::Unknown => {
                r.reasons = self.unknown.clone();
                let mut sub: Vec<String> = self
                    .views
                    .iter()
                    .flat_map(|v| v.results.iter())
                    .filter(|r| r.answer == Outcome::Unknown)
                    .flat_map(|r| r.reasons.iter().cloned())
                    .collect();
                sub.sort();
                sub.dedup();
                r.reasons.extend(sub);
            }
            Outcome::Invalid => {
                let mut reasons: Vec<String> = invalid
                    .iter()
                    .flat_map(|r| {
                        r.reasons.iter().map(move |s| {
                            format!(
                                "in {}: {s}",
                                Frames {
                                    first: r.first_frame,
                                    last: r.last_frame
                                }
                            )
                        })
                    })
                    .collect();
                reasons.dedup();
                reasons.truncate(crate::ask::WHY_NOT_CANDIDATES);
                r.reasons = reasons;
                if let Some(first) = invalid.first() {
                    r.diagnostics = first.diagnostics.clone();
                    r.too_large = first.too_large;
                }
            }
        }
        let headline = headline(&r);
        TemporalAnswer {
            form: t.form,
            keyword: t.keyword.clone(),
            parts: t.parts.iter().map(|p| p.text.clone()).collect(),
            windows,
            holds: self.holds,
            headline,
            result: r,
        }
    }
}

/// The one line that answers a temporal question, from its answer
/// spanning the video (so that every front end says the same): a yes
/// names the first bindings and their times, a no why it fails, an
/// unknown or invalid answer its first reason.
pub fn headline(r: &AskResult) -> String {
    let head = r.answer.as_str();
    let first = match r.answer {
        Outcome::Yes => {
            let said: Vec<&str> = r
                .notes
                .iter()
                .take(r.count.min(HEADLINE_BINDINGS))
                .map(String::as_str)
                .collect();
            let more = r.count.saturating_sub(HEADLINE_BINDINGS);
            let more = if more > 0 {
                format!("; and {more} more")
            } else {
                String::new()
            };
            return format!("{head} — {}{more}", said.join("; "));
        }
        Outcome::No => r.notes.first(),
        Outcome::Unknown | Outcome::Invalid => r.reasons.first(),
    };
    match first {
        Some(why) => format!("{head} — {why}"),
        None => head.to_string(),
    }
}

/// The windows a temporal query asked at window `at` looks at: every
/// window up to and including `at` (the video's past seen from there), or
/// all of them.
pub fn up_to<'a>(kbs: &'a [WindowKb], at: Option<&str>) -> Option<Vec<&'a WindowKb>> {
    match at {
        None => Some(kbs.iter().collect()),
        Some(id) => {
            let end = kbs.iter().position(|k| k.id == id)?;
            Some(kbs[..=end].iter().collect())
        }
    }
}

/// A temporal answer as one object, as `ask --json` prints it and
/// [`crate::pipeline::Pipeline::ask_json`] returns it: `"results"`, the
/// one result object spanning the video ([`TemporalAnswer::result_object`]),
/// and `"summary"`, the summary object of that result with the claim's
/// headline.
pub fn ask_object(
    words: &crate::context::Sentences,
    p: &Prepared,
    a: &TemporalAnswer,
) -> Result<serde_json::Value, serde_json::Error> {
    Ok(serde_json::json!({
        "results": [a.result_object(p)?],
        "summary": a.summary_object(words, p),
    }))
}

impl TemporalAnswer {
    /// The summary object `ask --json` prints last: the summary of the
    /// one result, its headline the claim's ([`headline`]).
    pub fn summary_object(
        &self,
        words: &crate::context::Sentences,
        p: &Prepared,
    ) -> serde_json::Value {
        let summary = crate::engine::Summary::new(words, p, std::slice::from_ref(&self.result));
        let mut s = crate::json::summary_object(&summary, p);
        if let Some(o) = s.as_object_mut() {
            o.insert("headline".into(), serde_json::json!(self.headline));
        }
        s
    }

    /// The answer as the JSON result object of `ask --json` (the
    /// [`AskResult`]'s fields, `"question"` when there is one, and
    /// `"temporal"`: the form, parts, windows and timelines).
    pub fn result_object(&self, p: &Prepared) -> Result<serde_json::Value, serde_json::Error> {
        let mut v = crate::json::answer_object(&self.result, p, None)?;
        if let Some(o) = v.as_object_mut() {
            o.insert("temporal".into(), serde_json::to_value(self)?);
        }
        Ok(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kb::{Observability, test_window};

    fn engine() -> Engine {
        Engine::new(LogicPad::builtin(), Observability::everything()).expect("engine")
    }

    /// A window `id` over `first..=last` with these facts.
    fn window(e: &Engine, id: &str, first: u32, last: u32, facts: &[(&str, &[&str])]) -> WindowKb {
        let mut kb = test_window(e.pad().program(), facts);
        kb.id = id.to_string();
        kb.first_frame = first;
        kb.last_frame = last;
        kb
    }

    const SLOWING: &[(&str, &[&str])] = &[
        ("Vehicles", &["car_1"]),
        ("Moving", &["car_1"]),
        ("SpeedDown", &["car_1"]),
    ];
    const STANDING: &[(&str, &[&str])] = &[("Vehicles", &["car_1"])];
    const CRUISING: &[(&str, &[&str])] = &[("Vehicles", &["car_1"]), ("Moving", &["car_1"])];

    fn ask(e: &Engine, text: &str, kbs: &[WindowKb]) -> TemporalAnswer {
        let p = e.prepare_query(text);
        let t = p
            .temporal
            .clone()
            .unwrap_or_else(|| panic!("{text} is temporal: {:?}", p.parsed.err()));
        let refs: Vec<&WindowKb> = kbs.iter().collect();
        answer(e, "video", &t, text, &refs, AskOptions::default())
    }

    #[test]
    fn then_holds_in_order_only() {
        let e = engine();
        let kbs = [
            window(&e, "w0", 0, 9, CRUISING),
            window(&e, "w1", 10, 19, SLOWING),
            window(&e, "w2", 20, 29, STANDING),
        ];
        let a = ask(&e, "(Decelerate(x)) THEN (Stopped(x))", &kbs);
        assert_eq!(a.result.answer, Outcome::Yes, "{a:?}");
        assert_eq!(
            a.result.bindings,
            vec![vec![("x".to_string(), "car_1".to_string())]]
        );
        assert_eq!(
            a.headline,
            "yes — x = car_1: `Decelerate(x)` in frames 10–19, then `Stopped(x)` in frames 20–29"
        );
        assert_eq!(a.result.window, "video");
        assert_eq!((a.result.first_frame, a.result.last_frame), (0, 29));
        assert_eq!(a.result.probability, Some(1.0));
        // The proof is both parts' proofs, in their windows.
        let facts: Vec<&str> = a.result.proofs[0].iter().map(|n| n.fact.as_str()).collect();
        assert_eq!(facts, ["Decelerate(car_1)", "Stopped(car_1)"]);
        // BEFORE is THEN; AFTER swaps the parts.
        let b = ask(&e, "(Decelerate(x)) before (Stopped(x))", &kbs);
        assert_eq!(b.result.answer, Outcome::Yes);
        let c = ask(&e, "(Stopped(x)) AFTER (Decelerate(x))", &kbs);
        assert_eq!(c.result.answer, Outcome::Yes);
        assert_eq!(c.parts, ["Decelerate(x)", "Stopped(x)"]);
        // The reverse order is no, saying what was seen.
        let r = ask(&e, "(Stopped(x)) THEN (Decelerate(x))", &kbs);
        assert_eq!(r.result.answer, Outcome::No, "{r:?}");
        assert!(r.headline.contains("never in that order"), "{}", r.headline);
        assert!(r.result.why_not.is_empty());
        assert!(r.result.notes[0].starts_with("x = car_1: `Stopped(x)` in frames 20–29"));
        let r = ask(&e, "(Decelerate(x)) AFTER (Stopped(x))", &kbs);
        assert_eq!(r.result.answer, Outcome::No);
    }

    #[test]
    fn then_needs_the_same_object_on_both_sides() {
        let e = engine();
        let kbs = [
            window(
                &e,
                "w0",
                0,
                9,
                &[
                    ("Vehicles", &["car_1"]),
                    ("Moving", &["car_1"]),
                    ("SpeedDown", &["car_1"]),
                ],
            ),
            window(
                &e,
                "w1",
                10,
                19,
                &[
                    ("Vehicles", &["car_1"]),
                    ("Moving", &["car_1"]),
                    ("Vehicles", &["car_2"]),
                ],
            ),
        ];
        // car_1 slows, car_2 stands: not the same car.
        let a = ask(&e, "(Decelerate(x)) THEN (Stopped(x))", &kbs);
        assert_eq!(a.result.answer, Outcome::No, "{a:?}");
        // Different variables are different objects, each existential.
        let a = ask(&e, "(Decelerate(x)) THEN (Stopped(y))", &kbs);
        assert_eq!(a.result.answer, Outcome::Yes, "{a:?}");
        assert!(a.result.variables.is_empty());
        assert_eq!(a.result.bindings, vec![Vec::<(String, String)>::new()]);
    }

    #[test]
    fn one_window_cannot_order_what_it_sees() {
        let e = engine();
        let both: &[(&str, &[&str])] = &[("Vehicles", &["car_1"]), ("SpeedDown", &["car_1"])];
        let kbs = [
            window(&e, "w0", 0, 9, CRUISING),
            window(&e, "w1", 10, 19, both),
        ];
        // Decelerate and Stopped both hold in frames 10–19 only.
        for q in [
            "(Decelerate(x)) THEN (Stopped(x))",
            "(Stopped(x)) THEN (Decelerate(x))",
        ] {
            let a = ask(&e, q, &kbs);
            assert_eq!(a.result.answer, Outcome::Unknown, "{q}: {a:?}");
            assert!(
                a.headline
                    .contains("one window cannot tell which came first"),
                "{}",
                a.headline
            );
        }
        // Seen in order elsewhere, the overlap does not make the opposite
        // order unknown.
        let kbs = [
            window(&e, "w0", 0, 9, SLOWING),
            window(&e, "w1", 10, 19, both),
            window(&e, "w2", 20, 29, STANDING),
        ];
        let a = ask(&e, "(Stopped(x)) THEN (Decelerate(x))", &kbs);
        assert_eq!(a.result.answer, Outcome::No, "{a:?}");
        assert!(a.headline.contains("opposite order"), "{}", a.headline);
        assert_eq!(
            ask(&e, "(Decelerate(x)) THEN (Stopped(x))", &kbs)
                .result
                .answer,
            Outcome::Yes
        );
    }

    #[test]
    fn overlapping_windows_order_only_what_they_separate() {
        let e = engine();
        // Stride 5 over windows of 10: slowing seen in 0–9 and 5–14,
        // standing in 10–19 and 15–24.
        let kbs = [
            window(&e, "w0", 0, 9, SLOWING),
            window(&e, "w1", 5, 14, SLOWING),
            window(&e, "w2", 10, 19, STANDING),
            window(&e, "w3", 15, 24, STANDING),
        ];
        let a = ask(&e, "(Decelerate(x)) THEN (Stopped(x))", &kbs);
        assert_eq!(a.result.answer, Outcome::Yes, "{a:?}");
        assert_eq!(
            a.headline,
            "yes — x = car_1: `Decelerate(x)` in frames 0–9, then `Stopped(x)` in frames 10–19"
        );
        assert_eq!(
            a.holds[0].parts[0].frames,
            [Frames { first: 0, last: 14 }],
            "overlapping windows merge"
        );
        assert_eq!(
            ask(&e, "(Stopped(x)) THEN (Decelerate(x))", &kbs)
                .result
                .answer,
            Outcome::No
        );
        // Only overlapping windows between them: not proven.
        let kbs = [
            window(&e, "w0", 0, 9, SLOWING),
            window(&e, "w1", 5, 14, STANDING),
        ];
        assert_eq!(
            ask(&e, "(Decelerate(x)) THEN (Stopped(x))", &kbs)
                .result
                .answer,
            Outcome::Unknown
        );
    }

    #[test]
    fn a_part_already_going_on_is_not_after() {
        let e = engine();
        // car_2 stands in every window; car_1 slows down in 10–19 only.
        let standing: &[(&str, &[&str])] = &[("Vehicles", &["car_2"])];
        let slowing: &[(&str, &[&str])] = &[
            ("Vehicles", &["car_2"]),
            ("Vehicles", &["car_1"]),
            ("Moving", &["car_1"]),
            ("SpeedDown", &["car_1"]),
        ];
        let kbs = [
            window(&e, "w0", 0, 9, standing),
            window(&e, "w1", 10, 19, slowing),
            window(&e, "w2", 20, 29, standing),
        ];
        // A window of slowing (10–19) ends before a window of standing
        // (20–29) starts, but car_2 had stood since frame 0: "did a car
        // slow down before the other stopped?" is no.
        let a = ask(&e, "(Decelerate(y)) THEN (Stopped(x))", &kbs);
        assert_eq!(a.result.answer, Outcome::No, "{a:?}");
        assert!(a.headline.contains("already going on"), "{}", a.headline);
        // The slowing car's own standing after it began later: yes.
        let kbs = [
            window(&e, "w0", 0, 9, CRUISING),
            window(&e, "w1", 10, 19, SLOWING),
            window(&e, "w2", 20, 29, STANDING),
        ];
        let a = ask(&e, "(Decelerate(x)) THEN (Stopped(x))", &kbs);
        assert_eq!(a.result.answer, Outcome::Yes, "{a:?}");
    }

    #[test]
    fn chains_order_every_step() {
        let e = engine();
        let kbs = [
            window(&e, "w0", 0, 9, CRUISING),
            window(&e, "w1", 10, 19, SLOWING),
            window(&e, "w2", 20, 29, STANDING),
        ];
        let q = "(Move(x)) THEN (Decelerate(x)) THEN (Stopped(x))";
        let a = ask(&e, q, &kbs);
        assert_eq!(a.result.answer, Outcome::Yes, "{a:?}");
        assert_eq!(a.holds[0].parts.len(), 3);
        let q = "(Decelerate(x)) THEN (Move(x)) THEN (Stopped(x))";
        // Move holds in 10–19 too (Moving), so the middle step has no
        // window after 10–19 and before 20–29.
        assert_ne!(ask(&e, q, &kbs).result.answer, Outcome::Yes);
    }

    #[test]
    fn ever_throughout_and_still() {
        let e = engine();
        let kbs = [
            window(&e, "w0", 0, 9, CRUISING),
            window(&e, "w1", 10, 19, SLOWING),
            window(&e, "w2", 20, 29, STANDING),
            window(
                &e,
                "w3",
                30,
                39,
                &[
                    ("Vehicles", &["car_1"]),
                    ("Vehicles", &["car_2"]),
                    ("Moving", &["car_2"]),
                ],
            ),
        ];
        let a = ask(&e, "EVER: Stopped(x)", &kbs);
        assert_eq!(a.result.answer, Outcome::Yes);
        assert_eq!(a.headline, "yes — x = car_1: `Stopped(x)` in frames 20–39");
        assert_eq!(
            ask(&e, "ever: Pedestrian(x)", &kbs).result.answer,
            Outcome::No
        );
        // car_1 is a vehicle in every window it is seen; car_2 too.
        let a = ask(&e, "THROUGHOUT: Vehicles(x)", &kbs);
        assert_eq!(a.result.answer, Outcome::Yes);
        assert_eq!(a.result.count, 2);
        // car_1 does not move in 20–39; car_2 moves in the one window it
        // is seen in.
        let a = ask(&e, "THROUGHOUT: Moving(x)", &kbs);
        assert_eq!(
            a.result.bindings,
            vec![vec![("x".to_string(), "car_2".to_string())]]
        );
        assert_eq!(
            ask(&e, "THROUGHOUT: Moving(car_1)", &kbs).result.answer,
            Outcome::No
        );
        // Still: car_1 stands from 20–29 to the end.
        let a = ask(&e, "STILL: Stopped(x)", &kbs);
        assert_eq!(a.result.answer, Outcome::Yes, "{a:?}");
        assert_eq!(
            a.headline,
            "yes — x = car_1: `Stopped(x)` since frames 20–29, through the last window (frames 30–39)"
        );
        // Moving: car_2 still moves; car_1 moved, then stopped.
        let a = ask(&e, "STILL: Moving(car_1)", &kbs);
        assert_eq!(a.result.answer, Outcome::No);
        assert!(
            a.headline.contains("not in the last window"),
            "{}",
            a.headline
        );
    }

    #[test]
    fn a_window_that_cannot_tell_makes_no_unknown() {
        // The source cannot observe motion at all.
        let e = engine().for_source(Observability::everything().without(
            &["SpeedDown", "SpeedUp", "Moving"],
            "no motion in this source",
        ));
        let kbs = [
            window(&e, "w0", 0, 9, STANDING),
            window(&e, "w1", 10, 19, STANDING),
        ];
        for q in [
            "(Decelerate(x)) THEN (Stopped(x))",
            "EVER: Decelerate(x)",
            "THROUGHOUT: Decelerate(x)",
            "STILL: Decelerate(x)",
        ] {
            let a = ask(&e, q, &kbs);
            assert_eq!(a.result.answer, Outcome::Unknown, "{q}: {a:?}");
            assert!(
                a.result
                    .reasons
                    .iter()
                    .any(|r| r.contains("no motion in this source")),
                "{q}: {:?}",
                a.result.reasons
            );
        }
        // A claim that holds is yes whatever cannot be told elsewhere.
        assert_eq!(
            ask(&e, "EVER: Vehicles(x)", &kbs).result.answer,
            Outcome::Yes
        );
    }

    #[test]
    fn parse_errors_are_diagnostics_with_spans() {
        let e = engine();
        let err = |text: &str| -> Vec<Diagnostic> {
            match parse(e.pad(), text) {
                Some(Err(d)) => d,
                other => panic!("{text}: expected diagnostics, got {other:?}"),
            }
        };
        let d = err("(Decelerate(x)) THEN");
        assert_eq!(d[0].message, "expected a query after `THEN`");
        assert_eq!(d[0].snippet(), "THEN");
        let d = err("THEN (Stopped(x))");
        assert_eq!(d[0].message, "expected a query before `THEN`");
        let d = err("EVER:");
        assert_eq!(d[0].message, "expected a query after `EVER:`");
        // An unknown predicate in the second part points into it.
        let d = err("(Decelerate(x)) THEN (Levitates(x))");
        assert_eq!(d[0].snippet(), "Levitates");
        assert_eq!(d[0].column(), 23);
        let d = err("(Decelerate(x)) THEN (Stopped(x)) AFTER (Move(x))");
        assert!(d[0].message.contains("ambiguous"), "{}", d[0].message);
        let d = err("(EVER: Decelerate(x)) THEN (Stopped(x))");
        assert!(
            d[0].message.contains("cannot stand inside"),
            "{}",
            d[0].message
        );
        let d = err("THROUGHOUT: (Decelerate(x)) THEN (Stopped(x))");
        assert!(d[0].message.contains("do not nest"), "{}", d[0].message);
        let d = err("(∀x: Vehicles(x) → Moving(x)) THEN (Stopped(x))");
        assert!(d[0].message.contains("universal"), "{}", d[0].message);
        let d = err("(Decelerate(x) THEN Stopped(x)");
        assert!(
            d[0].message.contains("must stand between"),
            "{}",
            d[0].message
        );
        // Not temporal: left to the query parser.
        for q in [
            "Moving(x)",
            "Then(x)",
            "Moving(then)",
            "Vehicles(x) ^ ¬∃y: (Road(y) ^ On(x, y))",
        ] {
            assert!(parse(e.pad(), q).is_none(), "{q}");
        }
        // Well formed: whole-query parentheses, ∧ inside, any case.
        for q in [
            "((Decelerate(x)) THEN (Stopped(x)))",
            "(Vehicles(x) ∧ Decelerate(x)) then (Stopped(x))",
            "Decelerate(x) THEN Stopped(x)",
            "ever : Stopped(x)",
            "EVER: (Decelerate(x)) THEN (Stopped(x))",
        ] {
            assert!(matches!(parse(e.pad(), q), Some(Ok(_))), "{q}");
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 256, ..Default::default() })]

        /// Any text made of the forms' pieces is prepared without a panic:
        /// a query, or diagnostics whose spans lie in the text.
        #[test]
        fn any_arrangement_of_the_pieces_prepares(pieces in proptest::collection::vec(
            proptest::sample::select(vec![
                "(", ")", " THEN ", " then ", " AFTER ", " BEFORE ", "EVER:", "STILL :",
                "THROUGHOUT:", "Stopped(x)", "Decelerate(x)", " ^ ", "∧", "é", "¬∃y: ", ":", " ",
            ]),
            0..12,
        )) {
            static ENGINE: std::sync::OnceLock<Engine> = std::sync::OnceLock::new();
            let e = ENGINE.get_or_init(engine);
            let text: String = pieces.concat();
            let p = e.prepare_query(&text);
            if let Err(diags) = &p.parsed {
                for d in diags {
                    proptest::prop_assert!(d.span.end <= text.len(), "{text}: {d:?}");
                }
            }
            if p.temporal.is_some() {
                proptest::prop_assert!(p.parsed.is_ok());
            }
        }
    }

    #[test]
    fn a_window_alone_answers_a_temporal_query_invalid() {
        let e = engine();
        let kb = window(&e, "w0", 0, 9, SLOWING);
        let p = e.prepare_query("(Decelerate(x)) THEN (Stopped(x))");
        assert!(p.temporal.is_some());
        let r = e.ask(&kb, &p, AskOptions::default());
        assert_eq!(r.answer, Outcome::Invalid);
        assert!(
            r.reasons[0].contains("one window alone cannot answer it"),
            "{:?}",
            r.reasons
        );
        assert_eq!(r.query, "(Decelerate(x)) THEN (Stopped(x))");
        // An invalid part makes the whole query invalid, with its span.
        let p = e.prepare_query("EVER: Levitates(x)");
        assert!(p.temporal.is_none());
        let Err(d) = &p.parsed else { panic!("invalid") };
        assert_eq!(d[0].snippet(), "Levitates");
        assert_eq!(
            e.ask(&kb, &p, AskOptions::default()).answer,
            Outcome::Invalid
        );
    }
}
