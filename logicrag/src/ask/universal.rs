//! Universal queries (`∀x: A → B`): answered by their counterexamples
//! (`A ∧ ¬B`), the answer's proof the absence of any.

use super::*;

/// Answers `∀x: A → B` under the closed world: "yes" when no object of the
/// window satisfies `A ∧ ¬B` (every binding of `A` then comes with the
/// proof of `B`), "no" with the counterexamples. Every predicate must be
/// fully observed: an object the source cannot see could break the rule,
/// and `¬B` on a partly observed `B` is a guess.
pub(super) fn ask_universal(
    pad: &LogicPad,
    kb: &WindowKb,
    blind: &Blindness<'_>,
    u: &logicpad::UniversalQuery,
    opts: AskOptions,
    mut result: AskResult,
) -> AskResult {
    let mut reasons: Vec<String> = u
        .counterexamples
        .disjuncts
        .iter()
        .flatten()
        .flat_map(Literal::atoms)
        .map(|(a, _)| a.pred.as_str())
        .filter_map(|p| {
            let s = blind.observed.get(p).copied().unwrap_or(Observed::Never);
            (s != Observed::Fully).then(|| blind_reason(pad, blind, p, s))
        })
        .collect();
    reasons.sort();
    reasons.dedup();
    if !reasons.is_empty() {
        result.answer = Outcome::Unknown;
        result.reasons = reasons;
        return result;
    }
    let (left, right) = (u.antecedent.clone(), u.consequent.clone());
    let limits = &opts.limits;
    let (counter, stopped) = match kb.model.bindings_limited(&u.counterexamples, limits) {
        Ok(c) => (c.items, c.stopped),
        Err(e) => {
            set_error(&mut result, &e);
            return result;
        }
    };
    // Counterexamples found before a limit still make it "no"; none found
    // before it decides nothing.
    if counter.is_empty()
        && let Some(reason) = stopped
    {
        result.answer = Outcome::Unknown;
        result.stopped = Some(reason);
        result.reasons = vec![super::stopped_reason(reason, limits, 0)];
        return result;
    }
    result.stopped = stopped;
    let (domain, domain_stopped) = kb
        .model
        .count_limited(&u.domain, limits)
        .unwrap_or((0, None));
    result.stopped = result.stopped.or(domain_stopped);
    let objects = |n: usize| format!("{n} object{}", if n == 1 { "" } else { "s" });
    if !counter.is_empty() {
        result.answer = Outcome::No;
        result.count = counter.len();
        result.notes.push(format!(
            "{} of the {} that satisfy {left} {} not satisfy {right}",
            counter.len(),
            objects(domain),
            if counter.len() == 1 { "does" } else { "do" }
        ));
        if opts.why_not {
            result.why_not = crate::whynot::universal(&left, &right, &counter);
        }
        return result;
    }
    result.answer = Outcome::Yes;
    if domain == 0 {
        result.notes.push(format!(
            "vacuously true: no object satisfies {left} in this window"
        ));
        return result;
    }
    result.notes.push(format!(
        "holds for every one of the {} that satisfy {left}",
        objects(domain)
    ));
    match answers_limited(kb, &u.witnesses, opts.proofs, limits) {
        Ok(found) => {
            let w = found.items;
            result.stopped = result.stopped.or(found.stopped);
            result.count = w.len();
            for a in &w {
                result.bindings.push(a.bindings.clone());
                if opts.proofs {
                    result.proofs.push(crate::proof::of_answer(kb, a));
                }
            }
        }
        Err(e) => {
            result.answer = Outcome::Invalid;
            set_error(&mut result, &e);
        }
    }
    result
}
