//! The JSON objects the command line prints and the server answers with,
//! built in one place so that `ask --json`, `facts --json` and the HTTP API
//! can never drift apart: a per-window answer object
//! ([`answer_object`]), the closing summary object ([`summary_object`]) and
//! a window's facts with provenance ([`facts_object`]); the two answer
//! objects together ([`AskObject`], as JSON [`ask_value`]) for the HTTP
//! API and Python.
//!
//! The answer objects are typed ([`AnswerObject`], [`SummaryObject`],
//! [`AskObject`]): JSON is one rendering of them, Python's dicts (built
//! straight from the same serde form) another.

use crate::ask::AskResult;
use crate::engine::{Prepared, Summary};
use crate::kb::FactRef;
use crate::llm::LmmAnswer;
use serde::Serialize;
use serde::ser::SerializeMap;
use serde_json::{Value, json};
use std::borrow::Cow;

/// One window's answer as `ask --json` prints it: the [`AskResult`]'s
/// fields, plus `"question"` when the text was an English question and
/// `"lmm"` when a multimodal model was asked too.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct AnswerObject<'a> {
    /// The answer.
    #[serde(flatten)]
    pub result: &'a AskResult,
    /// The English question (`None` for a query as written).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub question: Option<&'a str>,
    /// The multimodal model's answer, when one was asked.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lmm: Option<&'a LmmAnswer>,
}

/// [`AnswerObject`] as a JSON value.
pub fn answer_object(
    r: &AskResult,
    p: &Prepared,
    lmm: Option<&LmmAnswer>,
) -> Result<Value, serde_json::Error> {
    serde_json::to_value(AnswerObject {
        result: r,
        question: p.question.as_deref(),
        lmm,
    })
}

/// The summary object `ask --json` prints after the windows: the overall
/// answer, its one-line headline, the question, the query as run and the
/// translator's notes.
#[derive(Debug, Clone, Serialize)]
pub struct SummaryObject<'a> {
    /// The answer over every window.
    pub summary: &'a Summary,
    /// It in one line ([`Summary::headline`], or a temporal answer's).
    pub headline: String,
    /// The English question (`null` for a query as written).
    pub question: &'a Option<String>,
    /// The query as run.
    pub query: &'a str,
    /// The translator's notes.
    pub notes: &'a [String],
}

impl<'a> SummaryObject<'a> {
    /// The summary object of `summary`, headed by its own headline.
    pub fn new(summary: &'a Summary, p: &'a Prepared) -> SummaryObject<'a> {
        SummaryObject {
            summary,
            headline: summary.headline(),
            question: &p.question,
            query: &p.query,
            notes: &p.notes,
        }
    }
}

/// [`SummaryObject`] as a JSON value.
pub fn summary_object(summary: &Summary, p: &Prepared) -> Value {
    json!(SummaryObject::new(summary, p))
}

/// One question's answers over windows as one object: the per-window
/// objects (`"results"`, [`AnswerObject`]) and the summary (`"summary"`,
/// [`SummaryObject`]) — the lines of `ask --json`, as `serve`'s
/// `/api/ask` and the Python package's `Source.ask` return them; or a
/// temporal query's object ([`temporal_object`]), already JSON.
#[derive(Debug, Clone)]
pub enum AskObject<'a> {
    /// Per-window answers and their summary.
    Windows {
        /// The question as prepared.
        prepared: Cow<'a, Prepared>,
        /// One answer per window asked.
        results: Cow<'a, [AskResult]>,
        /// Their summary (boxed: it is most of the object's size).
        summary: Box<Summary>,
    },
    /// A temporal query's answer.
    Temporal(Value),
}

impl<'a> AskObject<'a> {
    /// The answers `results` to `prepared`, summarised (nouns and values
    /// from `words`).
    pub fn windows(
        words: &crate::context::Sentences,
        prepared: Cow<'a, Prepared>,
        results: Cow<'a, [AskResult]>,
    ) -> AskObject<'a> {
        let summary = Box::new(Summary::new(words, &prepared, &results));
        AskObject::Windows {
            prepared,
            results,
            summary,
        }
    }
}

impl Serialize for AskObject<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let (prepared, results, summary) = match self {
            AskObject::Temporal(v) => return v.serialize(s),
            AskObject::Windows {
                prepared,
                results,
                summary,
            } => (prepared, results, summary),
        };
        let question = prepared.question.as_deref();
        let mut head = SummaryObject::new(summary, prepared);
        // A temporal query's one result spans the video: the headline
        // names its times, as `ask` says it.
        if let (Some(_), [r]) = (&prepared.temporal, &results[..]) {
            head.headline = crate::temporal::headline(r);
        }
        let mut m = s.serialize_map(Some(2))?;
        m.serialize_entry(
            "results",
            &results
                .iter()
                .map(|result| AnswerObject {
                    result,
                    question,
                    lmm: None,
                })
                .collect::<Vec<_>>(),
        )?;
        m.serialize_entry("summary", &head)?;
        m.end()
    }
}

/// [`AskObject`] of per-window answers as a JSON value (the server's).
#[cfg(feature = "serve")]
pub(crate) fn ask_object(
    words: &crate::context::Sentences,
    p: &Prepared,
    results: &[AskResult],
) -> Result<Value, serde_json::Error> {
    serde_json::to_value(AskObject::windows(
        words,
        Cow::Borrowed(p),
        Cow::Borrowed(results),
    ))
}

/// A question (or query) answered on `pipeline`'s window named `window`,
/// or on every window, as the typed object whose JSON is `{"results":
/// [...], "summary": {...}}`: the objects `ask --json` prints, as
/// `serve`'s `/api/ask` answers them and Python's `Source.ask` returns
/// them. A temporal query has one result, spanning the windows up to
/// `window` (all for `None`), with its `"temporal"` timelines
/// ([`temporal_object`]).
pub fn ask(
    pipeline: &crate::pipeline::Pipeline,
    text: &str,
    window: Option<&str>,
    opts: crate::ask::AskOptions,
) -> Result<AskObject<'static>, crate::session::SessionError> {
    let words = pipeline.engine().words();
    let p = pipeline.prepare(text)?;
    if let Some(a) = pipeline.ask_temporal(&p, window, opts)? {
        return Ok(AskObject::Temporal(temporal_object(words, &p, &a)?));
    }
    let results: Vec<AskResult> = pipeline
        .ask(&p, window, opts)?
        .into_iter()
        .map(|a| a.result)
        .collect();
    Ok(AskObject::windows(
        words,
        Cow::Owned(p),
        Cow::Owned(results),
    ))
}

/// [`ask`] as a JSON value.
pub fn ask_value(
    pipeline: &crate::pipeline::Pipeline,
    text: &str,
    window: Option<&str>,
    opts: crate::ask::AskOptions,
) -> Result<Value, crate::session::SessionError> {
    Ok(serde_json::to_value(ask(pipeline, text, window, opts)?)?)
}

/// A temporal answer as one object, as `ask --json` prints it and [`ask`]
/// returns it: `"results"`, the one result object spanning the video
/// ([`temporal_result`]), and `"summary"`, the summary object of that
/// result with the claim's headline ([`temporal_summary`]).
pub fn temporal_object(
    words: &crate::context::Sentences,
    p: &Prepared,
    a: &crate::temporal::TemporalAnswer,
) -> Result<Value, serde_json::Error> {
    Ok(serde_json::json!({
        "results": [temporal_result(a, p)?],
        "summary": temporal_summary(a, words, p),
    }))
}

/// The summary object `ask --json` prints last for a temporal answer:
/// the summary of its one result, its headline the claim's
/// ([`crate::temporal::headline`]).
pub fn temporal_summary(
    a: &crate::temporal::TemporalAnswer,
    words: &crate::context::Sentences,
    p: &Prepared,
) -> Value {
    let summary = Summary::new(words, p, std::slice::from_ref(&a.result));
    let mut s = summary_object(&summary, p);
    if let Some(o) = s.as_object_mut() {
        o.insert("headline".into(), serde_json::json!(a.headline));
    }
    s
}

/// A temporal answer as the JSON result object of `ask --json` (the
/// [`AskResult`]'s fields, `"question"` when there is one, and
/// `"temporal"`: the form, parts, windows and timelines).
pub fn temporal_result(
    a: &crate::temporal::TemporalAnswer,
    p: &Prepared,
) -> Result<Value, serde_json::Error> {
    let mut v = answer_object(&a.result, p, None)?;
    if let Some(o) = v.as_object_mut() {
        o.insert("temporal".into(), serde_json::to_value(a)?);
    }
    Ok(v)
}

/// The retrieval context of a question on one window, as `context
/// --json` prints it.
pub fn context_value(
    pipeline: &crate::pipeline::Pipeline,
    text: &str,
    window: &str,
) -> Result<Value, crate::session::SessionError> {
    Ok(serde_json::to_value(pipeline.context_of(text, window)?)?)
}

/// Where a window lies in its source, for [`facts_object`].
#[derive(Debug, Clone, Copy)]
pub struct WindowPlace<'a> {
    /// Window id.
    pub id: &'a str,
    /// Position in the source.
    pub index: u32,
    /// First frame.
    pub first_frame: u32,
    /// Last frame.
    pub last_frame: u32,
}

impl<'a> From<&'a crate::kb::WindowInput> for WindowPlace<'a> {
    fn from(w: &'a crate::kb::WindowInput) -> WindowPlace<'a> {
        WindowPlace {
            id: &w.id,
            index: w.index,
            first_frame: w.first_frame,
            last_frame: w.last_frame,
        }
    }
}

/// A window's facts with provenance, as `facts --json` prints them; with
/// `why`, each fact also carries its provenance in words (`"why"`, the
/// line `facts --why` prints), for readers that show rather than parse it.
pub fn facts_object<'a>(
    source: &str,
    place: WindowPlace<'_>,
    facts: impl IntoIterator<Item = FactRef<'a>>,
    why: bool,
) -> Result<Value, serde_json::Error> {
    let mut list = Vec::new();
    for f in facts {
        let mut v = serde_json::to_value(f)?;
        if why && let Some(obj) = v.as_object_mut() {
            obj.insert(
                "why".into(),
                json!(crate::proof::describe_provenance(f.provenance())),
            );
        }
        list.push(v);
    }
    Ok(json!({
        "window": place.id, "index": place.index, "first_frame": place.first_frame,
        "last_frame": place.last_frame, "source": source, "facts": list,
    }))
}

/// Writes `s` as a JSON string, exactly as serde_json does: a string with
/// nothing to escape (no quote, backslash or control character) is copied
/// as it is; any other goes through serde_json.
pub(crate) fn write_json_str(out: &mut Vec<u8>, s: &str) -> serde_json::Result<()> {
    if !needs_escape(s.as_bytes()) {
        out.reserve(s.len() + 2);
        out.push(b'"');
        out.extend_from_slice(s.as_bytes());
        out.push(b'"');
        Ok(())
    } else {
        serde_json::to_writer(out, s)
    }
}

/// Whether `s` holds a byte JSON escapes (a control character, `"` or
/// `\\`), eight bytes at a time: the strings of a batch line are short
/// (facts, names), too short for the byte-by-byte loop to vectorise, and
/// it cost more than copying them. Without short-circuiting: nearly every
/// string is clean to its end.
fn needs_escape(s: &[u8]) -> bool {
    const ONES: u64 = u64::from_ne_bytes([0x01; 8]);
    const HIGH: u64 = u64::from_ne_bytes([0x80; 8]);
    // A byte of `w` below `n` (n <= 0x80) sets its high bit here; borrows
    // can only mark bytes after a real one, so "any" is exact.
    let below = |w: u64, n: u64| w.wrapping_sub(ONES * n) & !w & HIGH;
    let mut chunks = s.chunks_exact(8);
    let mut found = 0u64;
    for c in &mut chunks {
        let mut word = [0u8; 8];
        word.copy_from_slice(c);
        let w = u64::from_ne_bytes(word);
        found |= below(w, 0x20)
            | below(w ^ (ONES * u64::from(b'"')), 1)
            | below(w ^ (ONES * u64::from(b'\\')), 1);
    }
    found != 0
        || chunks
            .remainder()
            .iter()
            .any(|&b| b < 0x20 || b == b'"' || b == b'\\')
}

/// A list of strings as a JSON array (see [`write_json_str`]).
fn write_json_strs(out: &mut Vec<u8>, list: &[String]) -> serde_json::Result<()> {
    out.push(b'[');
    for (i, s) in list.iter().enumerate() {
        if i > 0 {
            out.push(b',');
        }
        write_json_str(out, s)?;
    }
    out.push(b']');
    Ok(())
}

/// One `--json` line of a `--queries` batch, without the newline: the
/// [`AskResult`]'s fields, then the query's index in its window
/// (`query_index`) and the query as written (`query_text`). Written field
/// by field so that the proofs go through
/// `write_proofs_json` (a batch with
/// proofs is mostly proof nodes); the bytes are those of serde's derived
/// form with the two fields appended (a test holds this). The why-not
/// candidates (one batch of "no"s writes a hundred thousand) are written
/// directly too.
pub fn write_batch_line(
    out: &mut Vec<u8>,
    r: &AskResult,
    query_index: usize,
    query_text: &str,
) -> serde_json::Result<()> {
    // `key` is one of the field names below, none of which needs escaping.
    fn field<T: serde::Serialize + ?Sized>(
        out: &mut Vec<u8>,
        key: &str,
        v: &T,
    ) -> serde_json::Result<()> {
        out.extend_from_slice(b",\"");
        out.extend_from_slice(key.as_bytes());
        out.extend_from_slice(b"\":");
        serde_json::to_writer(out, v)
    }
    out.extend_from_slice(br#"{"window":"#);
    write_json_str(out, &r.window)?;
    field(out, "first_frame", &r.first_frame)?;
    field(out, "last_frame", &r.last_frame)?;
    out.extend_from_slice(br#","query":"#);
    write_json_str(out, &r.query)?;
    field(out, "answer", &r.answer)?;
    out.extend_from_slice(br#","variables":"#);
    write_json_strs(out, &r.variables)?;
    field(out, "count", &r.count)?;
    // Each binding a `[variable, value]` pair, as serde writes a tuple: a
    // yes of a batch lists every binding, and serde's writer cost more
    // per string than the copy.
    out.extend_from_slice(br#","bindings":["#);
    for (i, b) in r.bindings.iter().enumerate() {
        if i > 0 {
            out.push(b',');
        }
        out.push(b'[');
        for (j, (var, value)) in b.iter().enumerate() {
            if j > 0 {
                out.push(b',');
            }
            out.push(b'[');
            write_json_str(out, var)?;
            out.push(b',');
            write_json_str(out, value)?;
            out.push(b']');
        }
        out.push(b']');
    }
    out.push(b']');
    out.extend_from_slice(br#","proofs":"#);
    write_proofs_json(out, &r.proofs)?;
    out.extend_from_slice(br#","why_not":["#);
    for (i, w) in r.why_not.iter().enumerate() {
        if i > 0 {
            out.push(b',');
        }
        out.extend_from_slice(br#"{"variable":"#);
        write_json_str(out, &w.variable)?;
        out.extend_from_slice(br#","candidate":"#);
        write_json_str(out, &w.candidate)?;
        out.extend_from_slice(br#","satisfied":"#);
        write_json_strs(out, &w.satisfied)?;
        out.extend_from_slice(br#","failed":"#);
        write_json_strs(out, &w.failed)?;
        // As serde writes it: only when there is something to say.
        if !w.uncertain.is_empty() {
            out.extend_from_slice(br#","uncertain":"#);
            write_json_strs(out, &w.uncertain)?;
        }
        out.push(b'}');
    }
    out.push(b']');
    out.extend_from_slice(br#","reasons":"#);
    write_json_strs(out, &r.reasons)?;
    field(out, "diagnostics", &r.diagnostics)?;
    out.extend_from_slice(br#","notes":"#);
    write_json_strs(out, &r.notes)?;
    if let Some(n) = &r.stopped {
        field(out, "stopped", n)?;
    }
    if let Some(p) = &r.probability {
        field(out, "probability", p)?;
    }
    if !r.binding_probabilities.is_empty() {
        field(out, "binding_probabilities", &r.binding_probabilities)?;
    }
    if !r.hinges.is_empty() {
        field(out, "hinges", &r.hinges)?;
    }
    field(out, "query_index", &query_index)?;
    out.extend_from_slice(br#","query_text":"#);
    write_json_str(out, query_text)?;
    out.push(b'}');
    Ok(())
}

/// Writes `proofs` as JSON, byte for byte what serde writes for them, for
/// batches that print millions of proof nodes. Two things make it cheaper
/// than serde: a string that needs no escaping (nearly all of them) is
/// copied as it is, and a provenance shared by consecutive observed facts
/// (a window's facts share one) is rendered once and copied after.
pub(crate) fn write_proofs_json(
    out: &mut Vec<u8>,
    proofs: &[Vec<crate::proof::ProofNode>],
) -> serde_json::Result<()> {
    let mut last: Option<(*const perception::Provenance, std::ops::Range<usize>)> = None;
    out.push(b'[');
    for (i, answer) in proofs.iter().enumerate() {
        if i > 0 {
            out.push(b',');
        }
        write_nodes(out, answer, &mut last)?;
    }
    out.push(b']');
    Ok(())
}

/// A list of nodes; `last` is the provenance rendered last and where its
/// bytes lie in `out` (only ever appended to, so they stay there).
fn write_nodes(
    out: &mut Vec<u8>,
    nodes: &[crate::proof::ProofNode],
    last: &mut Option<(*const perception::Provenance, std::ops::Range<usize>)>,
) -> serde_json::Result<()> {
    out.push(b'[');
    for (i, n) in nodes.iter().enumerate() {
        if i > 0 {
            out.push(b',');
        }
        out.extend_from_slice(br#"{"fact":"#);
        write_json_str(out, &n.fact)?;
        out.extend_from_slice(br#","step":{"kind":"#);
        match &n.step {
            crate::proof::Step::Observed { provenance } => {
                out.extend_from_slice(br#""observed","provenance":"#);
                match provenance {
                    None => out.extend_from_slice(b"null"),
                    Some(p) => {
                        let ptr = std::sync::Arc::as_ptr(p);
                        match last.as_ref() {
                            Some((q, range)) if std::ptr::eq(*q, ptr) => {
                                out.extend_from_within(range.clone());
                            }
                            _ => {
                                let start = out.len();
                                serde_json::to_writer(&mut *out, &**p)?;
                                *last = Some((ptr, start..out.len()));
                            }
                        }
                    }
                }
            }
            crate::proof::Step::Rule { line, text } => {
                out.extend_from_slice(br#""rule","line":"#);
                serde_json::to_writer(&mut *out, line)?;
                out.extend_from_slice(br#","text":"#);
                write_json_str(out, text)?;
            }
            crate::proof::Step::Absent { doubt: None } => {
                out.extend_from_slice(br#""absent""#);
            }
            crate::proof::Step::Absent { doubt: Some(q) } => {
                out.extend_from_slice(br#""absent","doubt":"#);
                serde_json::to_writer(&mut *out, &crate::belief::rounded(*q))?;
            }
            crate::proof::Step::Cut { reason } => {
                out.extend_from_slice(br#""cut","reason":"#);
                write_json_str(out, reason)?;
            }
        }
        out.push(b'}');
        if !n.premises.is_empty() {
            out.extend_from_slice(br#","premises":"#);
            write_nodes(out, &n.premises, last)?;
        }
        out.push(b'}');
    }
    out.push(b']');
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::ask::AskOptions;
    use crate::engine::Engine;
    use crate::kb::Observability;
    use crate::kb::{WindowKb, test_window};
    use logicpad::LogicPad;

    /// The built-in engine and a window of two vehicles (one a red moving
    /// car) and a pedestrian whose name needs escaping in JSON: the
    /// answers the JSON and Arrow renderings are tested on.
    pub(crate) fn cars() -> (Engine, WindowKb) {
        let e = Engine::new(LogicPad::builtin(), Observability::everything()).expect("engine");
        let kb = test_window(
            e.pad().program(),
            &[
                ("Vehicles", &["car_4"]),
                ("Vehicles", &["car_5"]),
                ("TypeOf", &["car_4", "Car"]),
                ("TypeOf", &["car_5", "Car"]),
                ("ColorOf", &["car_4", "Red"]),
                ("Moving", &["car_4"]),
                ("Pedestrian", &["ped_\"1\""]),
            ],
        );
        (e, kb)
    }

    /// What a batch line was before it was written by hand: serde's
    /// derived form of the answer with the two batch fields appended.
    #[derive(serde::Serialize)]
    struct Reference<'a> {
        #[serde(flatten)]
        result: &'a AskResult,
        query_index: usize,
        query_text: &'a str,
    }

    #[test]
    fn needs_escape_finds_every_escaped_byte_at_every_place() {
        // Around the byte: bytes just clear of each test, and high bytes.
        for fill in [b'a', b' ', b'!', b'#', b'[', b']', 0x80, 0xff] {
            for len in 0..20 {
                for at in 0..len {
                    for b in 0..=u8::MAX {
                        let mut s = vec![fill; len];
                        s[at] = b;
                        let slow = s.iter().any(|&c| c < 0x20 || c == b'"' || c == b'\\');
                        assert_eq!(
                            needs_escape(&s),
                            slow,
                            "{b:#x} at {at} of {len} in {fill:#x}"
                        );
                    }
                }
            }
        }
        assert!(!needs_escape(
            "Person(Pedestrian_2) ∀x : é ==> ¬".as_bytes()
        ));
    }

    #[test]
    fn a_batch_line_is_what_serde_writes() {
        let (e, kb) = cars();
        let small = AskOptions {
            limits: logicpad::Limits {
                answers: 1,
                ..logicpad::Limits::default()
            },
            ..AskOptions::default()
        };
        let cases = [
            (
                "Vehicles(x) ^ ¬SpeedUp(x) ^ ¬SpeedDown(x)",
                AskOptions::default(),
            ),
            ("TypeOf(x, Car) ^ ColorOf(x, Red)", AskOptions::default()),
            ("TypeOf(x, Car) ^ ColorOf(x, White)", AskOptions::default()),
            ("Pedestrian(x)", AskOptions::default()),
            ("Levitates(x)", AskOptions::default()),
            ("Vehicles(x) ^ Vehicles(y)", small),
            ("Moving(x)", AskOptions::BINDINGS),
        ];
        let mut seen_stopped = false;
        for (i, (q, opts)) in cases.into_iter().enumerate() {
            let p = e.prepare_query(q);
            let r = e.ask(&kb, &p, opts);
            seen_stopped |= r.stopped.is_some();
            let mut fast = Vec::new();
            write_batch_line(&mut fast, &r, i, q).expect("writes");
            let reference = serde_json::to_vec(&Reference {
                result: &r,
                query_index: i,
                query_text: q,
            })
            .expect("serialises");
            assert_eq!(
                String::from_utf8_lossy(&fast),
                String::from_utf8_lossy(&reference),
                "{q}"
            );
        }
        assert!(seen_stopped, "one case must exceed its answer budget");
    }

    /// Regression: a why-not's `uncertain` notes (on an uncertain source)
    /// were left out of batch lines, where serde writes them.
    #[test]
    fn a_batch_line_keeps_the_uncertain_notes_of_a_why_not() {
        let e = Engine::new(LogicPad::builtin(), Observability::everything()).expect("engine");
        let mut car = crate::kb::test_fact("TypeOf", &["car_1", "Car"], "measured");
        std::sync::Arc::make_mut(&mut car.provenance).probability = Some(0.8);
        let input = crate::kb::test_input(
            vec![crate::kb::test_fact("Vehicles", &["car_1"], ""), car],
            Vec::new(),
        );
        let kb = e.build(input).expect("builds");
        let q = "TypeOf(x, Car) ^ ColorOf(x, White)";
        let r = e.ask(&kb, &e.prepare_query(q), AskOptions::default());
        assert!(
            r.why_not.iter().any(|w| !w.uncertain.is_empty()),
            "{:?}",
            r.why_not
        );
        let mut fast = Vec::new();
        write_batch_line(&mut fast, &r, 0, q).expect("writes");
        let reference = serde_json::to_vec(&Reference {
            result: &r,
            query_index: 0,
            query_text: q,
        })
        .expect("serialises");
        assert_eq!(
            String::from_utf8_lossy(&fast),
            String::from_utf8_lossy(&reference)
        );
    }
}
