//! `POST /v1/chat/completions`: an OpenAI-compatible Logic-RAG proxy. A
//! chat request whose last message is the user's question goes to the
//! upstream model with the window's frames and the Logic-RAG context of the
//! paper's condition (C2 by default: the proved answer, its bindings and
//! proof; C3: the window's facts; C1: the frames alone), and the upstream's
//! chat completion comes back as it was sent, plus a `logicrag` field that
//! says which window, condition and logic answer were used. An OpenAI
//! client needs only its base URL changed (`…/v1`).
//!
//! The request may carry `"logicrag": {"window": ID, "condition": "c2"}`;
//! without a window, the first window whose answer is yes is used, else the
//! first window. Earlier messages are forwarded as text; other request
//! fields (`temperature`, `max_tokens`, `stop`, …) are forwarded as given,
//! except `model` (the upstream's, from `--llm-model`) and `stream`
//! (refused: the answer comes whole).

use super::api::{ask_options, prepare};
use super::{ApiError, App, JsonBody, blocking};
use crate::ask::Outcome;
use crate::context::RagContext;
use crate::llm::Condition;
use crate::llm::client::Message;
use axum::Router;
use axum::extract::State;
use axum::http::StatusCode;
use axum::routing::{get, post};
use serde::Deserialize;
use serde_json::{Map, Value, json};
use std::sync::Arc;

/// The routes of this module.
pub(super) fn routes() -> Router<Arc<App>> {
    Router::new()
        .route("/v1/chat/completions", post(chat))
        .route("/v1/models", get(models))
}

/// An OpenAI chat request; fields not named here are forwarded upstream.
#[derive(Debug, Deserialize)]
struct ChatRequest {
    messages: Vec<ChatMessage>,
    #[serde(default)]
    logicrag: Option<LogicragOptions>,
    #[serde(default)]
    stream: Option<bool>,
    /// The caller's model name; the upstream's own is sent instead (an
    /// OpenAI client sends its default, e.g. `gpt-3.5-turbo`).
    #[serde(default)]
    #[allow(dead_code)]
    model: Option<Value>,
    #[serde(flatten)]
    rest: Map<String, Value>,
}

/// The request's `logicrag` field.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct LogicragOptions {
    /// The window asked about.
    #[serde(default)]
    window: Option<String>,
    /// `c1`, `c2` (default) or `c3`.
    #[serde(default)]
    condition: Option<String>,
}

#[derive(Debug, Deserialize)]
struct ChatMessage {
    role: String,
    #[serde(default)]
    content: Value,
}

/// A message's text: a string, or the text parts of a part list. Images
/// from the caller are refused rather than dropped: the proxy attaches the
/// window's own frames.
fn message_text(m: &ChatMessage, i: usize) -> Result<String, ApiError> {
    match &m.content {
        Value::Null => Ok(String::new()),
        Value::String(s) => Ok(s.clone()),
        Value::Array(parts) => {
            let mut text = Vec::new();
            for p in parts {
                match (
                    p.get("type").and_then(Value::as_str),
                    p.get("text").and_then(Value::as_str),
                ) {
                    (Some("text"), Some(t)) => text.push(t),
                    (kind, _) => {
                        return Err(ApiError::bad_request(format!(
                            "messages[{i}] has a `{}` part: only text parts are accepted (the proxy attaches the window's frames itself)",
                            kind.unwrap_or("untyped")
                        )));
                    }
                }
            }
            Ok(text.join("\n"))
        }
        _ => Err(ApiError::bad_request(format!(
            "messages[{i}].content must be a string or a list of parts"
        ))),
    }
}

async fn models(State(app): State<Arc<App>>) -> Result<axum::Json<Value>, ApiError> {
    let proxy = app.opts.proxy.as_ref().ok_or_else(not_enabled)?;
    Ok(axum::Json(json!({
        "object": "list",
        "data": [{"id": proxy.lmm.chat.client.config().model, "object": "model", "owned_by": "logicrag"}],
    })))
}

fn not_enabled() -> ApiError {
    ApiError::new(
        StatusCode::NOT_FOUND,
        "the Logic-RAG proxy is off: start `logicrag serve` with --llm URL (an OpenAI-compatible upstream)",
    )
}

async fn chat(
    State(app): State<Arc<App>>,
    JsonBody(req): JsonBody<ChatRequest>,
) -> Result<axum::Json<Value>, ApiError> {
    if app.opts.proxy.is_none() {
        return Err(not_enabled());
    }
    blocking(move || complete(&app, req)).await.map(axum::Json)
}

/// Builds the Logic-RAG request, sends it upstream and returns the
/// upstream's completion with the `logicrag` field added.
fn complete(app: &App, req: ChatRequest) -> Result<Value, ApiError> {
    let proxy = app.opts.proxy.as_ref().ok_or_else(not_enabled)?;
    if req.stream == Some(true) {
        return Err(ApiError::bad_request(
            "`stream: true` is not supported: the proxy returns the whole answer",
        ));
    }
    let opts = req.logicrag.unwrap_or_default();
    let mut condition = match &opts.condition {
        Some(c) => c.parse::<Condition>().map_err(ApiError::bad_request)?,
        None => Condition::C2,
    };
    let Some((last, earlier)) = req.messages.split_last() else {
        return Err(ApiError::bad_request("`messages` is empty"));
    };
    if last.role != "user" {
        return Err(ApiError::bad_request(format!(
            "the last message must be the user's question, not a `{}` message",
            last.role
        )));
    }
    let question = message_text(last, earlier.len())?.trim().to_string();
    if question.is_empty() {
        return Err(ApiError::bad_request("the last user message has no text"));
    }
    let mut messages: Vec<Message> = Vec::with_capacity(req.messages.len());
    for (i, m) in earlier.iter().enumerate() {
        messages.push(Message::text(&m.role, message_text(m, i)?));
    }
    let engine = &app.served.engine;
    let mut notes: Vec<String> = Vec::new();
    // A question the grammar cannot read has no proved answer, but its
    // window's facts (C3) still need no query: say so rather than fail a
    // chat that any model could answer.
    let prepared = match prepare(app, &question) {
        Ok(p) => Some(p),
        Err(e) if condition != Condition::C2 => {
            notes.push(e.message);
            None
        }
        Err(e) => {
            notes.push(format!(
                "{}; answered under C3 (the window's facts) instead of C2",
                e.message
            ));
            condition = Condition::C3;
            None
        }
    };
    let candidates = app.windows(opts.window.as_deref())?;
    let mut chosen = None;
    if let Some(p) = &prepared {
        for kb in &candidates {
            let r = engine.ask(kb, p, ask_options(app));
            let yes = r.answer == Outcome::Yes;
            if chosen.is_none() || yes {
                chosen = Some((*kb, Some(r)));
            }
            if yes {
                break;
            }
        }
    } else {
        chosen = candidates.first().map(|kb| (*kb, None));
    }
    let Some((kb, result)) = chosen else {
        return Err(ApiError::bad_request(format!(
            "{} has no windows",
            app.served.label
        )));
    };
    let ctx = match (&prepared, &result) {
        (Some(p), Some(r)) => engine.context(kb, p, r),
        _ => RagContext {
            window: kb.id.clone(),
            question: Some(question.clone()),
            query: String::new(),
            c2: Vec::new(),
            c3: crate::context::fact_sentences_with(kb, engine.words()),
        },
    };
    let pngs = match &app.served.images {
        Some(images) => images
            .pngs(
                kb.first_frame,
                kb.last_frame,
                proxy.frames,
                crate::images::DEFAULT_MAX_SIDE,
            )
            .map_err(|e| ApiError::internal(e.to_string()))?,
        None => Vec::new(),
    };
    let prompt = proxy.lmm.prompt(condition, &question, &ctx, pngs.len());
    messages.push(crate::llm::user_message(&prompt, &pngs));
    let mut completion = proxy
        .lmm
        .chat
        .client
        .completion(&messages, &req.rest)
        .map_err(|e| ApiError::new(StatusCode::BAD_GATEWAY, e.to_string()))?;
    if let Some(obj) = completion.as_object_mut() {
        obj.insert(
            "logicrag".into(),
            json!({
                "window": kb.id,
                "frames": [kb.first_frame, kb.last_frame],
                "images": pngs.len(),
                "condition": condition,
                "question": question,
                "query": prepared.as_ref().map(|p| p.query.clone()),
                "answer": result.as_ref().map(|r| r.answer),
                "notes": notes,
            }),
        );
    }
    Ok(completion)
}
