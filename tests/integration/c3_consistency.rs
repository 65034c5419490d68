//! An answer and the C3 sentences of the same window never contradict
//! (issue 31, item 7). C3 says each mover's motion in one phrase ("does
//! not move", "moves at a constant speed", "speeds up", "slows down"); the
//! same window's answer to the everyday question about that object must
//! agree, for every object of every window of every built-in scenario, and
//! the synonyms must agree with each other ("walk at a steady pace" and
//! "move at a constant speed" of one pedestrian).
use logicrag::ask::AskOptions;
use logicrag::pipeline::{OpenOptions, Pipeline};

/// The yes/no answer of `question` on `window`.
fn answer(p: &Pipeline, question: &str, window: &str) -> String {
    let prepared = p
        .prepare(question)
        .unwrap_or_else(|e| panic!("{question:?} translates: {e}"));
    let asked = p
        .ask(&prepared, Some(window), AskOptions::default())
        .expect("the window exists");
    asked[0].result.answer.as_str().to_string()
}

#[test]
fn answers_and_c3_sentences_agree_in_every_scenario() {
    let (options, _) = OpenOptions::default()
        .prepared()
        .expect("the built-in LogicPad");
    let mut checked = 0;
    let mut contradictions = Vec::new();
    for name in perception::sim::BUILTIN_NAMES {
        let p = Pipeline::open(
            format!("sim:{name}").parse().expect("a source"),
            &options,
            &mut |_| {},
        )
        .expect("scenario opens");
        let kbs = p.kbs().expect("windows reason");
        for kb in kbs {
            let c3 = p
                .contexts(
                    &p.prepare("Is there a car?").expect("translates"),
                    Some(&kb.id),
                )
                .expect("context")
                .remove(0)
                .c3;
            for sentence in &c3 {
                // "car_4 is a red car that … does not move …."
                let Some((obj, rest)) = sentence.split_once(" is ") else {
                    continue;
                };
                if obj.contains(' ') || !rest.contains(" that ") {
                    continue;
                }
                let claims: &[(&str, &str, &str)] = &[
                    ("does not move", "Is {o} moving?", "no"),
                    ("does not move", "Is {o} stopped?", "yes"),
                    (
                        "moves at a constant speed",
                        "Does {o} move at a constant speed?",
                        "yes",
                    ),
                    ("moves at a constant speed", "Is {o} moving?", "yes"),
                    ("speeds up", "Does {o} speed up?", "yes"),
                    ("slows down", "Does {o} slow down?", "yes"),
                ];
                for (phrase, question, expected) in claims {
                    if !rest.contains(phrase) {
                        continue;
                    }
                    let q = question.replace("{o}", obj);
                    let got = answer(&p, &q, &kb.id);
                    checked += 1;
                    if got != *expected {
                        contradictions.push(format!(
                            "[{}] C3 says {sentence:?} but {q:?} answers {got}",
                            kb.id
                        ));
                    }
                }
                if obj.starts_with("pedestrian_") {
                    let a = answer(&p, &format!("Does {obj} walk at a steady pace?"), &kb.id);
                    let b = answer(&p, &format!("Does {obj} move at a constant speed?"), &kb.id);
                    checked += 1;
                    if a != b {
                        contradictions.push(format!(
                            "[{}] {obj}: 'walk at a steady pace' answers {a}, 'move at a constant speed' {b}",
                            kb.id
                        ));
                    }
                }
            }
        }
    }
    assert!(checked > 100, "only {checked} claims checked");
    assert!(
        contradictions.is_empty(),
        "{} contradictions:\n{}",
        contradictions.len(),
        contradictions.join("\n")
    );
}
