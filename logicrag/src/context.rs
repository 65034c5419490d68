//! Retrieval context for a multimodal model, in the two forms the paper
//! evaluates: **C2**, the inference result (answer, bindings, proof as short
//! sentences), and **C3**, the window's facts as template sentences
//! ("car_3 is a white car that starts on the left and moves at a constant
//! speed").

use crate::ask::{AskResult, Outcome};
use crate::kb::WindowKb;
use serde::Serialize;
use std::collections::BTreeMap;

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
    /// Builds the context from an answer and its window.
    pub fn new(kb: &WindowKb, question: Option<&str>, result: &AskResult) -> RagContext {
        RagContext {
            window: kb.id.clone(),
            question: question.map(str::to_string),
            query: result.query.clone(),
            c2: inference_sentences(result),
            c3: fact_sentences(kb),
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
                "The answer is yes: {} binding{} the query.",
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
                    out.push(format!("Answer {}: {}.", i + 1, bind.join(", ")));
                }
                if let Some(proof) = r.proofs.get(i) {
                    for line in proof {
                        out.push(proof_sentence(line));
                    }
                }
            }
        }
        Outcome::No => {
            out.push("The answer is no: no object satisfies every part of the query.".into());
            for w in &r.why_not {
                if w.failed.is_empty() {
                    continue;
                }
                out.push(format!(
                    "{} comes closest: {} hold{}, but {} do{} not.",
                    w.candidate,
                    w.satisfied.join(" and "),
                    if w.satisfied.len() == 1 { "s" } else { "" },
                    w.failed.join(" and "),
                    if w.failed.len() == 1 { "es" } else { "" },
                ));
            }
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
                    .filter_map(|x| x.lines().next())
                    .map(str::to_string),
            );
        }
    }
    out
}

fn proof_sentence(line: &str) -> String {
    let depth = line.len() - line.trim_start().len();
    let t = line.trim();
    let indent = if depth > 0 {
        "  ".repeat(depth / 2) + "because "
    } else {
        String::new()
    };
    if let Some((atom, rest)) = t.split_once("  [") {
        let rest = rest.trim_end_matches(']');
        if let Some(fact) = rest.strip_prefix("fact: ") {
            return format!("{indent}{atom} was observed ({fact}).");
        }
        if rest == "fact" {
            return format!("{indent}{atom} is a given fact.");
        }
        if let Some(rule) = rest.strip_prefix("rule, ") {
            return format!("{indent}{atom} follows by the rule at {rule}.");
        }
        if rest.starts_with("no such fact") {
            return format!(
                "{indent}{atom} holds because no such fact was observed (closed world)."
            );
        }
    }
    format!("{indent}{t}.")
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

/// C3: template sentences from the window's base facts.
pub fn fact_sentences(kb: &WindowKb) -> Vec<String> {
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
        let mut other: BTreeMap<String, Vec<String>> = BTreeMap::new();
        for f in facts {
            let a = |i: usize| f.args.get(i).cloned().unwrap_or_default();
            match (f.predicate.as_str(), f.args.len()) {
                ("TypeOf", 2) => type_name = Some(a(1)),
                ("ColorOf", 2) => colour = Some(a(1)),
                ("InitialLocation", 2) => initial.push(a(1)),
                ("LastLocation", 2) => last.push(a(1)),
                ("Moving", 1) => traits.push("moves".into()),
                ("SpeedUp", 1) => traits.push("speeds up".into()),
                ("SpeedDown", 1) => traits.push("slows down".into()),
                ("Appear", 1) => traits.push("appears in this window".into()),
                ("Disappear", 1) => traits.push("disappears in this window".into()),
                ("CloseToCamera", 1) => traits.push("is close to the camera".into()),
                ("AtLeft", 1) => traits.push("is at the left".into()),
                ("AtRight", 1) => traits.push("is at the right".into()),
                ("AtCenter", 1) => traits.push("is at the center".into()),
                ("DistanceIncrease", 2) => {
                    relations.push(format!("{obj} moves away from {}.", a(1)))
                }
                ("DistanceDecrease", 2) => {
                    relations.push(format!("{obj} gets closer to {}.", a(1)))
                }
                ("DistanceDecreasesToZero", 2) => {
                    relations.push(format!("{obj} closes the gap to {} completely.", a(1)))
                }
                ("DistanceZeroStart", 2) => {
                    relations.push(format!("{obj} touches {} at the start.", a(1)))
                }
                ("DistanceZeroEnd", 2) => {
                    relations.push(format!("{obj} touches {} at the end.", a(1)))
                }
                ("TooClose", 2) => relations.push(format!("{obj} comes too close to {}.", a(1))),
                ("On", 2) => relations.push(format!("{obj} is on {}.", a(1))),
                (p, 1) => class = class.or_else(|| Some(p.to_string())),
                (p, _) => other
                    .entry(p.to_string())
                    .or_default()
                    .push(f.args[1..].join(", ")),
            }
        }
        let noun = match (&type_name, &class) {
            (Some(t), _) => t.to_lowercase(),
            (None, Some(c)) => c.to_lowercase(),
            (None, None) => "object".into(),
        };
        let mut s = format!(
            "{obj} is a {}{noun}",
            colour
                .as_ref()
                .map(|c| format!("{} ", c.to_lowercase()))
                .unwrap_or_default()
        );
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
        if mobile && !traits.iter().any(|t| t == "moves") {
            parts.push("does not move".into());
        } else if mobile && !traits.iter().any(|t| t == "speeds up" || t == "slows down") {
            parts.push("moves at a constant speed".into());
            traits.retain(|t| t != "moves");
        }
        parts.extend(traits);
        for (p, vals) in other {
            parts.push(format!("has {p} {}", vals.join("; ")));
        }
        if !parts.is_empty() {
            s.push_str(" that ");
            s.push_str(&join_and(&parts));
        }
        s.push('.');
        out.push(s);
    }
    out.extend(relations);
    out
}

fn join_and(parts: &[String]) -> String {
    match parts.len() {
        0 => String::new(),
        1 => parts[0].clone(),
        n => format!("{} and {}", parts[..n - 1].join(", "), parts[n - 1]),
    }
}
