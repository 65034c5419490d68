//! Experts compose rules, in FOL or in English: the LogicPad promise that a
//! domain expert adds a predicate without editing YAML by hand.
//!
//! The main types:
//! - [`NewRule`]: a rule ready to join a LogicPad — its head predicate, the
//!   FOL text, the English phrases the translator will know it by, and how
//!   it was obtained ([`Via`]).
//! - [`Extended`]: a LogicPad with the rule added, checked, and the YAML
//!   text that holds it (for `--append`).
//!
//! Three ways in: a FOL rule as written ([`from_fol`]); an English
//! definition the grammar reads (`from_english`: "A pedestrian is
//! crossing when it is on a road" — the condition is asked as a question,
//! "Is there a pedestrian that is on a road?", through the same translator
//! as every question, and its query becomes the rule's body); or an LLM
//! (`from_llm`) with the check-and-repair loop of query translation.
//! Every rule, however obtained, is checked by adding it to the LogicPad's
//! own text and loading that text with the LogicPad checker ([`extend`]):
//! arity, safety, stratification and name clashes are the checker's, never
//! re-implemented here, and a rule it rejects is reported with its words.

use crate::engine::{Engine, LlmSetup, TranslatorMode};
use crate::llm::client::{LlmError, Message};
use crate::llm::{Chat, Templates, fill};
use logicpad::{Diagnostic, LogicPad};
use serde::Serialize;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// How a rule was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Via {
    /// Written in FOL by the user.
    Fol,
    /// An English definition read by the grammar.
    Grammar,
    /// An English definition translated by an LLM.
    Llm,
}

/// A rule ready to join a LogicPad.
///
/// Invariant: `logic` is one formula `… ==> name(args)` whose head has
/// `arity` arguments; `phrases` are lower-case words, never empty.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct NewRule {
    /// The head predicate (CamelCase).
    pub name: String,
    /// Its number of arguments.
    pub arity: usize,
    /// The rule in LogicPad's FOL syntax.
    pub logic: String,
    /// English phrases for the new predicate (the translator's vocabulary).
    pub phrases: Vec<String>,
    /// The English definition it came from, if any.
    pub sentence: Option<String>,
    /// How it was obtained.
    pub via: Via,
    /// What the translator said on the way (its notes, LLM rounds).
    pub notes: Vec<String>,
}

/// Why a rule could not be composed.
#[derive(Debug, thiserror::Error)]
pub enum ComposeError {
    /// Occurs when FOL text is not one rule `body ==> Head(args)`.
    #[error("not a rule: {text:?} ({expected})")]
    NotARule {
        /// The text given.
        text: String,
        /// What was expected instead.
        expected: String,
    },
    /// Occurs when an English sentence is not a definition the grammar
    /// reads.
    #[error(
        "cannot read {sentence:?} as a definition: {reason}; write it as \"A <object> is <name> when it is <condition>\" (e.g. \"A pedestrian is crossing when it is on a road\"), or give the rule in FOL, or use --translator auto with --llm"
    )]
    NotADefinition {
        /// The sentence given.
        sentence: String,
        /// What did not fit.
        reason: String,
    },
    /// Occurs when the definition's condition cannot be translated.
    #[error("cannot translate the condition {question:?}: {reason}")]
    Condition {
        /// The condition as asked.
        question: String,
        /// The translator's reason.
        reason: String,
    },
    /// Occurs when the LogicPad checker rejects the rule.
    #[error("the LogicPad rejects `{logic}`:\n{}", .diagnostics.join("\n"))]
    Rejected {
        /// The rule.
        logic: String,
        /// The checker's findings, one per line (`line:col: message`).
        diagnostics: Vec<String>,
    },
    /// Occurs when the LLM says the sentence cannot be expressed.
    #[error("the LLM could not express the definition: {0}")]
    LlmCannot(String),
    /// Occurs when every LLM round was rejected.
    #[error("the LLM's rule `{logic}` is still invalid after {rounds} round(s):\n{}", .diagnostics.join("\n"))]
    LlmInvalid {
        /// The last rule proposed.
        logic: String,
        /// Rounds made.
        rounds: usize,
        /// The last findings.
        diagnostics: Vec<String>,
    },
    /// Occurs when the LLM server cannot answer.
    #[error(transparent)]
    Llm(#[from] LlmError),
    /// Occurs when the llm mode has no server to ask.
    #[error("the llm translator needs a server: give --llm URL (or set LOGICRAG_LLM_URL)")]
    NoLlm,
    /// Occurs when neither the grammar nor the LLM can make the rule (auto mode).
    #[error("cannot make a rule of the definition: the grammar: {grammar}; the LLM: {llm}")]
    Neither {
        /// The grammar's reason.
        grammar: Box<ComposeError>,
        /// The LLM's reason.
        llm: Box<ComposeError>,
    },
    /// Occurs when the LogicPad file to append to cannot be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
}

/// Whether `text` is FOL (a rule arrow) rather than English.
pub fn looks_like_fol(text: &str) -> bool {
    ["==>", "=>", "→", "⇒", "->"]
        .iter()
        .any(|a| text.contains(a))
}

/// A rule written in FOL: its head is read from the text after the arrow;
/// the rest is left to the LogicPad checker ([`extend`]).
pub fn from_fol(text: &str) -> Result<NewRule, ComposeError> {
    let not_a_rule = |expected: &str| ComposeError::NotARule {
        text: text.to_string(),
        expected: expected.to_string(),
    };
    let text = text.trim();
    let arrow = ["==>", "=>", "→", "⇒", "->"]
        .iter()
        .filter_map(|a| text.rfind(a).map(|i| (i, a.len())))
        .max()
        .ok_or_else(|| not_a_rule("expected `body ==> Head(x)`"))?;
    let head = text[arrow.0 + arrow.1..].trim();
    let open = head
        .find('(')
        .ok_or_else(|| not_a_rule("expected a head atom such as `Crossing(x)` after `==>`"))?;
    let name = head[..open].trim();
    let args = head[open + 1..]
        .strip_suffix(')')
        .ok_or_else(|| not_a_rule("expected the head atom to end with `)`"))?;
    if name.starts_with('¬') || name.starts_with('~') || name.starts_with('!') {
        return Err(not_a_rule(
            "a negated head is an integrity constraint: add it to the LogicPad file",
        ));
    }
    if !is_predicate_name(name) {
        return Err(not_a_rule(
            "expected a CamelCase predicate name in the head, e.g. `Crossing(x)`",
        ));
    }
    let arity = args.split(',').filter(|a| !a.trim().is_empty()).count();
    if arity == 0 {
        return Err(not_a_rule("expected the head to have arguments"));
    }
    Ok(NewRule {
        name: name.to_string(),
        arity,
        logic: text.to_string(),
        phrases: vec![words_of(name)],
        sentence: None,
        via: Via::Fol,
        notes: Vec::new(),
    })
}

fn is_predicate_name(name: &str) -> bool {
    let mut chars = name.chars();
    chars.next().is_some_and(|c| c.is_ascii_uppercase())
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// `GettingCloser` → `getting closer`.
fn words_of(name: &str) -> String {
    let mut out = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            out.push(' ');
        }
        out.extend(c.to_lowercase());
    }
    out.replace('_', " ")
}

/// `close to the curb` → `CloseToTheCurb`.
fn name_of(words: &str) -> String {
    words
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| !w.is_empty())
        .map(|w| {
            let mut c = w.chars();
            c.next().map_or_else(String::new, |f| {
                f.to_ascii_uppercase().to_string() + &c.as_str().to_ascii_lowercase()
            })
        })
        .collect()
}

/// The parts of a definition "A <subject> is <head> when <condition>".
#[derive(Debug, Clone, PartialEq, Eq)]
struct Definition {
    subject: String,
    head: String,
    condition: String,
}

/// Words that start the condition of a definition.
const CONDITION_WORDS: [&str; 4] = ["whenever", "when", "if", "while"];
/// Articles before the subject.
const ARTICLES: [&str; 6] = ["a", "an", "the", "any", "every", "each"];
/// How a condition refers back to the subject, and what is asked instead.
const PRONOUNS: [(&str, &str); 7] = [
    ("it is ", "that is "),
    ("it's ", "that is "),
    ("they are ", "that is "),
    ("he is ", "that is "),
    ("she is ", "that is "),
    ("it ", "that "),
    ("they ", "that "),
];

fn read_definition(sentence: &str) -> Result<Definition, String> {
    let s = sentence
        .trim()
        .trim_end_matches(['.', '!'])
        .trim()
        .to_lowercase();
    let words: Vec<&str> = s.split_whitespace().collect();
    let cond_at = words
        .iter()
        .position(|w| CONDITION_WORDS.contains(w))
        .ok_or("no `when` or `if` before the condition")?;
    let copula = words[..cond_at]
        .iter()
        .position(|w| matches!(*w, "is" | "are"))
        .ok_or("no `is` between the object and the new name")?;
    let mut subject = &words[..copula];
    if subject.first().is_some_and(|w| ARTICLES.contains(w)) {
        subject = &subject[1..];
    }
    let head = &words[copula + 1..cond_at];
    let condition = words[cond_at + 1..].join(" ");
    if subject.is_empty() {
        return Err("no object before `is`".into());
    }
    if head.is_empty() {
        return Err("no name between `is` and the condition".into());
    }
    if condition.is_empty() {
        return Err("nothing after the condition word".into());
    }
    Ok(Definition {
        subject: subject.join(" "),
        head: head.join(" "),
        condition,
    })
}

/// An English definition through the grammar: "A pedestrian is crossing
/// when it is on a road" asks "Is there a pedestrian that is on a road?",
/// and the query (`Pedestrian(x)^Road(y)^On(x, y)`) becomes the body of
/// `Crossing(x)`, whose head variable is the subject's. `name` overrides
/// the predicate name made from the words between `is` and `when`.
pub(crate) fn from_english(
    engine: &Engine,
    sentence: &str,
    name: Option<&str>,
) -> Result<NewRule, ComposeError> {
    let not_def = |reason: String| ComposeError::NotADefinition {
        sentence: sentence.to_string(),
        reason,
    };
    let def = read_definition(sentence).map_err(not_def)?;
    let rest = PRONOUNS
        .iter()
        .find_map(|(p, ask)| def.condition.strip_prefix(p).map(|r| format!("{ask}{r}")))
        .ok_or_else(|| {
            not_def(format!(
                "the condition {:?} does not start with `it` (the {} it defines)",
                def.condition, def.subject
            ))
        })?;
    // "… and it is moving" reads as "… and moving": one subject throughout.
    let rest = PRONOUNS
        .iter()
        .fold(rest, |r, (p, _)| r.replace(&format!(" and {p}"), " and "));
    let question = format!("Is there a {} {rest}?", def.subject);
    let t = engine
        .translator()
        .translate(&question)
        .map_err(|e| ComposeError::Condition {
            question: question.clone(),
            reason: e.to_string(),
        })?;
    // A rule's body is a conjunction of atoms: a scoped negation, a count
    // or a time order has no rule form, and is refused by name rather
    // than defined from a part of it.
    if !t.is_conjunction() {
        return Err(ComposeError::Condition {
            question: question.clone(),
            reason: format!(
                "`{}` is not a conjunction of atoms (a {} query), and a rule body must be one: define a helper predicate for the inner part and negate or use that",
                t.query,
                match t.form {
                    crate::translate::Form::Scoped => "scoped negation",
                    crate::translate::Form::Count => "counting",
                    crate::translate::Form::Temporal => "temporal",
                    crate::translate::Form::Conjunction => "conjunctive",
                }
            ),
        });
    }
    // The subject's variable is the first positive atom's first argument:
    // the translator writes the subject's class first.
    let head_var = t
        .atoms
        .iter()
        .find(|a| !a.negated)
        .and_then(|a| a.args.first())
        .filter(|v| logicpad::is_variable_name(v))
        .ok_or_else(|| ComposeError::Condition {
            question: question.clone(),
            reason: format!("`{}` binds no object to define", t.query),
        })?
        .clone();
    let body: Vec<String> = t.atoms.iter().map(ToString::to_string).collect();
    let name = name.map_or_else(|| name_of(&def.head), str::to_string);
    if !is_predicate_name(&name) {
        return Err(not_def(format!(
            "`{name}` is not a predicate name (CamelCase letters and digits)"
        )));
    }
    Ok(NewRule {
        logic: format!("∀{head_var} : {} ==> {name}({head_var})", body.join(" ∧ ")),
        name,
        arity: 1,
        phrases: vec![def.head.clone()],
        sentence: Some(sentence.trim().to_string()),
        via: Via::Grammar,
        notes: std::iter::once(format!("condition asked as: {question} → {}", t.query))
            .chain(t.notes)
            .collect(),
    })
}

/// A LogicPad with one more rule, checked.
#[derive(Debug)]
pub struct Extended {
    /// The checked LogicPad (its source text is `text`).
    pub pad: LogicPad,
    /// The LogicPad text with the rule's entry added.
    pub text: String,
    /// The line of the rule's entry in `text` (from 1).
    pub line: usize,
    /// Warnings the checker gave the new rule.
    pub warnings: Vec<String>,
}

/// The LogicPad entry of a rule, indented by `indent` spaces, the English
/// sentence (if any) as a comment above it.
fn entry(rule: &NewRule, indent: usize) -> String {
    let pad = " ".repeat(indent);
    let quote = |s: &str| {
        // A YAML double-quoted scalar: only `\` and `"` need escaping;
        // line breaks never reach here (they are folded to spaces).
        format!(
            "\"{}\"",
            s.replace(['\n', '\r'], " ")
                .replace('\\', "\\\\")
                .replace('"', "\\\"")
        )
    };
    let mut out = String::new();
    if let Some(s) = &rule.sentence {
        out.push_str(&format!("{pad}# {}\n", s.replace(['\n', '\r'], " ")));
    }
    let role = if rule.arity == 1 {
        "property"
    } else {
        "relation"
    };
    let phrases: Vec<String> = rule.phrases.iter().map(|p| quote(p)).collect();
    out.push_str(&format!("{pad}- name: {}\n", rule.name));
    out.push_str(&format!("{pad}  role: {role}\n"));
    out.push_str(&format!("{pad}  phrases: [{}]\n", phrases.join(", ")));
    out.push_str(&format!("{pad}  logic: {}\n", quote(&rule.logic)));
    out
}

/// Where a new `derived_predicates` entry goes in a LogicPad's text: the
/// byte offset after the section's last item, and the items' indentation;
/// `None` when the text has no such section.
fn insertion_point(text: &str) -> Option<(usize, usize)> {
    let mut offset = 0;
    let mut in_section = false;
    let mut end = None;
    let mut indent = None;
    for line in text.split_inclusive('\n') {
        let start = offset;
        offset += line.len();
        let trimmed = line.trim_end();
        if !in_section {
            if trimmed
                .split('#')
                .next()
                .is_some_and(|l| l.trim_end() == "derived_predicates:")
                && !line.starts_with([' ', '\t'])
            {
                in_section = true;
                end = Some(offset);
            }
            continue;
        }
        let blank = trimmed.trim().is_empty() || trimmed.trim_start().starts_with('#');
        if blank {
            continue;
        }
        // A key at column 0 ends the section (a `-` there is a list item
        // of the section written without indentation).
        if !line.starts_with([' ', '\t', '-']) {
            break;
        }
        if indent.is_none() && trimmed.trim_start().starts_with('-') {
            indent = Some(line.len() - line.trim_start().len());
        }
        end = Some(start + line.len());
    }
    end.map(|e| (e, indent.unwrap_or(2)))
}

/// A declared predicate in a few words: `Stopped(x)`, its phrases.
fn describe(p: &logicpad::schema::PredInfo) -> String {
    let args: Vec<String> = (0..p.arity).map(|i| format!("x{i}")).collect();
    let mut s = format!("{}({})", p.name, args.join(", "));
    if !p.phrases.is_empty() {
        s.push_str(&format!(": {}", p.phrases.join(", ")));
    }
    s
}

/// Existing predicates that the translator already knows by one of the
/// rule's phrases: questions with that phrase may not reach the new rule.
fn phrase_clashes(pad: &LogicPad, rule: &NewRule) -> Vec<String> {
    let mut out = Vec::new();
    for phrase in &rule.phrases {
        for p in pad.schema().predicates() {
            if p.phrases.iter().any(|q| q.eq_ignore_ascii_case(phrase)) {
                out.push(format!(
                    "the phrase \"{phrase}\" already means `{}`; give the new predicate other words with --phrases",
                    p.name
                ));
            }
        }
    }
    out
}

/// A diagnostic as one line: `file:line:col: message (help)`.
fn diagnostic_line(d: &Diagnostic) -> String {
    let mut s = d.summary();
    if let Some(h) = &d.help {
        s.push_str(&format!(" ({h})"));
    }
    s
}

/// Adds `rule` to the LogicPad `pad` (its own text) and checks the result
/// with the LogicPad checker. Rejected when the checker finds an error it
/// did not find before (in the rule, or one the rule causes elsewhere, such
/// as a negation cycle), or when the rule is left out of the program.
pub fn extend(pad: &LogicPad, rule: &NewRule) -> Result<Extended, ComposeError> {
    // A second definition of a declared predicate would silently change
    // the meaning of every question that uses it: a new rule names a new
    // predicate (an alternative definition is an edit of the LogicPad).
    if let Some(old) = pad
        .schema()
        .predicates()
        .find(|p| p.name.eq_ignore_ascii_case(&rule.name))
    {
        return Err(ComposeError::Rejected {
            logic: rule.logic.clone(),
            diagnostics: vec![format!(
                "`{}` is already declared by the LogicPad ({}): a new rule must name a new predicate; choose another name (--name), or edit the LogicPad to change `{}`",
                rule.name,
                describe(old),
                old.name
            )],
        });
    }
    let source = pad.source();
    let old = &source.text;
    let (text, at) = match insertion_point(old) {
        Some((at, indent)) => {
            let mut t = String::with_capacity(old.len() + 256);
            t.push_str(&old[..at]);
            if !t.ends_with('\n') {
                t.push('\n');
            }
            let ins = t.len();
            t.push_str(&entry(rule, indent));
            t.push_str(&old[at..]);
            (t, ins)
        }
        None => {
            let mut t = old.clone();
            if !t.is_empty() && !t.ends_with('\n') {
                t.push('\n');
            }
            t.push_str("derived_predicates:\n");
            let at = t.len();
            t.push_str(&entry(rule, 2));
            (t, at)
        }
    };
    let rejected = |diagnostics: Vec<String>| ComposeError::Rejected {
        logic: rule.logic.clone(),
        diagnostics,
    };
    let new =
        LogicPad::parse(&text, &source.name, false).map_err(|e| rejected(vec![e.to_string()]))?;
    let before: BTreeSet<(String, String)> = pad
        .diagnostics()
        .iter()
        .map(|d| (format!("{:?}", d.kind), d.message.clone()))
        .collect();
    let fresh: Vec<&Diagnostic> = new
        .diagnostics()
        .iter()
        .filter(|d| !before.contains(&(format!("{:?}", d.kind), d.message.clone())))
        .collect();
    let errors: Vec<String> = fresh
        .iter()
        .filter(|d| d.is_error())
        .map(|d| diagnostic_line(d))
        .collect();
    if !errors.is_empty() {
        return Err(rejected(errors));
    }
    if !new
        .program()
        .rules()
        .iter()
        .any(|r| r.source.entry == rule.name)
    {
        return Err(rejected(vec![format!(
            "the rule for `{}` was left out of the program",
            rule.name
        )]));
    }
    let line = text[..at].matches('\n').count() + 1;
    Ok(Extended {
        warnings: fresh
            .iter()
            .filter(|d| !d.is_error())
            .map(|d| diagnostic_line(d))
            .chain(phrase_clashes(pad, rule))
            .collect(),
        pad: new,
        text,
        line,
    })
}

/// Writes an extended LogicPad over `path`, whole or not at all (a
/// temporary file beside it, then a rename).
pub fn write_pad(path: &Path, ext: &Extended) -> Result<(), ComposeError> {
    let io = |source| ComposeError::Io {
        path: path.to_path_buf(),
        source,
    };
    let tmp = path.with_extension(format!("yaml.tmp-{}", std::process::id()));
    std::fs::write(&tmp, &ext.text).map_err(io)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e)
    })
}

/// An English definition under a translator mode, as questions are
/// translated ([`crate::engine::translator`]): the grammar, the LLM of `llm`, or
/// the grammar then the LLM (`Auto`; without `llm`, the grammar alone).
pub fn from_definition(
    engine: &Engine,
    sentence: &str,
    name: Option<&str>,
    mode: TranslatorMode,
    llm: Option<&LlmSetup>,
) -> Result<NewRule, ComposeError> {
    let by_llm = |s: &LlmSetup| from_llm(engine, &s.chat, &s.templates, sentence, name, s.repairs);
    match (mode, llm) {
        (TranslatorMode::Grammar, _) | (TranslatorMode::Auto, None) => {
            from_english(engine, sentence, name)
        }
        (TranslatorMode::Llm, None) => Err(ComposeError::NoLlm),
        (TranslatorMode::Llm, Some(s)) => by_llm(s),
        (TranslatorMode::Auto, Some(s)) => {
            from_english(engine, sentence, name).or_else(|grammar| {
                by_llm(s).map_err(|llm| ComposeError::Neither {
                    grammar: Box::new(grammar),
                    llm: Box::new(llm),
                })
            })
        }
    }
}

/// The rule in an LLM's reply (its first line, unwrapped, without a
/// `Rule:` label).
fn read_rule(reply: &str) -> String {
    crate::llm::translate::read_answer_line(reply, "Rule:")
}

/// An English definition through an LLM: the prompt lists the LogicPad's
/// vocabulary; the reply is checked by adding it to the LogicPad
/// ([`extend`]), and a rejected reply gets a repair prompt quoting the
/// checker, up to `repairs` rounds. `name` is the predicate name to use,
/// if the user gave one.
pub(crate) fn from_llm(
    engine: &Engine,
    chat: &Chat,
    templates: &Templates,
    sentence: &str,
    name: Option<&str>,
    repairs: u32,
) -> Result<NewRule, ComposeError> {
    let translator = crate::llm::translate::LlmTranslator {
        chat,
        templates,
        pad: engine.pad(),
        repairs,
    };
    let name_hint = name.map_or_else(
        || "a new CamelCase name made from the defined words".to_string(),
        |n| format!("`{n}`"),
    );
    let prompt = fill(
        &templates.rule,
        &[
            ("vocabulary", &translator.vocabulary()),
            ("sentence", sentence.trim()),
            ("name", &name_hint),
        ],
    );
    let mut messages = vec![Message::text("user", prompt)];
    let mut rounds = 0usize;
    loop {
        rounds += 1;
        let (reply, _) = chat.reply(&messages)?;
        let logic = read_rule(&reply);
        if let Some(reason) = logic.strip_prefix("CANNOT:") {
            return Err(ComposeError::LlmCannot(reason.trim().to_string()));
        }
        let checked = from_fol(&logic).and_then(|mut rule| {
            if let Some(n) = name
                && rule.name != n
            {
                return Err(ComposeError::Rejected {
                    logic: logic.clone(),
                    diagnostics: vec![format!("the head must be `{n}`, not `{}`", rule.name)],
                });
            }
            rule.sentence = Some(sentence.trim().to_string());
            rule.via = Via::Llm;
            rule.notes = vec![format!(
                "written by the LLM ({}) in {rounds} round{}",
                chat.client.config().model,
                if rounds == 1 { "" } else { "s" }
            )];
            extend(engine.pad(), &rule).map(|_| rule)
        });
        match checked {
            Ok(rule) => return Ok(rule),
            Err(e) => {
                let said = match e {
                    ComposeError::Rejected { diagnostics, .. } => diagnostics,
                    other => vec![other.to_string()],
                };
                if rounds > repairs as usize {
                    return Err(ComposeError::LlmInvalid {
                        logic,
                        rounds,
                        diagnostics: said,
                    });
                }
                let repair = fill(&templates.repair_rule, &[("diagnostics", &said.join("\n"))]);
                messages.push(Message::text("assistant", reply));
                messages.push(Message::text("user", repair));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kb::Observability;

    fn engine() -> Engine {
        match Engine::new(LogicPad::builtin(), Observability::everything()) {
            Ok(e) => e,
            Err(e) => panic!("built-in engine: {e}"),
        }
    }

    #[test]
    fn a_definition_is_read_into_subject_name_and_condition() {
        assert_eq!(
            read_definition("A pedestrian is crossing when it is on a road."),
            Ok(Definition {
                subject: "pedestrian".into(),
                head: "crossing".into(),
                condition: "it is on a road".into()
            })
        );
        assert!(read_definition("Pedestrians cross roads").is_err());
        assert!(read_definition("is crossing when it is on a road").is_err());
    }

    #[test]
    fn an_english_definition_becomes_a_checked_rule_whose_body_is_the_conditions_query() {
        let e = engine();
        let r = from_english(&e, "A pedestrian is crossing when it is on a road", None)
            .unwrap_or_else(|err| panic!("{err}"));
        assert_eq!(r.name, "Crossing");
        assert_eq!(r.arity, 1);
        assert_eq!(
            r.logic,
            "∀x : Pedestrian(x) ∧ Road(y) ∧ On(x, y) ==> Crossing(x)"
        );
        assert_eq!(r.phrases, vec!["crossing".to_string()]);
        assert_eq!(r.via, Via::Grammar);
        let ext = extend(e.pad(), &r).unwrap_or_else(|err| panic!("{err}"));
        assert!(
            ext.text
                .contains("# A pedestrian is crossing when it is on a road")
        );
        assert!(ext.pad.schema().get("Crossing").is_some());
    }

    #[test]
    fn a_condition_that_is_no_conjunction_is_refused_by_name() {
        let e = engine();
        let err = from_english(
            &e,
            "A pedestrian is off road when it is not on a road",
            None,
        )
        .err()
        .map(|x| x.to_string())
        .unwrap_or_default();
        assert!(err.contains("scoped negation"), "{err}");
    }

    #[test]
    fn a_fol_rule_is_read_and_a_clash_or_unknown_predicate_is_rejected_by_the_checker() {
        let e = engine();
        let ok = from_fol("∀x : Vehicles(x) ∧ Moving(x) ∧ ColorOf(x, Red) ==> RedMover(x)")
            .unwrap_or_else(|err| panic!("{err}"));
        assert_eq!((ok.name.as_str(), ok.arity), ("RedMover", 1));
        assert!(extend(e.pad(), &ok).is_ok());
        // A name the LogicPad already declares (regression: a second
        // definition of Stopped was accepted and changed its meaning).
        let clash =
            from_fol("∀x : Vehicles(x) ==> Stopped(x)").unwrap_or_else(|err| panic!("{err}"));
        let Err(ComposeError::Rejected { diagnostics, .. }) = extend(e.pad(), &clash) else {
            panic!("a clash with Stopped must be rejected");
        };
        assert!(
            diagnostics.join(" ").contains("already declared"),
            "{diagnostics:?}"
        );
        let english = from_english(&e, "A car is stopped when it is on a road", None)
            .unwrap_or_else(|err| panic!("{err}"));
        assert!(matches!(
            extend(e.pad(), &english),
            Err(ComposeError::Rejected { .. })
        ));
        // An unknown predicate in the body.
        let unknown = from_fol("∀x : Vehicles(x) ∧ Flying(x) ==> Bird(x)")
            .unwrap_or_else(|err| panic!("{err}"));
        let Err(ComposeError::Rejected { diagnostics, .. }) = extend(e.pad(), &unknown) else {
            panic!("an unknown predicate must be rejected");
        };
        assert!(diagnostics.join(" ").contains("Flying"), "{diagnostics:?}");
        // Not a rule at all.
        assert!(matches!(
            from_fol("Vehicles(x) ^ Moving(x)"),
            Err(ComposeError::NotARule { .. })
        ));
        assert!(matches!(
            from_fol("∀x : Vehicles(x) ==> ¬Moving(x)"),
            Err(ComposeError::NotARule { .. })
        ));
    }

    #[test]
    fn a_rule_that_makes_a_negation_cycle_is_rejected() {
        let e = engine();
        let r = from_fol("∀x : Vehicles(x) ∧ ¬Loop(x) ==> Loop(x)")
            .unwrap_or_else(|err| panic!("{err}"));
        assert!(matches!(
            extend(e.pad(), &r),
            Err(ComposeError::Rejected { .. })
        ));
    }

    #[test]
    fn the_entry_goes_at_the_end_of_derived_predicates_even_when_a_section_follows() {
        let text = "atomic_predicates:\n  - Vehicles(x)\n  - Moving(x)\nderived_predicates:\n  - name: Go\n    logic: \"∀x : Vehicles(x) ∧ Moving(x) ==> Go(x)\"\n\n# tail comment\nintegrity_constraints: []\n";
        let (at, indent) = insertion_point(text).unwrap_or_else(|| panic!("no section"));
        assert_eq!(indent, 2);
        assert!(text[..at].ends_with("==> Go(x)\"\n"), "{:?}", &text[..at]);
    }

    #[test]
    fn names_and_phrases_are_made_from_words() {
        assert_eq!(name_of("close to the curb"), "CloseToTheCurb");
        assert_eq!(words_of("GettingCloser"), "getting closer");
    }
}
