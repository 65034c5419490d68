//! Each form's claim read from the parts' answers: `THEN` (and `BEFORE`,
//! `AFTER`), `EVER`, `THROUGHOUT` and `STILL`.

use super::Frames;
use super::reading::Evaluation;
use super::views::{
    Key, before, chain, chain_episodes, not_after, project, spans, spans_text, with_binding,
};
use crate::ask::Outcome;
use logicpad::ParsedQuery;
use std::collections::BTreeSet;

impl Evaluation<'_> {
    pub(super) fn then(&mut self, limit: usize) {
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

    pub(super) fn ever(&mut self) {
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

    /// Notes that `text` holds with `key` in `holding`, and that the
    /// windows `blind` cannot tell whether it holds there too.
    fn cannot_tell(&mut self, key: &Key, text: &str, holding: &[Frames], blind: &[usize]) {
        self.unknown.push(with_binding(
            key,
            format!(
                "`{text}` holds in {}, and {} cannot tell",
                spans_text(holding),
                spans_text(&spans(self.frames, blind))
            ),
        ));
    }

    /// Records that the claim fails for `key` (`why`), though `text` held
    /// with it in `holding`.
    fn fails(&mut self, key: Key, text: &str, holding: &[Frames], why: String) {
        self.failed.push((
            key,
            vec![format!("`{text}` in {}", spans_text(holding))],
            why,
        ));
    }

    pub(super) fn throughout(&mut self) {
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
                self.cannot_tell(&key, &text, &holding, &blind);
            } else {
                let why = format!(
                    "not in {}, though {} seen there",
                    spans_text(&spans(self.frames, &fails)),
                    match objects.as_slice() {
                        [] => "everything is".to_string(),
                        [one] => format!("{one} is"),
                        many => format!("{} are", many.join(" and ")),
                    }
                );
                self.fails(key, &text, &holding, why);
            }
        }
        if self.holds.is_empty() && self.unknown.is_empty() && !self.blind(0).is_empty() {
            self.unknown
                .push("no window proves it, and some windows cannot tell".into());
        }
    }

    pub(super) fn still(&mut self) {
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
                self.cannot_tell(&key, &text, &holding, &blind);
            } else {
                let why = if fails.contains(&last) {
                    format!("not in the last window ({})", self.frames[last])
                } else {
                    format!(
                        "it stopped holding in {}",
                        spans_text(&spans(self.frames, &fails))
                    )
                };
                self.fails(key, &text, &holding, why);
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
}
