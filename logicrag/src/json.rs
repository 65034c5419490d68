//! The JSON objects the command line prints and the server answers with,
//! built in one place so that `ask --json`, `facts --json` and the HTTP API
//! can never drift apart: a per-window answer object
//! ([`answer_object`]), the closing summary object ([`summary_object`]) and
//! a window's facts with provenance ([`facts_object`]).

use crate::ask::AskResult;
use crate::engine::{Prepared, Summary};
use crate::kb::FactRef;
use crate::llm::LmmAnswer;
use serde_json::{Value, json};

/// One window's answer as `ask --json` prints it: the [`AskResult`]'s
/// fields, plus `"question"` when the text was an English question and
/// `"lmm"` when a multimodal model was asked too.
pub fn answer_object(
    r: &AskResult,
    p: &Prepared,
    lmm: Option<&LmmAnswer>,
) -> Result<Value, serde_json::Error> {
    let mut v = serde_json::to_value(r)?;
    if let Some(obj) = v.as_object_mut() {
        if let Some(q) = &p.question {
            obj.insert("question".into(), json!(q));
        }
        if let Some(l) = lmm {
            obj.insert("lmm".into(), serde_json::to_value(l)?);
        }
    }
    Ok(v)
}

/// The summary object `ask --json` prints after the windows: the overall
/// answer, its one-line headline, the question, the query as run and the
/// translator's notes.
pub fn summary_object(summary: &Summary, p: &Prepared) -> Value {
    json!({
        "summary": summary,
        "headline": summary.headline(),
        "question": p.question,
        "query": p.query,
        "notes": p.notes,
    })
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
