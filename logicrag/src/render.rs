//! Plain-text rendering of an [`AskResult`], shared by `logicrag ask` and
//! the REPL so that both show the same evidence in the same words.

use crate::ask::{AskResult, Outcome};

/// `" (2 answers)"` for a "yes" or "no" to a query with answer variables,
/// else empty: "how many …" is answered by the number of distinct bindings,
/// so a reader must see the count (0 included), not only "yes" or "no".
/// An answer that is not certain says how sure it is:
/// `" (2 answers; probability 0.93)"`, `" (probability 0.7)"`.
pub fn count_suffix(r: &AskResult) -> String {
    let count = match r.answer {
        Outcome::Yes | Outcome::No if !r.variables.is_empty() => Some(format!(
            "{}{} answer{}",
            if r.stopped.is_some() { "at least " } else { "" },
            r.count,
            if r.count == 1 { "" } else { "s" }
        )),
        _ => None,
    };
    let sure = r
        .probability
        .filter(|p| *p < 1.0)
        .map(|p| format!("probability {p}"));
    match (count, sure) {
        (Some(c), Some(s)) => format!(" ({c}; {s})"),
        (Some(x), None) | (None, Some(x)) => format!(" ({x})"),
        (None, None) => String::new(),
    }
}

/// Width diagnostics are drawn at in a terminal.
const DIAGNOSTIC_WIDTH: usize = 100;

/// The lines under an answer's headline: each binding with its proof for
/// "yes", the closest candidates and what they fail for "no", the reasons
/// for "unknown" and "invalid".
pub fn detail_lines(r: &AskResult) -> Vec<String> {
    detail_lines_page(r, 0, usize::MAX)
}

/// One answer: its bindings on a line, then its proof indented.
pub(crate) fn binding_lines(
    out: &mut Vec<String>,
    b: &[(String, String)],
    proof: Option<&[crate::proof::ProofNode]>,
) {
    let bind: Vec<String> = b.iter().map(|(v, c)| format!("{v} = {c}")).collect();
    out.push(if bind.is_empty() {
        "  (true)".to_string()
    } else {
        format!("  {}", bind.join(", "))
    });
    for line in proof.map(crate::proof::lines).into_iter().flatten() {
        out.push(format!("      {line}"));
    }
}

/// [`detail_lines`] with only bindings `skip..skip + take` of a "yes" (the
/// REPL shows answers a page at a time).
pub(crate) fn detail_lines_page(r: &AskResult, skip: usize, take: usize) -> Vec<String> {
    // What the answer rests on besides its bindings comes first: "car_3 is
    // not seen in frames 20–29", "holds for every one of the 2 objects …".
    let mut out: Vec<String> = r.notes.iter().map(|n| format!("  {n}")).collect();
    if skip == 0
        && matches!(r.answer, Outcome::Yes | Outcome::No)
        && let Some(why) = r.stopped
    {
        out.push(format!(
            "  the run stopped at its {why} limit: what it found before, in the order found"
        ));
    }
    match r.answer {
        Outcome::Yes => {
            // Proofs are absent when they were not asked for.
            let proofs = r.proofs.iter().map(Some).chain(std::iter::repeat(None));
            for (b, proof) in r.bindings.iter().zip(proofs).skip(skip).take(take) {
                binding_lines(&mut out, b, proof.map(Vec::as_slice));
            }
        }
        Outcome::No => {
            for w in &r.why_not {
                if let Some(sentence) = w.sentence() {
                    let sep = if w.candidate == crate::whynot::NO_CANDIDATE {
                        ":"
                    } else {
                        " ="
                    };
                    out.push(format!("  {}{sep} {sentence}", w.variable));
                }
            }
        }
        // An invalid query is shown with a caret under the fault.
        Outcome::Invalid if !r.diagnostics.is_empty() => {
            for d in &r.diagnostics {
                let text = d.diagnostic.render_plain(DIAGNOSTIC_WIDTH);
                out.extend(text.lines().map(|l| format!("  {l}")));
            }
        }
        Outcome::Unknown | Outcome::Invalid => {
            for reason in &r.reasons {
                out.extend(reason.lines().map(|l| format!("  {l}")));
            }
        }
    }
    // What the answer's probability rests on, once, under the first page.
    if skip == 0 {
        out.extend(r.hinges.iter().map(|h| format!("  {}", h.sentence())));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn result(answer: Outcome, bindings: &[&[(&str, &str)]]) -> AskResult {
        AskResult {
            window: "w".into(),
            first_frame: 0,
            last_frame: 9,
            notes: Vec::new(),
            stopped: None,
            probability: None,
            binding_probabilities: Vec::new(),
            hinges: Vec::new(),
            query: "Pedestrian(x)".into(),
            answer,
            variables: bindings
                .first()
                .map(|b| b.iter().map(|(v, _)| v.to_string()).collect())
                .unwrap_or_else(|| vec!["x".to_string()]),
            count: bindings.len(),
            bindings: bindings
                .iter()
                .map(|b| {
                    b.iter()
                        .map(|(v, c)| (v.to_string(), c.to_string()))
                        .collect()
                })
                .collect(),
            proofs: Vec::new(),
            why_not: Vec::new(),
            reasons: vec!["line one\nline two".into()],
            diagnostics: Vec::new(),
        }
    }

    #[test]
    fn a_yes_with_bindings_shows_its_count() {
        // Regression: "How many pedestrians are there?" printed only "YES".
        let r = result(Outcome::Yes, &[&[("x", "p1")], &[("x", "p2")]]);
        assert_eq!(count_suffix(&r), " (2 answers)");
        let mut unsure = r.clone();
        unsure.probability = Some(0.93);
        assert_eq!(count_suffix(&unsure), " (2 answers; probability 0.93)");
        unsure.probability = Some(1.0);
        assert_eq!(count_suffix(&unsure), " (2 answers)");
        assert_eq!(detail_lines(&r), ["  x = p1", "  x = p2"]);
        let one = result(Outcome::Yes, &[&[("x", "p1")]]);
        assert_eq!(count_suffix(&one), " (1 answer)");
        let ground = result(Outcome::Yes, &[&[]]);
        assert_eq!(count_suffix(&ground), "");
        assert_eq!(detail_lines(&ground), ["  (true)"]);
    }

    #[test]
    fn a_no_to_a_query_with_variables_says_none() {
        // "How many cars are moving?" with none: "NO (0 answers)".
        let r = result(Outcome::No, &[]);
        assert_eq!(count_suffix(&r), " (0 answers)");
    }

    #[test]
    fn multi_line_reasons_stay_indented() {
        let r = result(Outcome::Unknown, &[]);
        assert_eq!(count_suffix(&r), "");
        assert_eq!(detail_lines(&r), ["  line one", "  line two"]);
    }
}
