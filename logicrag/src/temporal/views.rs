//! What the parts' answers say over the windows: literals as written,
//! bindings projected on the shared variables, frame spans, and chains of
//! windows in time order.

use super::{Frames, Part};
use crate::ask::{AskResult, Outcome};
use logicpad::ParsedQuery;
use std::collections::BTreeMap;

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
pub(super) fn distinct_literals(parts: &[Part]) -> Vec<String> {
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
pub(super) type Key = Vec<(String, String)>;

/// One part's answers over the windows, read for a claim.
pub(super) struct PartView<'a> {
    pub(super) part: &'a Part,
    pub(super) results: &'a [AskResult],
    /// Per window: the part's bindings projected on the claim's shared
    /// variables, each with the index of its first full binding.
    pub(super) keys: Vec<BTreeMap<Key, usize>>,
    /// The part's variables that the claim shares.
    pub(super) shared: Vec<String>,
    /// The part as said in an answer: without the literals every part of
    /// a `THEN` shares (`TypeOf(x, Car)` said once is enough), else as
    /// written.
    pub(super) short: String,
}

impl PartView<'_> {
    /// The windows (indices) where the part holds with `key` (its
    /// projection of a claim's binding).
    pub(super) fn windows_of(&self, key: &Key) -> Vec<usize> {
        (0..self.keys.len())
            .filter(|&w| self.keys[w].contains_key(key))
            .collect()
    }

    pub(super) fn outcome(&self, w: usize) -> Outcome {
        self.results.get(w).map_or(Outcome::Invalid, |r| r.answer)
    }

    /// The probability of the part holding with `key` in window `w`.
    pub(super) fn probability(&self, w: usize, key: &Key) -> f64 {
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
    pub(super) fn proof(&self, w: usize, key: &Key) -> Vec<crate::proof::ProofNode> {
        let (Some(r), Some(&i)) = (self.results.get(w), self.keys[w].get(key)) else {
            return Vec::new();
        };
        r.proofs.get(i).cloned().unwrap_or_default()
    }
}

/// The answer variables of a part, from its answers (or its query).
pub(super) fn variables_of(part: &Part, results: &[AskResult]) -> Vec<String> {
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

pub(super) fn project(binding: &[(String, String)], vars: &[String]) -> Key {
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

pub(super) fn with_binding(b: &[(String, String)], said: String) -> String {
    if b.is_empty() {
        said
    } else {
        format!("{}: {said}", binding_text(b))
    }
}

/// Windows' frames merged where they touch or overlap.
pub(super) fn spans(frames: &[Frames], windows: &[usize]) -> Vec<Frames> {
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

pub(super) fn spans_text(s: &[Frames]) -> String {
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
pub(super) fn chain(
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
pub(super) fn before(a: Frames, b: Frames) -> bool {
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
pub(super) fn chain_episodes(lists: &[Vec<usize>], frames: &[Frames]) -> Option<Vec<usize>> {
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
pub(super) fn not_after(a: Frames, b: Frames) -> bool {
    b.last >= a.first
}
