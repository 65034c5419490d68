//! Diagnostics: what the checker reports, with file, line, column and a caret.
//!
//! A [`Diagnostic`] owns an `Arc` of the [`SourceFile`] it points into, so it can
//! be rendered by miette long after the file was loaded.

use std::fmt;
use std::sync::{Arc, OnceLock};

/// Source lines longer than this many characters are not echoed whole in a
/// rendered diagnostic (see [`Diagnostic::render_plain`]).
pub const MAX_SNIPPET_LINE: usize = 240;

/// Characters shown either side of the caret in an excerpt of a long line.
pub const EXCERPT_CONTEXT: usize = 60;

/// `offset` clamped to `text` and moved back to a character boundary.
fn floor_char_boundary(text: &str, offset: usize) -> usize {
    let mut off = offset.min(text.len());
    while off > 0 && !text.is_char_boundary(off) {
        off -= 1;
    }
    off
}

/// A named piece of source text (a LogicPad file, or a query typed by a user).
///
/// Invariant: `text` is the exact text that every [`Span`] pointing into this
/// file was computed against, and `line_starts`, once built, indexes it.
#[derive(Clone)]
pub struct SourceFile {
    /// File name as given by the caller (a path, or e.g. `<query>`).
    pub name: String,
    /// The complete text.
    pub text: String,
    /// Byte offsets where lines start, counted as miette counts them
    /// (after `\n`, `\r\n` or a lone `\r`), built on the first render.
    /// Without it every rendered diagnostic rescanned the text from its
    /// start: quadratic in a file with thousands of findings (the
    /// fuzzer's 3,000-rule LogicPad took 7 s).
    line_starts: OnceLock<Vec<usize>>,
    /// 0 and the offset after each `\n`: the lines [`SourceFile::line_col`]
    /// counts, built on first use. Without it every line, column and
    /// excerpt searched the text from the offset back to the line start or
    /// the file start: a 4 MB query line with 60 diagnostics still took
    /// 10 s once excerpts were bounded (fuzzer, issue 13).
    newline_starts: OnceLock<Vec<usize>>,
}

impl fmt::Debug for SourceFile {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SourceFile")
            .field("name", &self.name)
            .field("text", &self.text)
            .finish()
    }
}

/// Files are equal by name and text; the line index is a cache.
impl PartialEq for SourceFile {
    fn eq(&self, other: &SourceFile) -> bool {
        self.name == other.name && self.text == other.text
    }
}

impl Eq for SourceFile {}

impl SourceFile {
    /// Wraps a name and a text into a shareable source.
    pub fn new(name: impl Into<String>, text: impl Into<String>) -> Arc<SourceFile> {
        Arc::new(SourceFile {
            name: name.into(),
            text: text.into(),
            line_starts: OnceLock::new(),
            newline_starts: OnceLock::new(),
        })
    }

    /// See the `newline_starts` field.
    fn newline_starts(&self) -> &[usize] {
        self.newline_starts.get_or_init(|| {
            std::iter::once(0)
                .chain(
                    self.text
                        .bytes()
                        .enumerate()
                        .filter(|&(_, b)| b == b'\n')
                        .map(|(i, _)| i + 1),
                )
                .collect()
        })
    }

    /// The start of the line (after the last `\n` before `offset`) holding
    /// byte `offset`, and its index (0-based).
    fn line_of(&self, offset: usize) -> (usize, usize) {
        let starts = self.newline_starts();
        let idx = starts.partition_point(|&s| s <= offset).saturating_sub(1);
        (idx, starts.get(idx).copied().unwrap_or(0))
    }

    /// The end of the line holding byte `offset`: the offset of the next
    /// `\n` at or after it, or the end of the text.
    fn line_end(&self, offset: usize) -> usize {
        let starts = self.newline_starts();
        let next = starts.partition_point(|&s| s <= offset);
        starts.get(next).map_or(self.text.len(), |s| s - 1)
    }

    /// See the `line_starts` field.
    fn line_starts(&self) -> &[usize] {
        self.line_starts.get_or_init(|| {
            let b = self.text.as_bytes();
            let mut starts = vec![0];
            for (i, &c) in b.iter().enumerate() {
                let ends_line = c == b'\n' || (c == b'\r' && b.get(i + 1) != Some(&b'\n'));
                if ends_line {
                    starts.push(i + 1);
                }
            }
            starts
        })
    }

    /// 1-based line and 1-based column (in characters) of a byte offset.
    /// Offsets past the end are clamped to the end; offsets inside a UTF-8
    /// sequence are moved back to the character start.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let off = floor_char_boundary(&self.text, offset);
        let (line, line_start) = self.line_of(off);
        let col = self
            .text
            .get(line_start..off)
            .map_or(0, |s| s.chars().count())
            + 1;
        (line + 1, col)
    }
}

/// A byte range `[start, end)` in a [`SourceFile`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, PartialOrd, Ord)]
pub struct Span {
    /// First byte.
    pub start: usize,
    /// One past the last byte (`end >= start`).
    pub end: usize,
}

impl Span {
    /// A span from `start` to `end` (swapped if given backwards).
    pub fn new(start: usize, end: usize) -> Span {
        if end < start {
            Span {
                start: end,
                end: start,
            }
        } else {
            Span { start, end }
        }
    }
    /// Moves the span by `base` bytes (used to map a formula's spans into its file).
    pub fn shifted(self, base: usize) -> Span {
        Span {
            start: self.start + base,
            end: self.end + base,
        }
    }
    /// The smallest span covering both.
    pub fn join(self, other: Span) -> Span {
        Span {
            start: self.start.min(other.start),
            end: self.end.max(other.end),
        }
    }
    /// Length in bytes.
    pub fn len(&self) -> usize {
        self.end - self.start
    }
    /// True when the span covers no byte.
    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }
}

/// How bad a diagnostic is. `Error`s remove the offending rule (or make
/// loading fail under `strict`); `Warning`s are informative.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    /// Something worth knowing; does not change the exit code of `lint`.
    Advice,
    /// Suspicious but accepted.
    Warning,
    /// The rule or declaration is left out.
    Error,
}

/// The kind of a diagnostic; its [`DiagKind::code`] is the stable miette code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum DiagKind {
    /// The file is not readable.
    Io,
    /// The YAML itself does not parse.
    YamlSyntax,
    /// The YAML parses but does not have the LogicPad shape.
    Structure,
    /// A FOL formula does not parse.
    FolSyntax,
    /// A formula parses but uses a construct LogicPad cannot evaluate.
    Unsupported,
    /// A predicate (or function) that nothing declares.
    UnknownPredicate,
    /// Wrong number of arguments.
    ArityMismatch,
    /// A constant outside a function's declared values.
    UndeclaredValue,
    /// A head variable, a negated variable or a `≠` variable no positive atom binds.
    UnsafeRule,
    /// Negation inside a recursive cycle: no stratification exists.
    NegationCycle,
    /// A rule whose body needs a predicate that nothing can produce.
    DeadRule,
    /// The same rule twice.
    DuplicateRule,
    /// `... ==> ¬P(x)`: not Horn, kept as an integrity constraint.
    NegatedHead,
    /// A predicate declared twice.
    DuplicateDeclaration,
    /// A rule head whose name matches neither its entry nor any declaration.
    HeadMismatch,
    /// A base predicate named `NotP` that encodes negation as a fact.
    NegationAsPredicate,
    /// A `role:` or `frames:` that is unknown or does not fit the predicate.
    BadRole,
}

impl DiagKind {
    /// Stable code, shown by miette and usable in tests.
    pub fn code(self) -> &'static str {
        match self {
            DiagKind::Io => "logicpad::io",
            DiagKind::YamlSyntax => "logicpad::yaml_syntax",
            DiagKind::Structure => "logicpad::structure",
            DiagKind::FolSyntax => "logicpad::fol_syntax",
            DiagKind::Unsupported => "logicpad::unsupported",
            DiagKind::UnknownPredicate => "logicpad::unknown_predicate",
            DiagKind::ArityMismatch => "logicpad::arity_mismatch",
            DiagKind::UndeclaredValue => "logicpad::undeclared_value",
            DiagKind::UnsafeRule => "logicpad::unsafe",
            DiagKind::NegationCycle => "logicpad::negation_cycle",
            DiagKind::DeadRule => "logicpad::dead_rule",
            DiagKind::DuplicateRule => "logicpad::duplicate_rule",
            DiagKind::NegatedHead => "logicpad::negated_head",
            DiagKind::DuplicateDeclaration => "logicpad::duplicate_declaration",
            DiagKind::HeadMismatch => "logicpad::head_mismatch",
            DiagKind::NegationAsPredicate => "logicpad::negation_as_predicate",
            DiagKind::BadRole => "logicpad::bad_role",
        }
    }
}

/// A secondary pointer into the same source, with its own text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Label {
    /// Where.
    pub span: Span,
    /// What to say there.
    pub text: String,
}

/// One finding of the loader, the checker or the query checker.
///
/// Invariant: `span` (and every label's span) lies within `source.text`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// The kind (stable code).
    pub kind: DiagKind,
    /// Error, warning or advice.
    pub severity: Severity,
    /// One-line message.
    pub message: String,
    /// The file the spans point into.
    pub source: Arc<SourceFile>,
    /// The offending text (the caret goes here).
    pub span: Span,
    /// Text printed under the caret.
    pub label: String,
    /// Extra pointers (e.g. the other rules of a negation cycle).
    pub related: Vec<Label>,
    /// How to fix it.
    pub help: Option<String>,
}

impl Diagnostic {
    /// A diagnostic with no label text, no related labels and no help.
    pub fn new(
        kind: DiagKind,
        severity: Severity,
        source: &Arc<SourceFile>,
        span: Span,
        message: impl Into<String>,
    ) -> Diagnostic {
        let len = source.text.len();
        let span = Span::new(span.start.min(len), span.end.min(len));
        Diagnostic {
            kind,
            severity,
            message: message.into(),
            source: Arc::clone(source),
            span,
            label: String::new(),
            related: Vec::new(),
            help: None,
        }
    }
    /// Sets the text under the caret.
    pub fn with_label(mut self, label: impl Into<String>) -> Diagnostic {
        self.label = label.into();
        self
    }
    /// Sets the help line.
    pub fn with_help(mut self, help: impl Into<String>) -> Diagnostic {
        self.help = Some(help.into());
        self
    }
    /// Adds a secondary label.
    pub fn with_related(mut self, span: Span, text: impl Into<String>) -> Diagnostic {
        let len = self.source.text.len();
        self.related.push(Label {
            span: Span::new(span.start.min(len), span.end.min(len)),
            text: text.into(),
        });
        self
    }
    /// 1-based line of the caret.
    pub fn line(&self) -> usize {
        self.source.line_col(self.span.start).0
    }
    /// 1-based column (characters) of the caret.
    pub fn column(&self) -> usize {
        self.source.line_col(self.span.start).1
    }
    /// True for [`Severity::Error`].
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
    /// The text under the caret.
    pub fn snippet(&self) -> &str {
        self.source
            .text
            .get(self.span.start..self.span.end)
            .unwrap_or("")
    }
    /// Renders with miette's graphical handler, without colour, at `width`
    /// columns; a diagnostic on a line longer than [`MAX_SNIPPET_LINE`]
    /// characters is rendered as an excerpt around the caret instead, since
    /// miette would echo the whole line (a 130 KB rule was printed whole).
    pub fn render_plain(&self, width: usize) -> String {
        if self.has_long_line() {
            return self.render_excerpt();
        }
        let handler =
            miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor())
                .with_width(width)
                .with_links(false);
        let mut out = String::new();
        if handler.render_report(&mut out, self).is_err() {
            out = format!("{}\n", self.summary());
        }
        out
    }
}

impl Diagnostic {
    /// True when a label points into a line longer than [`MAX_SNIPPET_LINE`]
    /// characters, which renderers show as an excerpt.
    pub fn has_long_line(&self) -> bool {
        let text = &self.source.text;
        std::iter::once(self.span)
            .chain(self.related.iter().map(|l| l.span))
            .any(|span| {
                let start = floor_char_boundary(text, span.start);
                let end = floor_char_boundary(text, span.end.max(span.start));
                let line_start = self.source.line_of(start).1;
                let line_end = self.source.line_end(end);
                // Counting stops past the limit: counting every character
                // of a megabyte line once per diagnostic was quadratic.
                text[line_start..line_end]
                    .chars()
                    .nth(MAX_SNIPPET_LINE)
                    .is_some()
            })
    }

    /// The summary line, then at most [`EXCERPT_CONTEXT`] characters either
    /// side of the caret with `…` where the line was cut, the label, and
    /// the help.
    fn render_excerpt(&self) -> String {
        let text = &self.source.text;
        let start = floor_char_boundary(text, self.span.start);
        let end = floor_char_boundary(text, self.span.end.max(self.span.start));
        let line_start = self.source.line_of(start).1;
        let line_end = self.source.line_end(start);
        // Only the characters shown are read, plus one to tell whether the
        // line was cut: collecting the whole line (megabytes) for every
        // diagnostic pointing into it took 30 s for a 4 MB query line with
        // 60 diagnostics (fuzzer, issue 13).
        let mut before: Vec<char> = text[line_start..start]
            .chars()
            .rev()
            .take(EXCERPT_CONTEXT + 1)
            .collect();
        let before_cut = before.len() > EXCERPT_CONTEXT;
        before.truncate(EXCERPT_CONTEXT);
        before.reverse();
        let first = |s: &str| -> (Vec<char>, bool) {
            let mut v: Vec<char> = s.chars().take(EXCERPT_CONTEXT + 1).collect();
            let cut = v.len() > EXCERPT_CONTEXT;
            v.truncate(EXCERPT_CONTEXT);
            (v, cut)
        };
        let (marked, marked_cut) = first(&text[start..end.min(line_end)]);
        let (after, after_cut) = first(&text[end.min(line_end)..line_end]);
        let mut shown = String::new();
        if before_cut {
            shown.push('…');
        }
        shown.extend(&before);
        let caret_col = shown.chars().count();
        shown.extend(&marked);
        if marked_cut {
            shown.push('…');
        }
        shown.extend(&after);
        if after_cut {
            shown.push('…');
        }
        let carets = "^".repeat(marked.len().max(1));
        let mut out = format!(
            "{}\n    | {shown}\n    | {}{carets}",
            self.summary(),
            " ".repeat(caret_col)
        );
        if !self.label.is_empty() {
            out.push(' ');
            out.push_str(&self.label);
        }
        out.push('\n');
        if let Some(help) = &self.help {
            out.push_str(&format!("  help: {help}\n"));
        }
        out
    }

    /// One line: `file:line:col: error[code]: message`.
    pub fn summary(&self) -> String {
        let (line, col) = self.source.line_col(self.span.start);
        let sev = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Advice => "advice",
        };
        format!(
            "{}:{}:{}: {}[{}]: {}",
            self.source.name,
            line,
            col,
            sev,
            self.kind.code(),
            self.message
        )
    }
}

/// Displays the message only (miette adds the location); see [`Diagnostic::summary`].
impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Diagnostic {}

impl miette::Diagnostic for Diagnostic {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        Some(Box::new(self.kind.code()))
    }
    fn severity(&self) -> Option<miette::Severity> {
        Some(match self.severity {
            Severity::Error => miette::Severity::Error,
            Severity::Warning => miette::Severity::Warning,
            Severity::Advice => miette::Severity::Advice,
        })
    }
    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.help
            .as_ref()
            .map(|h| Box::new(h) as Box<dyn fmt::Display + 'a>)
    }
    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        // A file that could not be read has no text to point into.
        if self.source.text.is_empty() {
            None
        } else {
            Some(self)
        }
    }
    fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
        if self.source.text.is_empty() {
            return None;
        }
        let label = if self.label.is_empty() {
            None
        } else {
            Some(self.label.clone())
        };
        let primary =
            miette::LabeledSpan::new_primary_with_span(label, (self.span.start, self.span.len()));
        let rest = self.related.iter().map(|l| {
            miette::LabeledSpan::new_with_span(Some(l.text.clone()), (l.span.start, l.span.len()))
        });
        Some(Box::new(std::iter::once(primary).chain(rest)))
    }
}

impl miette::SourceCode for Diagnostic {
    /// miette's own `read_span` walks the text from its first byte; this
    /// hands it only the lines from `context_lines_before` above the span
    /// to the end of the text, found in the source's line index, and puts
    /// the lines and bytes skipped back into the answer, so the result is
    /// the same at a cost that no longer grows with the span's offset.
    fn read_span<'a>(
        &'a self,
        span: &miette::SourceSpan,
        context_lines_before: usize,
        context_lines_after: usize,
    ) -> Result<Box<dyn miette::SpanContents<'a> + 'a>, miette::MietteError> {
        let text = &self.source.text;
        let starts = self.source.line_starts();
        // The line holding the span's first byte, then `before` lines up.
        let line = starts
            .partition_point(|&s| s <= span.offset())
            .saturating_sub(1);
        let first = line.saturating_sub(context_lines_before);
        let line_start = starts.get(first).copied().unwrap_or(0).min(text.len());
        // One byte earlier (the previous line's terminator, ASCII) when
        // there is one: miette looks one byte behind a span's end, so an
        // empty span at a line start needs it. It counts as one line more.
        let (base, shift) = match line_start.checked_sub(1) {
            Some(b) => (b, 1),
            None => (0, 0),
        };
        let window = text.get(base..).unwrap_or("");
        let Some(offset) = span.offset().checked_sub(base) else {
            return Err(miette::MietteError::OutOfBounds);
        };
        let local = miette::SourceSpan::new(offset.into(), span.len());
        let inner = window.read_span(&local, context_lines_before, context_lines_after)?;
        Ok(Box::new(miette::MietteSpanContents::new_named(
            self.source.name.clone(),
            inner.data(),
            miette::SourceSpan::new((inner.span().offset() + base).into(), inner.span().len()),
            (inner.line() + first).saturating_sub(shift),
            inner.column(),
            (inner.line_count() + first).saturating_sub(shift),
        )))
    }
}

/// Did-you-mean: the closest of `candidates` to `name`, if it is close enough
/// (same name ignoring case, or an edit distance small for the length).
pub fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let lower: Vec<char> = name.chars().flat_map(char::to_lowercase).collect();
    let name_chars = name.chars().count();
    let name_ascii = name.is_ascii();
    let mut c_lower: Vec<char> = Vec::new();
    let mut best: Option<(usize, &'a str)> = None;
    for c in candidates {
        if c == name {
            continue;
        }
        let c_chars = if c.is_ascii() {
            c.len()
        } else {
            c.chars().count()
        };
        let allowed = (name_chars.max(c_chars) / 4).clamp(1, 3);
        // ASCII lowercasing keeps the length: most candidates are ruled out
        // here, before any lowercasing (a LogicPad of thousands of
        // misspelt names meets every candidate once per name).
        if name_ascii && c.is_ascii() && name.len().abs_diff(c.len()) > allowed {
            continue;
        }
        c_lower.clear();
        c_lower.extend(c.chars().flat_map(char::to_lowercase));
        // The edit distance is at least the difference in length, so a
        // candidate that differs by more than `allowed` characters is not
        // compared character by character: a megabyte-long name in a query
        // took seconds against the schema's predicates (fuzzer, issue 13).
        if lower.len().abs_diff(c_lower.len()) > allowed {
            continue;
        }
        if let Some(d) = bounded_levenshtein(&lower, &c_lower, allowed)
            && best.is_none_or(|(bd, bc)| (d, c) < (bd, bc))
        {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

/// The Levenshtein distance of `a` and `b` if it is at most `k`, else
/// `None`. Only the diagonal band of width `2k + 1` can hold a distance
/// ≤ `k`, and a row whose band is all above `k` ends the search: a LogicPad
/// of thousands of misspelt names compares every name with every
/// candidate, and the full table (with an allocation per pair) made that
/// take seconds.
fn bounded_levenshtein(a: &[char], b: &[char], k: usize) -> Option<usize> {
    if a.len().abs_diff(b.len()) > k {
        return None;
    }
    const FAR: usize = usize::MAX / 2;
    // prev[j] / cur[j]: distance between a[..i] and b[..j].
    let mut prev: Vec<usize> = (0..=b.len())
        .map(|j| if j <= k { j } else { FAR })
        .collect();
    let mut cur = vec![FAR; b.len() + 1];
    for i in 1..=a.len() {
        let lo = i.saturating_sub(k).max(1);
        let hi = (i + k).min(b.len());
        cur.fill(FAR);
        cur[0] = if i <= k { i } else { FAR };
        let mut row_min = cur[0];
        for j in lo..=hi {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let v = (prev[j - 1] + cost).min(prev[j] + 1).min(cur[j - 1] + 1);
            cur[j] = v;
            row_min = row_min.min(v);
        }
        if row_min > k {
            return None;
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    let d = prev[b.len()];
    (d <= k).then_some(d)
}

#[cfg(test)]
mod tests;
