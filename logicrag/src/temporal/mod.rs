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
use logicpad::{DiagKind, ParsedQuery, SourceFile, Span};
use serde::Serialize;
use std::sync::Arc;

mod forms;
mod reading;
mod syntax;
#[cfg(test)]
mod tests;
mod views;

pub use reading::evaluate;
use syntax::diag;
pub use syntax::parse;

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
