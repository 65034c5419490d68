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
//! first window (and a note says so). Earlier messages are forwarded as
//! given; the client's own image parts stay in the last message, after the
//! window's frames. Every other field the client sent (`temperature`,
//! `max_tokens`, `stop`, `stream`, …) is forwarded as given and nothing is
//! added, except `model` (the upstream's, from `--llm-model`).
//!
//! **The question** is found in the last user message's text by this rule:
//! a line that begins with `Question:` (any case) starts it, and it runs to
//! the first blank line or the next line that begins with a label such as
//! `Context:`; without such a line, a message of one paragraph of at most
//! [`MAX_BARE_QUESTION`] characters is the question. When none is found, or
//! it cannot be translated under C2, the request goes upstream unchanged
//! and `logicrag.context_added` is `false`, with a note saying why.
//!
//! **Streaming**: with `"stream": true` the answer comes as server-sent
//! events in OpenAI's wire format (`data: {chunk}` … `data: [DONE]`); the
//! upstream's own stream is forwarded when it streams, and its whole
//! answer is cut into chunks when it does not. The first chunk carries the
//! `logicrag` field.
//!
//! **Isolation**: at most [`ServeOptions::upstream_concurrency`] upstream
//! calls run at once (one more waits [`UPSTREAM_QUEUE_WAIT`], then 503),
//! each within [`ServeOptions::upstream_timeout`] (504), on threads of
//! their own, so that a hung upstream never starves `/api/*`. A streaming
//! call stops reading the upstream as soon as its client goes away.
//!
//! [`ServeOptions::upstream_concurrency`]: super::ServeOptions::upstream_concurrency
//! [`ServeOptions::upstream_timeout`]: super::ServeOptions::upstream_timeout
//! [`UPSTREAM_QUEUE_WAIT`]: super::UPSTREAM_QUEUE_WAIT

use super::api::{ask_options, prepare};
use super::{ApiError, App, JsonBody, UPSTREAM_QUEUE_WAIT};
use crate::ask::Outcome;
use crate::context::RagContext;
use crate::llm::Condition;
use axum::Router;
use axum::extract::State;
use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use serde::Deserialize;
use serde_json::{Map, Value, json};
use std::collections::HashMap;
use std::io::BufRead as _;
use std::sync::{Arc, Mutex};

/// The routes of this module.
pub(super) fn routes() -> Router<Arc<App>> {
    Router::new()
        .route("/v1/chat/completions", post(chat))
        .route("/v1/models", get(models))
}

/// An OpenAI chat request; fields not named here are forwarded upstream.
#[derive(Debug, Deserialize)]
struct ChatRequest {
    messages: Vec<Value>,
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

/// The longest message taken whole as the question when it has no
/// `Question:` line.
pub(super) const MAX_BARE_QUESTION: usize = 500;

/// A message's role and content, or 400.
fn role_content(m: &Value, i: usize) -> Result<(&str, &Value), ApiError> {
    let role = m
        .get("role")
        .and_then(Value::as_str)
        .ok_or_else(|| ApiError::bad_request(format!("messages[{i}] has no `role` string")))?;
    Ok((role, m.get("content").unwrap_or(&Value::Null)))
}

/// A message content's text (a string, or the text parts of a part list)
/// and its other parts (images), kept as the client sent them.
fn text_and_parts(content: &Value, i: usize) -> Result<(String, Vec<Value>), ApiError> {
    match content {
        Value::Null => Ok((String::new(), Vec::new())),
        Value::String(s) => Ok((s.clone(), Vec::new())),
        Value::Array(parts) => {
            let mut text = Vec::new();
            let mut other = Vec::new();
            for p in parts {
                match (
                    p.get("type").and_then(Value::as_str),
                    p.get("text").and_then(Value::as_str),
                ) {
                    (Some("text"), Some(t)) => text.push(t),
                    (Some(_), _) => other.push(p.clone()),
                    (None, _) => {
                        return Err(ApiError::bad_request(format!(
                            "messages[{i}] has a part without a `type`"
                        )));
                    }
                }
            }
            Ok((text.join("\n"), other))
        }
        _ => Err(ApiError::bad_request(format!(
            "messages[{i}].content must be a string or a list of parts"
        ))),
    }
}

/// Whether `line` begins with a label (`Context:`, `Answer:`, `Options:`):
/// a few words and a colon.
fn is_label(line: &str) -> bool {
    let Some((head, _)) = line.split_once(':') else {
        return false;
    };
    let head = head.trim();
    !head.is_empty()
        && head.len() <= 30
        && head.chars().next().is_some_and(char::is_alphabetic)
        && head
            .chars()
            .all(|c| c.is_alphanumeric() || c == ' ' || c == '_' || c == '-')
        && head.split_whitespace().count() <= 3
}

/// The question in a user message, by the rule in the module docs, and
/// how it was found.
pub(crate) fn find_question(text: &str) -> Option<(String, &'static str)> {
    let lines: Vec<&str> = text.lines().collect();
    for (i, line) in lines.iter().enumerate() {
        let t = line.trim_start();
        let Some(rest) = t
            .get(..9)
            .filter(|h| h.eq_ignore_ascii_case("question:"))
            .map(|_| &t[9..])
        else {
            continue;
        };
        let mut q = vec![rest.trim()];
        for next in &lines[i + 1..] {
            if next.trim().is_empty() || is_label(next.trim_start()) {
                break;
            }
            q.push(next.trim());
        }
        let q = q.join(" ").trim().to_string();
        if !q.is_empty() {
            return Some((q, "the line that begins with `Question:`"));
        }
    }
    let whole = text.trim();
    let one_paragraph = !whole.lines().any(|l| l.trim().is_empty());
    (!whole.is_empty() && one_paragraph && whole.chars().count() <= MAX_BARE_QUESTION).then(|| {
        (
            whole.split_whitespace().collect::<Vec<_>>().join(" "),
            "the whole message",
        )
    })
}

/// A window's frames as `data:` URLs, by window id and frame count.
type FrameUrls = HashMap<(String, usize), Arc<Vec<String>>>;

/// Rendered frames as `data:` URLs, by window and count.
#[derive(Debug, Default)]
pub(super) struct FramesCache {
    urls: Mutex<FrameUrls>,
}

/// Windows whose frames [`FramesCache`] keeps (five frames of about
/// 100 kB each per window).
const FRAMES_CACHE_WINDOWS: usize = 64;

impl FramesCache {
    /// The frames of `kb` for the proxy, rendered once.
    fn get(
        &self,
        app: &App,
        kb: &crate::kb::WindowKb,
        n: usize,
    ) -> Result<Arc<Vec<String>>, ApiError> {
        let key = (kb.id.clone(), n);
        if let Some(hit) = self
            .urls
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get(&key)
        {
            return Ok(Arc::clone(hit));
        }
        let pngs = match &app.served.images {
            Some(images) => images
                .pngs(
                    kb.first_frame,
                    kb.last_frame,
                    n,
                    crate::images::DEFAULT_MAX_SIDE,
                )
                .map_err(|e| ApiError::internal(e.to_string()))?,
            None => Vec::new(),
        };
        let urls: Arc<Vec<String>> = Arc::new(
            pngs.iter()
                .map(|p| format!("data:image/png;base64,{}", crate::llm::client::base64(p)))
                .collect(),
        );
        let mut cache = self.urls.lock().unwrap_or_else(|e| e.into_inner());
        // Forgetting everything at once keeps the cache bounded without
        // bookkeeping.
        if cache.len() >= FRAMES_CACHE_WINDOWS {
            cache.clear();
        }
        cache.insert(key, Arc::clone(&urls));
        Ok(urls)
    }
}

/// The upstream's models, as it lists them. When it cannot say (busy,
/// down, slow, or no model list), the model this proxy was configured
/// with, and `logicrag.upstream_models` says why: a client listing models
/// to pick one still gets the one that works.
async fn models(State(app): State<Arc<App>>) -> Result<axum::Json<Value>, ApiError> {
    let proxy = app.opts.proxy.clone().ok_or_else(not_enabled)?;
    let configured = proxy.lmm.chat.client.config().model.clone();
    let fallback = |why: String| {
        axum::Json(json!({
            "object": "list",
            "data": [{"id": configured, "object": "model", "owned_by": "logicrag"}],
            "logicrag": {"upstream_models": why},
        }))
    };
    let Ok(permit) = Arc::clone(&app.upstream).try_acquire_owned() else {
        return Ok(fallback("the upstream is busy".into()));
    };
    let client = proxy.lmm.chat.client.clone();
    let call = tokio::task::spawn_blocking(move || {
        let _permit = permit;
        client.models()
    });
    Ok(
        match tokio::time::timeout(app.opts.upstream_timeout, call).await {
            Ok(Ok(Ok(list))) => axum::Json(list),
            Ok(Ok(Err(e))) => fallback(e.to_string()),
            Ok(Err(e)) => fallback(e.to_string()),
            Err(_) => fallback(format!(
                "no answer within {} s",
                app.opts.upstream_timeout.as_secs_f64()
            )),
        },
    )
}

fn not_enabled() -> ApiError {
    ApiError::new(
        StatusCode::NOT_FOUND,
        "the Logic-RAG proxy is off: start `logicrag serve` with --llm URL (an OpenAI-compatible upstream)",
    )
}

/// The request to send upstream and what Logic-RAG added to it.
struct Built {
    body: Value,
    info: Value,
}

async fn chat(
    State(app): State<Arc<App>>,
    JsonBody(req): JsonBody<ChatRequest>,
) -> Result<Response, ApiError> {
    let Some(proxy) = app.opts.proxy.clone() else {
        return Err(not_enabled());
    };
    let stream = req.stream == Some(true);
    let a = Arc::clone(&app);
    let reasoning = app.work(move || build(&a, req));
    let built = tokio::time::timeout(app.opts.request_timeout, reasoning)
        .await
        .map_err(|_| {
            ApiError::new(
                StatusCode::SERVICE_UNAVAILABLE,
                "building the Logic-RAG context took longer than this server allows",
            )
        })??;
    let permit = tokio::time::timeout(
        UPSTREAM_QUEUE_WAIT,
        Arc::clone(&app.upstream).acquire_owned(),
    )
    .await
    .ok()
    .and_then(Result::ok)
    .ok_or_else(|| {
        ApiError::new(
            StatusCode::SERVICE_UNAVAILABLE,
            format!(
                "the upstream model is busy ({} calls in flight): try again later",
                app.opts.upstream_concurrency
            ),
        )
    })?;
    let limit = app.opts.upstream_timeout;
    let timed_out = || {
        ApiError::new(
            StatusCode::GATEWAY_TIMEOUT,
            format!(
                "the upstream model did not answer within {} s",
                limit.as_secs_f64()
            ),
        )
    };
    let client = proxy.lmm.chat.client;
    if stream {
        let (head_tx, head_rx) = tokio::sync::oneshot::channel();
        let (tx, rx) = tokio::sync::mpsc::channel::<Result<axum::body::Bytes, std::io::Error>>(32);
        tokio::task::spawn_blocking(move || {
            let _permit = permit;
            stream_upstream(&client, &built, head_tx, &tx);
        });
        let head = tokio::time::timeout(limit, head_rx)
            .await
            .map_err(|_| timed_out())?
            .map_err(|_| ApiError::internal("the upstream call failed"))?;
        head.map_err(|e| ApiError::new(StatusCode::BAD_GATEWAY, e.to_string()))?;
        let body = futures_util::stream::unfold(rx, |mut rx| async move {
            rx.recv().await.map(|chunk| (chunk, rx))
        });
        return Ok((
            [
                (header::CONTENT_TYPE, "text/event-stream"),
                (header::CACHE_CONTROL, "no-cache"),
            ],
            axum::body::Body::from_stream(body),
        )
            .into_response());
    }
    let call = tokio::task::spawn_blocking(move || {
        let _permit = permit;
        client.completion_body(&built.body).map(|c| (c, built.info))
    });
    let (mut completion, info) = tokio::time::timeout(limit, call)
        .await
        .map_err(|_| timed_out())?
        .map_err(|e| ApiError::internal(format!("the upstream call failed: {e}")))?
        .map_err(|e| ApiError::new(StatusCode::BAD_GATEWAY, e.to_string()))?;
    if let Some(obj) = completion.as_object_mut() {
        obj.insert("logicrag".into(), info);
    }
    Ok(axum::Json(completion).into_response())
}

/// One server-sent event.
fn event(data: &str) -> axum::body::Bytes {
    axum::body::Bytes::from(format!("data: {data}\n\n"))
}

/// Calls the upstream with `stream` as the client asked and feeds `tx`
/// with events: the upstream's own, or its whole answer cut into chunks.
/// `head` learns first whether the call succeeded. Stops as soon as the
/// client is gone (`tx` closed), which drops the upstream connection.
fn stream_upstream(
    client: &crate::llm::client::Client,
    built: &Built,
    head: tokio::sync::oneshot::Sender<Result<(), crate::llm::client::LlmError>>,
    tx: &tokio::sync::mpsc::Sender<Result<axum::body::Bytes, std::io::Error>>,
) {
    let resp = match client.post_streaming(&built.body) {
        Ok(r) => r,
        Err(e) => {
            let _ = head.send(Err(e));
            return;
        }
    };
    let _ = head.send(Ok(()));
    let is_sse = resp
        .headers()
        .get(reqwest::header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .is_some_and(|v| v.starts_with("text/event-stream"));
    let send = |b: axum::body::Bytes| tx.blocking_send(Ok(b)).is_ok();
    if !is_sse {
        let completion: Value = resp
            .text()
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or(Value::Null);
        for c in chunks_of(&completion, &built.info) {
            if !send(event(&c.to_string())) {
                return;
            }
        }
        let _ = send(event("[DONE]"));
        return;
    }
    let mut first = true;
    for line in std::io::BufReader::new(resp).lines() {
        let Ok(line) = line else { break };
        let Some(data) = line.strip_prefix("data:") else {
            continue;
        };
        let data = data.trim();
        if data == "[DONE]" {
            let _ = send(event("[DONE]"));
            return;
        }
        let out = if first {
            first = false;
            match serde_json::from_str::<Value>(data) {
                Ok(mut v) => {
                    if let Some(o) = v.as_object_mut() {
                        o.insert("logicrag".into(), built.info.clone());
                    }
                    v.to_string()
                }
                Err(_) => data.to_string(),
            }
        } else {
            data.to_string()
        };
        if !send(event(&out)) {
            return;
        }
    }
    let _ = send(event("[DONE]"));
}

/// A whole chat completion as stream chunks: the role and content, then
/// the finish reason (and usage, when the completion has it).
fn chunks_of(completion: &Value, info: &Value) -> Vec<Value> {
    let base = |choices: Value| {
        json!({
            "id": completion.get("id").cloned().unwrap_or(json!("chatcmpl-logicrag")),
            "object": "chat.completion.chunk",
            "created": completion.get("created").cloned().unwrap_or(json!(0)),
            "model": completion.get("model").cloned().unwrap_or(Value::Null),
            "choices": choices,
        })
    };
    let choice = completion.get("choices").and_then(|c| c.get(0));
    let message = choice.and_then(|c| c.get("message"));
    let content = message
        .and_then(|m| m.get("content"))
        .cloned()
        .unwrap_or(json!(""));
    let mut first = base(json!([{
        "index": 0, "delta": {"role": "assistant", "content": content}, "finish_reason": null,
    }]));
    if let Some(o) = first.as_object_mut() {
        o.insert("logicrag".into(), info.clone());
    }
    let finish = choice
        .and_then(|c| c.get("finish_reason"))
        .cloned()
        .unwrap_or(json!("stop"));
    let mut last = base(json!([{"index": 0, "delta": {}, "finish_reason": finish}]));
    if let (Some(o), Some(u)) = (last.as_object_mut(), completion.get("usage")) {
        o.insert("usage".into(), u.clone());
    }
    vec![first, last]
}

/// The upstream request body: the upstream's model, `messages`, and every
/// other field exactly as the client sent it.
fn upstream_body(
    app: &App,
    messages: Vec<Value>,
    req_stream: Option<bool>,
    rest: Map<String, Value>,
) -> Value {
    let model = app
        .opts
        .proxy
        .as_ref()
        .map(|p| p.lmm.chat.client.config().model.clone())
        .unwrap_or_default();
    let mut body = Map::new();
    body.insert("model".into(), json!(model));
    body.insert("messages".into(), Value::Array(messages));
    if let Some(s) = req_stream {
        body.insert("stream".into(), json!(s));
    }
    for (k, v) in rest {
        body.entry(k).or_insert(v);
    }
    Value::Object(body)
}

/// Builds the Logic-RAG request (or the client's own, unchanged, when no
/// question can be found or read) and what the response will say of it.
fn build(app: &App, req: ChatRequest) -> Result<Built, ApiError> {
    let proxy = app.opts.proxy.as_ref().ok_or_else(not_enabled)?;
    let opts = req.logicrag.unwrap_or_default();
    let condition = match &opts.condition {
        Some(c) => c.parse::<Condition>().map_err(ApiError::bad_request)?,
        None => Condition::C2,
    };
    let Some((last, earlier)) = req.messages.split_last() else {
        return Err(ApiError::bad_request("`messages` is empty"));
    };
    for (i, m) in earlier.iter().enumerate() {
        role_content(m, i)?;
    }
    let (role, content) = role_content(last, earlier.len())?;
    if role != "user" {
        return Err(ApiError::bad_request(format!(
            "the last message must be the user's question, not a `{role}` message"
        )));
    }
    let (text, client_parts) = text_and_parts(content, earlier.len())?;
    if text.trim().is_empty() && client_parts.is_empty() {
        return Err(ApiError::bad_request("the last user message has no text"));
    }
    let candidates = app.windows(opts.window.as_deref())?;
    let unchanged = |notes: Vec<String>| Built {
        body: upstream_body(app, req.messages.clone(), req.stream, req.rest.clone()),
        info: json!({
            "context_added": false,
            "window": null, "condition": null, "question": null, "query": null, "answer": null,
            "notes": notes,
        }),
    };
    let Some((question, how)) = find_question(&text) else {
        return Ok(unchanged(vec![format!(
            "no question found in the last user message (no line begins with `Question:` and it is not one paragraph of at most {MAX_BARE_QUESTION} characters): it went upstream unchanged, without Logic-RAG context"
        )]));
    };
    let pipeline = app.pipeline();
    let mut notes: Vec<String> = Vec::new();
    if how != "the whole message" {
        notes.push(format!("the question was taken from {how}"));
    }
    let prepared = match prepare(app, &question) {
        Ok(p) if p.parsed.is_ok() => Ok(p),
        Ok(p) => Err(format!("the query `{}` does not fit the LogicPad", p.query)),
        Err(e) => Err(e.message),
    };
    let prepared = match prepared {
        Ok(p) => Some(p),
        // C2 needs a proved answer, and without a query no window can be
        // chosen: never a silent fallback to another condition or window.
        Err(why) if condition == Condition::C2 || opts.window.is_none() => {
            notes.push(format!(
                "{why}: the request went upstream unchanged, without Logic-RAG context"
            ));
            let mut b = unchanged(notes);
            if let Some(o) = b.info.as_object_mut() {
                o.insert("question".into(), json!(question));
            }
            return Ok(b);
        }
        Err(why) => {
            notes.push(why);
            None
        }
    };
    let mut chosen = None;
    if let Some(p) = &prepared {
        for kb in &candidates {
            let r = pipeline.ask_window(kb, p, ask_options(app));
            let yes = r.answer == Outcome::Yes;
            if chosen.is_none() || yes {
                chosen = Some((*kb, Some(r)));
            }
            if yes {
                break;
            }
        }
        if opts.window.is_none()
            && let Some((kb, Some(r))) = &chosen
            && r.answer != Outcome::Yes
        {
            notes.push(format!(
                "no window says yes: window {} (the first) was used; name one with logicrag.window",
                kb.id
            ));
        }
    } else {
        chosen = candidates.first().map(|kb| (*kb, None));
    }
    let Some((kb, result)) = chosen else {
        return Err(ApiError::bad_request(format!(
            "{} has no windows",
            pipeline.label()
        )));
    };
    let ctx = match (&prepared, &result) {
        (Some(p), Some(r)) => pipeline.context(kb, p, r),
        _ => RagContext {
            window: kb.id.clone(),
            question: Some(question.clone()),
            query: String::new(),
            c2: Vec::new(),
            c3: crate::context::fact_sentences_with(kb, pipeline.engine().words()),
        },
    };
    let frames = app.proxy_frames.get(app, kb, proxy.frames)?;
    let prompt = proxy.lmm.prompt(condition, &question, &ctx, frames.len());
    // As `llm::user_message` lays it out: the pictures, then the text;
    // the client's own pictures follow the window's.
    let mut parts: Vec<Value> = frames
        .iter()
        .map(|url| json!({"type": "image_url", "image_url": {"url": url}}))
        .collect();
    parts.extend(client_parts.iter().cloned());
    parts.push(json!({"type": "text", "text": prompt}));
    let mut messages: Vec<Value> = earlier.to_vec();
    messages.push(if parts.len() == 1 {
        json!({"role": "user", "content": prompt})
    } else {
        json!({"role": "user", "content": parts})
    });
    Ok(Built {
        body: upstream_body(app, messages, req.stream, req.rest),
        info: json!({
            "context_added": true,
            "window": kb.id,
            "frames": [kb.first_frame, kb.last_frame],
            "images": frames.len(),
            "client_images": client_parts.len(),
            "condition": condition,
            "question": question,
            "query": prepared.as_ref().map(|p| p.query.clone()),
            "answer": result.as_ref().map(|r| r.answer),
            "notes": notes,
        }),
    })
}
