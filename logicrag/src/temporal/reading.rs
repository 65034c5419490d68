//! Reading a temporal claim from every window's answer to each part
//! ([`evaluate`]): the working state, the shared bindings, and the answer
//! spanning the video.

use super::views::{Key, PartView, distinct_literals, project, spans, variables_of, with_binding};
use super::{
    Form, Frames, NOTE_TIMELINES, PartTimes, TemporalAnswer, TemporalQuery, Timeline, headline,
};
use crate::ask::{AskOptions, AskResult, Outcome};
use crate::kb::WindowKb;
use std::collections::{BTreeMap, BTreeSet};

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
        Form::Then => e.then(opts.limits.answers),
        Form::Ever => e.ever(),
        Form::Throughout => e.throughout(),
        Form::Still => e.still(),
    }
    e.finish(label, t, query, &shared, opts)
}

/// The working state of [`evaluate`].
pub(super) struct Evaluation<'a> {
    pub(super) frames: &'a [Frames],
    pub(super) kbs: &'a [&'a WindowKb],
    pub(super) views: &'a [PartView<'a>],
    /// Bindings for which the claim holds.
    pub(super) holds: Vec<Timeline>,
    /// Their proofs (the parts' proofs in their witness windows).
    pub(super) proofs: Vec<Vec<crate::proof::ProofNode>>,
    /// Their probabilities.
    pub(super) probabilities: Vec<f64>,
    /// Why the claim cannot be told for a binding or at all.
    pub(super) unknown: Vec<String>,
    /// Candidates for which it fails: what held when, and why it fails.
    pub(super) failed: Vec<(Key, Vec<String>, String)>,
    /// What else the answer rests on.
    pub(super) notes: Vec<String>,
    /// Why a "no" has no candidate at all (no binding that any part
    /// holds with), in words.
    pub(super) none: Option<String>,
}

impl Evaluation<'_> {
    /// Every key of part `i` over all windows.
    pub(super) fn keys_of(&self, i: usize) -> BTreeSet<Key> {
        self.views[i]
            .keys
            .iter()
            .flat_map(|m| m.keys().cloned())
            .collect()
    }

    /// The claim's bindings that every part can have: the parts' keys
    /// joined on the variables they share (at most `limit`).
    pub(super) fn candidates(&self, limit: usize) -> (Vec<Key>, bool) {
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

    pub(super) fn part_times(&self, i: usize, key: &Key, witness: Option<usize>) -> PartTimes {
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
    pub(super) fn hold(&mut self, key: Key, witness: &[usize], said: String) {
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
    pub(super) fn blind(&self, i: usize) -> Vec<usize> {
        (0..self.frames.len())
            .filter(|&w| {
                matches!(
                    self.views[i].outcome(w),
                    Outcome::Unknown | Outcome::Invalid
                )
            })
            .collect()
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
        let mut r = AskResult::blank(
            label.to_string(),
            self.frames.iter().map(|f| f.first).min().unwrap_or(0),
            self.frames.iter().map(|f| f.last).max().unwrap_or(0),
            query,
        );
        r.answer = answer;
        r.variables = shared.to_vec();
        r.count = self.holds.len();
        r.bindings = self.holds.iter().map(|h| h.binding.clone()).collect();
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
                    r.stopped = first.stopped;
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
