//! Retrieval context for a multimodal model, in the two forms the paper
//! evaluates: **C2**, the inference result (answer, bindings, proof as short
//! sentences), and **C3**, the window's facts as template sentences
//! ("car_3 is a white car that starts on the left and moves at a constant
//! speed").

use crate::ask::{AskResult, Outcome};
use crate::kb::WindowKb;
use crate::proof::{ProofNode, Step, describe_provenance};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

/// Both context forms for one question on one window.
#[derive(Debug, Clone, Serialize)]
pub struct RagContext {
    /// Window id.
    pub window: String,
    /// The question, when one was asked in English.
    pub question: Option<String>,
    /// The query that was run.
    pub query: String,
    /// C2: the inference result as sentences.
    pub c2: Vec<String>,
    /// C3: one sentence per object, then one per relation.
    pub c3: Vec<String>,
}

impl RagContext {
    /// Builds the context from an answer and its window, in the words of
    /// the LogicPad the answer was reasoned with (`Engine::words`; there is
    /// no default, so a custom LogicPad's wording is never replaced by the
    /// built-in one unnoticed).
    pub fn new(
        kb: &WindowKb,
        question: Option<&str>,
        result: &AskResult,
        words: &Sentences,
    ) -> RagContext {
        RagContext {
            window: kb.id.clone(),
            question: question.map(str::to_string),
            query: result.query.clone(),
            c2: inference_sentences(result),
            c3: fact_sentences_with(kb, words),
        }
    }

    /// The prompt text an LMM would receive.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        s.push_str(&format!("Window {}.\n", self.window));
        if let Some(q) = &self.question {
            s.push_str(&format!("Question: {q}\n"));
        }
        s.push_str(&format!(
            "Logical query: {}\n\n[C2] Inference result:\n",
            self.query
        ));
        for l in &self.c2 {
            s.push_str(&format!("- {l}\n"));
        }
        s.push_str("\n[C3] Scene facts:\n");
        for l in &self.c3 {
            s.push_str(&format!("- {l}\n"));
        }
        s
    }
}

/// C2: the answer, its bindings and proofs as sentences.
pub fn inference_sentences(r: &AskResult) -> Vec<String> {
    let mut out = Vec::new();
    match r.answer {
        Outcome::Yes => {
            out.push(format!(
                "The answer is {}{}: {} binding{} the query.",
                verdict("yes", r.probability),
                how_sure(r.probability),
                r.count,
                if r.count == 1 {
                    " satisfies"
                } else {
                    "s satisfy"
                }
            ));
            for (i, b) in r.bindings.iter().enumerate() {
                let bind: Vec<String> = b.iter().map(|(v, c)| format!("{v} is {c}")).collect();
                if !bind.is_empty() {
                    let sure = match r.binding_probabilities.get(i) {
                        Some(p) if *p < PROBABLY_BELOW => format!(" (probably: probability {p})"),
                        Some(p) if *p < 1.0 => format!(" (probability {p})"),
                        _ => String::new(),
                    };
                    out.push(format!("Answer {}: {}{sure}.", i + 1, bind.join(", ")));
                }
                if let Some(proof) = r.proofs.get(i) {
                    proof_sentences(proof, &mut out);
                }
            }
            out.extend(r.hinges.iter().map(crate::belief::Hinge::sentence));
        }
        // A counting query's "no" is its test failing, not a missing
        // object: its note ("found 2 cars …; the question asks for more
        // than 2") follows.
        Outcome::No if r.query.trim_start().starts_with('#') => {
            out.push(format!(
                "The answer is {}{}.",
                verdict("no", r.probability),
                how_sure(r.probability)
            ));
            out.extend(r.hinges.iter().map(crate::belief::Hinge::sentence));
        }
        Outcome::No => {
            out.push(format!(
                "The answer is {}{}: no object satisfies every part of the query.",
                verdict("no", r.probability),
                how_sure(r.probability)
            ));
            // Every sentence is a claim the engine checked (crate::whynot).
            out.extend(r.why_not.iter().filter_map(crate::whynot::WhyNot::sentence));
            out.extend(r.hinges.iter().map(crate::belief::Hinge::sentence));
        }
        Outcome::Unknown => {
            out.push(
                "The answer is unknown: the perception source cannot observe part of the query."
                    .into(),
            );
            out.extend(
                r.reasons
                    .iter()
                    .map(|x| format!("{}.", x.trim_end_matches('.'))),
            );
        }
        Outcome::Invalid => {
            out.push("The query could not be checked against the LogicPad.".into());
            out.extend(
                r.reasons
                    .iter()
                    .map(|x| format!("{}.", x.trim_end_matches('.'))),
            );
        }
    }
    // After the verdict: what it rests on ("car_3 is not seen in frames
    // 20–29", how a universal held).
    let verdict = usize::from(!out.is_empty());
    for (i, n) in r.notes.iter().enumerate() {
        let mut sentence = n.trim_end_matches('.').to_string();
        if let Some(first) = sentence.get(..1) {
            sentence.replace_range(..1, &first.to_uppercase());
        }
        out.insert(verdict + i, format!("{sentence}."));
    }
    out
}

/// Below this probability an answer, an observed fact in its proof and a
/// scene fact are said with "probably" and their number, so that a model
/// reading the context does not take a doubtful perception as proved
/// (issue 36). From this up to 1 the number alone is given; at 1 (a
/// noise-free source) nothing.
pub const PROBABLY_BELOW: f64 = 0.95;

/// Whether a probability is low enough to hedge ([`PROBABLY_BELOW`]).
fn doubtful(probability: Option<f64>) -> Option<f64> {
    probability.filter(|p| *p < PROBABLY_BELOW)
}

/// How sure an answer is, for its verdict sentence: nothing when it is
/// certain (a noise-free source), else its probability of being right.
fn how_sure(probability: Option<f64>) -> String {
    match probability {
        Some(p) if p < 1.0 => format!(", with probability {p} of being right"),
        _ => String::new(),
    }
}

/// The verdict's word: "yes", or "probably yes" below [`PROBABLY_BELOW`].
fn verdict(word: &str, probability: Option<f64>) -> String {
    match doubtful(probability) {
        Some(_) => format!("probably {word}"),
        None => word.to_string(),
    }
}

/// A proof as sentences, depth first, a premise indented under its
/// conclusion with "because".
fn proof_sentences(nodes: &[ProofNode], out: &mut Vec<String>) {
    let mut stack: Vec<(usize, &ProofNode)> = nodes.iter().rev().map(|n| (0, n)).collect();
    while let Some((depth, n)) = stack.pop() {
        let indent = if depth > 0 {
            "  ".repeat(depth) + "because "
        } else {
            String::new()
        };
        let atom = &n.fact;
        out.push(match &n.step {
            Step::Observed {
                provenance: Some(p),
            } if doubtful(p.probability).is_some() => format!(
                "{indent}{atom} was probably observed ({}).",
                describe_provenance(p)
            ),
            Step::Observed {
                provenance: Some(p),
            } => format!("{indent}{atom} was observed ({}).", describe_provenance(p)),
            Step::Observed { provenance: None } => format!("{indent}{atom} is a given fact."),
            Step::Rule { line, text } => {
                format!("{indent}{atom} follows by the rule at line {line}: {text}.")
            }
            Step::Absent { doubt: None } => {
                format!("{indent}{atom} holds because no such fact was observed (closed world).")
            }
            Step::Absent { doubt: Some(q) } => format!(
                "{indent}{atom} holds because no such fact was observed (closed world), though the measurement leaves probability {} that it holds.",
                crate::belief::rounded(*q)
            ),
            // A derived fact whose proof logicpad's ProofLimits left out.
            Step::Cut { reason } => {
                format!("{indent}{atom} holds; its proof is left out here ({reason}).")
            }
        });
        stack.extend(n.premises.iter().rev().map(|p| (depth + 1, p)));
    }
}

fn location_phrase(v: &str) -> String {
    let (near, side) = if let Some(s) = v.strip_prefix("Near") {
        ("near ", s)
    } else if let Some(s) = v.strip_prefix("Far") {
        ("far ", s)
    } else {
        ("", v)
    };
    match side {
        "Front" => format!("{near}in front"),
        s => format!("{near}on the {}", s.to_lowercase()),
    }
}

/// How facts read as sentences: each predicate's `sentence:` template from
/// a LogicPad, and which predicates are classes (they name the noun).
#[derive(Debug, Clone, Default)]
pub struct Sentences {
    templates: BTreeMap<String, String>,
    classes: BTreeSet<String>,
    /// The noun of each class predicate and of each value of a `type`
    /// function (`Pedestrian` → "pedestrian", `TypeOf`/`Car` → "car").
    nouns: BTreeMap<String, String>,
    /// Functions whose last argument is a value asked for by "what/which":
    /// roles `type` and `attribute` (`TypeOf`, `ColorOf`).
    valued: BTreeSet<String>,
    /// Functions with the role `type`.
    types: BTreeSet<String>,
    /// For each valued function, each value's strict supertypes by the
    /// LogicPad's taxonomy rules (`TypeOf(x, Sedan) ==> TypeOf(x, Car)`),
    /// transitively closed ([`Sentences::with_taxonomy`]); empty until set.
    supertypes: BTreeMap<String, BTreeMap<String, BTreeSet<String>>>,
}

impl Sentences {
    /// The same words with the taxonomy of `program`'s rules for every
    /// valued function: what a "what type …" answer reads to keep only
    /// the most specific values (an expert's `:rule` extends it).
    pub(crate) fn with_taxonomy(mut self, program: &logicpad::Program) -> Sentences {
        self.supertypes = self
            .valued
            .iter()
            .map(|f| (f.clone(), crate::engine::taxonomy_edges(program, f)))
            .filter(|(_, up)| !up.is_empty())
            .collect();
        self
    }

    /// Each value of `function` with its strict supertypes (empty when the
    /// LogicPad has no taxonomy rule for it).
    pub(crate) fn supertypes(&self, function: &str) -> Option<&BTreeMap<String, BTreeSet<String>>> {
        self.supertypes.get(function)
    }

    /// The templates and classes a LogicPad declares.
    pub fn from_schema(schema: &logicpad::Schema) -> Sentences {
        let mut s = Sentences::default();
        for p in schema.predicates() {
            if let Some(t) = &p.sentence {
                s.templates.insert(p.name.clone(), t.clone());
            }
            let first = |phrases: &[String], name: &str| {
                phrases
                    .first()
                    .cloned()
                    .unwrap_or_else(|| crate::translate::default_phrase(name))
            };
            match p.role {
                Some(logicpad::Role::Class) if p.arity == 1 => {
                    s.classes.insert(p.name.clone());
                    s.nouns.insert(p.name.clone(), first(&p.phrases, &p.name));
                }
                Some(logicpad::Role::Type) => {
                    s.valued.insert(p.name.clone());
                    s.types.insert(p.name.clone());
                    for v in p.values.iter().flatten() {
                        let phrases = p.value_phrases.get(v).cloned().unwrap_or_default();
                        s.nouns.insert(v.clone(), first(&phrases, v));
                    }
                }
                Some(logicpad::Role::Attribute) => {
                    s.valued.insert(p.name.clone());
                }
                _ => {}
            }
        }
        s
    }

    /// The noun of a class predicate or a type value, as the LogicPad says it.
    pub fn noun(&self, name: &str) -> Option<&str> {
        self.nouns.get(name).map(String::as_str)
    }

    /// Whether `pred` is a class predicate.
    pub(crate) fn is_class(&self, pred: &str) -> bool {
        self.classes.contains(pred)
    }

    /// Whether `function` has the role `type`.
    pub(crate) fn is_type(&self, function: &str) -> bool {
        self.types.contains(function)
    }

    /// Whether `function`'s value is what a "what/which" question asks for.
    pub(crate) fn is_valued(&self, function: &str) -> bool {
        self.valued.contains(function)
    }

    /// The built-in LogicPad's, read once.
    pub fn builtin() -> &'static Sentences {
        static BUILTIN: std::sync::OnceLock<Sentences> = std::sync::OnceLock::new();
        BUILTIN.get_or_init(|| {
            let pad = logicpad::LogicPad::builtin();
            Sentences::from_schema(pad.schema()).with_taxonomy(pad.program())
        })
    }

    /// A fact read through its template: `None` without one, `Some("")`
    /// for a fact left unsaid.
    fn fill(&self, fact: &crate::kb::FactRef<'_>) -> Option<String> {
        let t = self.templates.get(fact.predicate())?;
        let get = |i: usize| fact.arg(i).unwrap_or_default();
        Some(t.replace("{x}", get(0)).replace("{y}", get(1)))
    }
}

/// C3: the window's facts as template sentences, one per object (class,
/// type, colour, places, traits), then one per relation, in the built-in
/// LogicPad's words.
pub fn fact_sentences(kb: &WindowKb) -> Vec<String> {
    fact_sentences_with(kb, Sentences::builtin())
}

/// [`fact_sentences`] in the words of a given LogicPad's `sentence:`
/// templates; a fact without one is stated as written, never dropped.
pub(crate) fn fact_sentences_with(kb: &WindowKb, words: &Sentences) -> Vec<String> {
    let mut out = Vec::new();
    let mut relations: Vec<String> = Vec::new();
    let by_obj = kb.facts_by_object();
    for (obj, facts) in &by_obj {
        let mut class = None;
        let mut type_name = None;
        let mut colour = None;
        let mut initial = Vec::new();
        let mut last = Vec::new();
        let mut traits: Vec<String> = Vec::new();
        let mut together: Vec<String> = Vec::new();
        // Motion is said as one phrase ("does not move", "moves at a
        // constant speed"), from these three facts.
        let mut moving: Option<String> = None;
        let mut changes_speed = false;
        // Facts of this object measured with a probability below
        // PROBABLY_BELOW, said after its sentence.
        let mut unsure: Vec<String> = Vec::new();
        for f in facts {
            if let Some(p) = doubtful(f.provenance().probability) {
                unsure.push(format!(
                    "{} (probability {})",
                    f.to_kb_line(),
                    crate::belief::rounded(p)
                ));
            }
            let a = |i: usize| f.arg(i).unwrap_or_default().to_string();
            match (f.predicate(), f.arity()) {
                ("TypeOf", 2) => type_name = Some(a(1)),
                ("ColorOf", 2) => colour = Some(a(1)),
                ("InitialLocation", 2) => initial.push(a(1)),
                ("LastLocation", 2) => last.push(a(1)),
                ("SharesFrames", 2) => together.push(a(1)),
                // Only a class predicate names the noun: a user's unary
                // predicate sorted before `Vehicles` must not make a car an
                // "emergency".
                (p, 1) if words.classes.contains(p) => {
                    class = class.or_else(|| Some(p.to_string()))
                }
                (p, n) => {
                    let said = words.fill(f);
                    let own = format!("{obj} ");
                    match (said, n) {
                        (Some(t), _) if t.is_empty() => {}
                        // "{x} moves" said of the object itself is a trait
                        // of its sentence.
                        (Some(t), 1) if t.starts_with(&own) => {
                            let phrase = t[own.len()..].to_string();
                            match p {
                                "Moving" => moving = Some(phrase),
                                "SpeedUp" | "SpeedDown" => {
                                    changes_speed = true;
                                    traits.push(phrase);
                                }
                                _ => traits.push(phrase),
                            }
                        }
                        (Some(t), _) => relations.push(format!("{t}.")),
                        (None, 1) => traits.push(format!("satisfies {p}")),
                        // Facts the templates do not know are stated as
                        // written rather than dropped: the context must not
                        // hide evidence.
                        (None, _) => relations.push(format!("{f} holds.")),
                    }
                }
            }
        }
        // `Other` says only "not one of the listed values": a vague type
        // falls back to the class ("a vehicle"), a vague colour is left out
        // rather than read as "an other car".
        let vague = |v: &&String| !matches!(v.as_str(), "Other" | "Misc");
        let noun = match (type_name.as_ref().filter(vague), &class) {
            (Some(t), _) => noun_phrase(t),
            (None, Some(c)) => noun_phrase(c),
            (None, None) => "object".into(),
        };
        let described = match colour.as_ref().filter(vague) {
            Some(c) => format!("{} {noun}", noun_phrase(c).to_lowercase()),
            None => noun,
        };
        // Mass nouns take no article ("vegetation_19 is vegetation").
        let mass = matches!(described.as_str(), "vegetation" | "terrain");
        let mut s = if mass {
            format!("{obj} is {described}")
        } else {
            format!("{obj} is {} {described}", article(&described))
        };
        let plain = |v: &Vec<String>| {
            v.iter()
                .find(|x| !x.starts_with("Near") && !x.starts_with("Far"))
                .or(v.first())
                .cloned()
        };
        let mut parts = Vec::new();
        if let Some(i) = plain(&initial) {
            let near = initial
                .iter()
                .find(|x| x.starts_with("Near") || x.starts_with("Far"));
            parts.push(format!("starts {}", location_phrase(near.unwrap_or(&i))));
        }
        if let Some(l) = plain(&last) {
            let near = last
                .iter()
                .find(|x| x.starts_with("Near") || x.starts_with("Far"));
            parts.push(format!("ends {}", location_phrase(near.unwrap_or(&l))));
        }
        let mobile = matches!(
            class.as_deref(),
            Some("Vehicles" | "Pedestrian" | "Person" | "Cyclist")
        );
        // Speeding up or slowing down is movement, whatever `Moving` says
        // about the window's mean speed.
        if mobile && !changes_speed && moving.is_none() {
            parts.push("does not move".into());
        } else if mobile && !changes_speed {
            parts.push("moves at a constant speed".into());
        } else if let Some(m) = moving.filter(|_| !changes_speed) {
            parts.push(m);
        }
        parts.extend(traits);
        if !together.is_empty() {
            parts.push(format!(
                "is seen in the same frames as {}",
                join_and(&together)
            ));
        }
        if !parts.is_empty() {
            s.push_str(" that ");
            s.push_str(&join_and(&parts));
        }
        s.push('.');
        out.push(s);
        if !unsure.is_empty() {
            out.push(format!(
                "Of what is said of {obj}, these are only probable: {}.",
                unsure.join(", ")
            ));
        }
    }
    out.extend(relations);
    out
}

/// A class predicate or `TypeOf` value as an English noun: `Vehicles` →
/// "vehicle", `PoliceCar` → "police car", `SUV` stays "SUV".
fn noun_phrase(name: &str) -> String {
    match name {
        "Vehicles" => return "vehicle".into(),
        "ConstructionObj" => return "construction object".into(),
        "Misc" | "Other" => return "object".into(),
        _ => {}
    }
    crate::translate::camel_words(name)
        .iter()
        .map(|w| {
            // An acronym (`SUV`, plural `SUVs`) keeps its capitals.
            let stem = w
                .strip_suffix('s')
                .filter(|s| s.chars().count() > 1)
                .unwrap_or(w);
            if stem.chars().count() > 1 && stem.chars().all(|c| !c.is_lowercase()) {
                w.clone()
            } else {
                w.to_lowercase()
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

fn article(phrase: &str) -> &'static str {
    // By the sound of the first word: acronyms by their letter names ("an
    // SUV", "a BMW"), words by their first letter, with the usual
    // "you"-sounding and silent-h exceptions.
    let first = phrase.split_whitespace().next().unwrap_or("");
    let is_acronym = first.chars().count() > 1 && first.chars().all(|c| c.is_ascii_uppercase());
    let vowel_sound = if first.starts_with(|c: char| c.is_ascii_digit()) {
        // Numbers by their sound: "an 8", "an 11", "an 18", "a 7".
        first.starts_with('8') || first == "11" || first == "18"
    } else if is_acronym || first.chars().count() == 1 {
        first.starts_with(['A', 'E', 'F', 'H', 'I', 'L', 'M', 'N', 'O', 'R', 'S', 'X'])
            || first.starts_with(['a', 'e', 'f', 'h', 'i', 'l', 'm', 'n', 'o', 'r', 's', 'x'])
    } else {
        let w = first.to_lowercase();
        // Words whose initial vowel sounds "you" or "won": whole-word
        // stems, since "un-" words ("unidentified") take "an".
        let you = [
            "unit", "unique", "uniform", "unicycl", "univers", "union", "unicorn", "usual",
            "useful", "used", "user", "usage", "utilit", "uranium", "euro", "one", "once",
        ];
        let silent_h = ["hour", "honest", "honou", "heir"];
        (w.starts_with(['a', 'e', 'i', 'o', 'u']) && !you.iter().any(|p| w.starts_with(p)))
            || silent_h.iter().any(|p| w.starts_with(p))
    };
    if vowel_sound { "an" } else { "a" }
}

fn join_and(parts: &[String]) -> String {
    match parts.len() {
        0 => String::new(),
        1 => parts[0].clone(),
        n => format!("{} and {}", parts[..n - 1].join(", "), parts[n - 1]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use logicpad::LogicPad;

    fn kb(lines: &[(&str, &[&str])]) -> WindowKb {
        crate::kb::test_window(LogicPad::builtin().program(), lines)
    }

    #[test]
    fn a_user_unary_predicate_does_not_rename_the_class() {
        // Regression: the first unary predicate by name became the noun, so
        // `Ambulance(car_1)` (sorted before `Vehicles`) made "an ambulance"
        // and the class was lost.
        let s = fact_sentences(&kb(&[("Vehicles", &["car_1"]), ("Ambulance", &["car_1"])]));
        assert_eq!(
            s[0],
            "car_1 is a vehicle that does not move and satisfies Ambulance."
        );
    }

    #[test]
    fn nouns_and_articles_read_as_english() {
        assert_eq!(noun_phrase("PoliceCar"), "police car");
        assert_eq!(noun_phrase("TrafficLight"), "traffic light");
        assert_eq!(noun_phrase("SUV"), "SUV");
        assert_eq!(noun_phrase("SUVLarge"), "SUV large");
        assert_eq!(noun_phrase("Fire Truck"), "fire truck");
        assert_eq!(article("unknown car"), "an");
        assert_eq!(article("used car"), "a");
        assert_eq!(article("X"), "an");
        assert_eq!(article("BMW"), "a");
        // Regression: "a unidentified", "SU vs".
        assert_eq!(article("unidentified object"), "an");
        assert_eq!(article("unit"), "a");
        assert_eq!(article("8 m object"), "an");
        assert_eq!(article("7 m object"), "a");
        assert_eq!(noun_phrase("SUVs"), "SUVs");
        assert_eq!(noun_phrase("SUVsLarge"), "SUVs large");
        assert_eq!(article("orange car"), "an");
        assert_eq!(article("SUV"), "an");
        assert_eq!(article("white SUV"), "a");
        assert_eq!(article("object"), "an");
        assert_eq!(article("car"), "a");
        let s = fact_sentences(&kb(&[
            ("Vehicles", &["car_1"]),
            ("TypeOf", &["car_1", "PoliceCar"]),
            ("ColorOf", &["car_1", "Orange"]),
        ]));
        assert_eq!(s[0], "car_1 is an orange police car that does not move.");
    }

    #[test]
    fn vague_values_and_compound_colours_read_as_english() {
        // Regression: "an other SUV", "a white object" (the class was lost
        // to `TypeOf Other`), "a lightblue car".
        let s = fact_sentences(&kb(&[
            ("Vehicles", &["car_1"]),
            ("TypeOf", &["car_1", "SUV"]),
            ("ColorOf", &["car_1", "Other"]),
            ("Vehicles", &["car_2"]),
            ("TypeOf", &["car_2", "Other"]),
            ("ColorOf", &["car_2", "White"]),
            ("Vehicles", &["car_3"]),
            ("TypeOf", &["car_3", "Car"]),
            ("ColorOf", &["car_3", "LightBlue"]),
        ]));
        assert!(s[0].starts_with("car_1 is an SUV that"), "{s:?}");
        assert!(s[1].starts_with("car_2 is a white vehicle that"), "{s:?}");
        assert!(s[2].starts_with("car_3 is a light blue car that"), "{s:?}");
    }

    #[test]
    fn doubtful_perceptions_are_said_with_probably_and_their_number() {
        // A fact measured with probability 0.8 (below PROBABLY_BELOW).
        let mut moving = crate::kb::test_fact("Moving", &["car_1"], "speed 1.2 m/s");
        std::sync::Arc::make_mut(&mut moving.provenance).probability = Some(0.8);
        let input = crate::kb::test_input(
            vec![
                crate::kb::test_fact("Vehicles", &["car_1"], ""),
                moving.clone(),
            ],
            Vec::new(),
        );
        let kb = WindowKb::build(input, LogicPad::builtin().program()).unwrap();
        let s = fact_sentences(&kb);
        assert_eq!(
            s[1],
            "Of what is said of car_1, these are only probable: Moving(car_1) (probability 0.8)."
        );
        // In a proof: "was probably observed".
        let mut out = Vec::new();
        let node = ProofNode {
            fact: "Moving(car_1)".into(),
            step: Step::Observed {
                provenance: Some(moving.provenance.clone()),
            },
            premises: Vec::new(),
        };
        proof_sentences(std::slice::from_ref(&node), &mut out);
        assert!(
            out[0].starts_with("Moving(car_1) was probably observed ("),
            "{}",
            out[0]
        );
        // The verdict: hedged below the threshold only.
        assert_eq!(verdict("yes", Some(0.9)), "probably yes");
        assert_eq!(verdict("no", Some(0.97)), "no");
        assert_eq!(verdict("yes", None), "yes");
    }

    #[test]
    fn mass_nouns_take_no_article() {
        let s = fact_sentences(&kb(&[("Vegetation", &["vegetation_19"])]));
        assert_eq!(s[0], "vegetation_19 is vegetation.");
    }

    #[test]
    fn speeding_up_is_not_standing_still() {
        // Regression: "does not move, …, speeds up" when `SpeedUp` held
        // without `Moving`.
        let s = fact_sentences(&kb(&[
            ("Pedestrian", &["pedestrian_5"]),
            ("SpeedUp", &["pedestrian_5"]),
        ]));
        assert_eq!(s[0], "pedestrian_5 is a pedestrian that speeds up.");
    }

    #[test]
    fn a_users_predicate_reads_in_its_own_sentence() {
        // C3 templates live in the LogicPad: a new predicate gets words
        // without code, and a bad placeholder is reported at its line.
        let yaml = "atomic_predicates:\n  seg:\n    - predicate: Vehicles(x)\n      role: class\n  rel:\n    - predicate: Tailgates(x, y)\n      sentence: \"{x} tailgates {y}\"\n    - predicate: Honks(x)\n      sentence: \"{x} honks\"\n";
        let pad = logicpad::LogicPad::parse(yaml, "user.yaml", false).expect("loads");
        assert!(pad.diagnostics().is_empty(), "{:?}", pad.diagnostics());
        let kb = crate::kb::test_window(
            pad.program(),
            &[
                ("Vehicles", &["car_1"]),
                ("Honks", &["car_1"]),
                ("Tailgates", &["car_1", "car_2"]),
            ],
        );
        let c3 = fact_sentences_with(&kb, &Sentences::from_schema(pad.schema()));
        assert_eq!(
            c3,
            [
                "car_1 is a vehicle that does not move and honks.",
                "car_1 tailgates car_2."
            ]
        );
        let bad = yaml.replace("{x} honks", "{z} honks");
        let pad = logicpad::LogicPad::parse(&bad, "user.yaml", false).expect("loads");
        let d = pad.diagnostics().first().expect("a diagnostic");
        assert!(
            d.message.contains("uses `{z}`") && d.line() == 9,
            "{} at {}",
            d.message,
            d.line()
        );
    }

    #[test]
    fn an_invalid_query_is_explained_in_words() {
        // Regression: C2 carried only the diagnostic's code line; now the
        // sentence comes from the diagnostic's own message and help.
        let pad = logicpad::LogicPad::builtin();
        let kb = crate::kb::test_window(pad.program(), &[("Pedestrian", &["pedestrian_5"])]);
        let observed = crate::kb::Observability::everything().classify(&pad);
        let r = crate::ask::ask(
            &pad,
            &kb,
            &observed,
            "Pedestrian(x) ^ Levitates(x)",
            Default::default(),
        );
        let c2 = inference_sentences(&r);
        assert_eq!(
            c2[0],
            "The query could not be checked against the LogicPad."
        );
        assert!(c2[1].starts_with("unknown predicate `Levitates`"), "{c2:?}");
        assert!(!c2[1].contains('×') && !c2[1].contains('╭'), "{c2:?}");
        assert_eq!(r.diagnostics[0].code, "logicpad::unknown_predicate");
    }

    #[test]
    fn shares_frames_and_unknown_relations_read_as_sentences() {
        // Regression: these read "has SharesFrames car_2; ped_1" and
        // "has Towing car_2".
        let s = fact_sentences(&kb(&[
            ("Vehicles", &["car_1"]),
            ("TypeOf", &["car_1", "Car"]),
            ("SharesFrames", &["car_1", "car_2"]),
            ("SharesFrames", &["car_1", "ped_1"]),
            ("Towing", &["car_1", "car_2"]),
        ]));
        assert_eq!(
            s[0],
            "car_1 is a car that does not move and is seen in the same frames as car_2 and ped_1."
        );
        assert!(
            s.contains(&"Towing(car_1, car_2) holds.".to_string()),
            "{s:?}"
        );
        assert!(s.iter().all(|l| !l.contains("has ")), "{s:?}");
    }
}
