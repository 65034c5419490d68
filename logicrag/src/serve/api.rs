//! The web page and the JSON API: windows, answers, context, facts, the
//! scene (boxes and bird's-eye tracks) and frames as PNG.

use super::{ApiError, App, JsonBody, MAX_OFFSET, window_error};
use crate::ask::{AskOptions, AskResult};
use crate::engine::Prepared;
use axum::Router;
use axum::extract::rejection::QueryRejection;
use axum::extract::{Query, State};
use axum::http::{StatusCode, header};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::{get, post};
use serde::Deserialize;
use serde_json::{Value, json};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// The routes of this module.
pub(super) fn routes() -> Router<Arc<App>> {
    Router::new()
        .route("/", get(page))
        .route("/api/windows", get(windows))
        .route("/api/ask", post(ask))
        .route("/api/context", post(context))
        .route("/api/facts", get(facts))
        .route("/api/scene", get(scene))
        .route("/api/frame", get(frame))
        .route("/v1/retrieve", post(retrieve))
}

/// The page: HTML with its stylesheet and script inlined, so that it is one
/// request (behind a token, a browser would not send the token for a
/// `<script src>`) and needs no build step and no network.
fn page_html() -> &'static str {
    static PAGE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    PAGE.get_or_init(|| {
        include_str!("../../assets/index.html")
            .replace("/*APP_CSS*/", include_str!("../../assets/app.css"))
            .replace("/*APP_JS*/", include_str!("../../assets/app.js"))
    })
}

async fn page() -> Html<&'static str> {
    Html(page_html())
}

/// A query string, or 400 saying what is wrong with it.
fn query<T>(q: Result<Query<T>, QueryRejection>) -> Result<T, ApiError> {
    q.map(|Query(t)| t)
        .map_err(|e| ApiError::bad_request(format!("bad query string: {}", e.body_text())))
}

async fn windows(State(app): State<Arc<App>>) -> axum::Json<Value> {
    let s = &app.served;
    let list: Vec<Value> = app
        .all_windows()
        .iter()
        .map(|w| {
            // The frames of the window that have a picture: the page shows a
            // placeholder for the others instead of a broken image.
            let image_frames: Vec<u32> = s.images.as_ref().map_or_else(Vec::new, |i| {
                (w.first_frame..=w.last_frame)
                    .filter(|&f| i.get(f).is_some())
                    .collect()
            });
            json!({
                "id": w.id, "index": w.index, "first_frame": w.first_frame,
                "last_frame": w.last_frame, "objects": w.objects.len(), "facts": w.fact_count(),
                "image_frames": image_frames,
            })
        })
        .collect();
    axum::Json(json!({
        "source": app.pipeline().label(),
        "images": s.images.as_ref().is_some_and(|i| !i.is_empty()),
        "scene": s.scenes.is_some(),
        // Inputs the source skipped, counted with their reason (an AV2
        // log's EGO_VEHICLE rows): never dropped unseen.
        "skipped": s.scenes.as_ref().map_or(&[][..], |sc| sc.skipped()),
        "proxy": app.opts.proxy.is_some(),
        "windows": list,
    }))
}

/// `POST /api/ask` and `/api/context`: a question, and optionally one window.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct AskRequest {
    /// A question in English or a query.
    question: String,
    /// Only this window (default: every window).
    #[serde(default)]
    window: Option<String>,
    /// Bindings listed per window (default and most: the server's
    /// `--max-answers`).
    #[serde(default)]
    limit: Option<usize>,
    /// Bindings skipped per window before those listed (default 0).
    #[serde(default)]
    offset: Option<usize>,
}

pub(super) use crate::engine::Page;

/// The page a request asks for, checked against the server's limits.
pub(super) fn page_of(
    app: &App,
    limit: Option<usize>,
    offset: Option<usize>,
) -> Result<Page, ApiError> {
    let max = app.opts.max_answers;
    let limit = limit.unwrap_or(max);
    if limit == 0 || limit > max {
        return Err(ApiError::bad_request(format!(
            "`limit` must be 1 to {max} (this server's --max-answers)"
        )));
    }
    let offset = offset.unwrap_or(0);
    let furthest = MAX_OFFSET.max(max);
    if offset.saturating_add(limit) > furthest {
        return Err(ApiError::bad_request(format!(
            "`offset` + `limit` must be at most {furthest}: narrow the query instead"
        )));
    }
    Ok(Page { offset, limit })
}

/// Translates (or takes as written) a question under the server's
/// `--translator`; 400 when it cannot be translated, in the words `logicrag
/// ask` uses. An LLM translation takes one of the upstream permits (503
/// when none is free) so that a slow or hung LLM holds no more of the
/// server than the proxy may; an LLM that fails is 502.
pub(super) fn prepare(app: &App, text: &str) -> Result<Prepared, ApiError> {
    use crate::engine::PrepareError;
    use crate::llm::translate::LlmTranslateError;
    let text = text.trim();
    if text.is_empty() {
        return Err(ApiError::bad_request("the question is empty"));
    }
    let pipeline = app.pipeline();
    if let Some(prepared) = pipeline.prepare_offline(text) {
        return prepared.map_err(|e| ApiError::bad_request(e.to_string()));
    }
    let _permit = Arc::clone(&app.upstream)
        .try_acquire_owned()
        .map_err(|_| ApiError::unavailable("the LLM translator is busy; try again"))?;
    pipeline.prepare(text).map_err(|e| match &e {
        PrepareError::Llm(LlmTranslateError::Llm(_))
        | PrepareError::Neither {
            llm: LlmTranslateError::Llm(_),
            ..
        } => ApiError::new(StatusCode::BAD_GATEWAY, e.to_string()),
        _ => ApiError::bad_request(e.to_string()),
    })
}

/// How the server asks: everything `ask` shows, within its answer limit.
pub(super) fn ask_options(app: &App) -> AskOptions {
    let defaults = AskOptions::default();
    AskOptions {
        limits: logicpad::Limits {
            answers: app.opts.max_answers,
            time: Some(app.opts.max_query_time),
            ..defaults.limits
        },
        ..defaults
    }
}

/// The answers of `req` as `ask --json` prints them: one object per window
/// (`results`) and the summary object (`summary`), each window bounded
/// and paged ([`Engine::ask_page`] under the server's `--max-answers`),
/// a result whose bindings were cut marked `truncated`.
///
/// [`Engine::ask_page`]: crate::engine::Engine::ask_page
fn answer(app: &App, req: &AskRequest) -> Result<Value, ApiError> {
    let page = page_of(app, req.limit, req.offset)?;
    let p = prepare(app, &req.question)?;
    let pipeline = app.pipeline();
    let (results, cuts): (Vec<AskResult>, Vec<Option<Value>>) = pipeline
        .ask_page(&p, req.window.as_deref(), ask_options(app), page)
        .map_err(window_error)?
        .into_iter()
        .map(|a| {
            let cut = a.truncated.and_then(|c| serde_json::to_value(c).ok());
            (a.result, cut)
        })
        .unzip();
    let mut out = crate::json::ask_object(pipeline.engine().words(), &p, &results)
        .map_err(|e| ApiError::internal(e.to_string()))?;
    let mut any = false;
    if let Some(objects) = out.get_mut("results").and_then(Value::as_array_mut) {
        for (o, cut) in objects.iter_mut().zip(cuts) {
            if let (Some(o), Some(cut)) = (o.as_object_mut(), cut) {
                o.insert("truncated".into(), cut);
                any = true;
            }
        }
    }
    if any && let Some(o) = out.as_object_mut() {
        o.insert("truncated".into(), Value::Bool(true));
    }
    Ok(out)
}

async fn ask(
    State(app): State<Arc<App>>,
    JsonBody(req): JsonBody<AskRequest>,
) -> Result<axum::Json<Value>, ApiError> {
    let a = Arc::clone(&app);
    app.work(move || answer(&a, &req)).await.map(axum::Json)
}

async fn context(
    State(app): State<Arc<App>>,
    JsonBody(req): JsonBody<AskRequest>,
) -> Result<axum::Json<Value>, ApiError> {
    let a = Arc::clone(&app);
    app.work(move || {
        let page = page_of(&a, req.limit, req.offset)?;
        let p = prepare(&a, &req.question)?;
        let pipeline = a.pipeline();
        let contexts: Vec<crate::context::RagContext> = pipeline
            .ask_page(&p, req.window.as_deref(), ask_options(&a), page)
            .map_err(window_error)?
            .iter()
            .map(|answer| pipeline.context(answer.window, &p, &answer.result))
            .collect();
        Ok(axum::Json(json!({ "contexts": contexts })))
    })
    .await
}

#[derive(Debug, Deserialize)]
struct WindowQuery {
    window: String,
}

async fn facts(
    State(app): State<Arc<App>>,
    q: Result<Query<WindowQuery>, QueryRejection>,
) -> Result<axum::Json<Value>, ApiError> {
    let q = query(q)?;
    let w = app.window(&q.window)?;
    let place = crate::json::WindowPlace {
        id: &w.id,
        index: w.index,
        first_frame: w.first_frame,
        last_frame: w.last_frame,
    };
    crate::json::facts_object(app.pipeline().label(), place, w.facts(), true)
        .map(axum::Json)
        .map_err(|e| ApiError::internal(e.to_string()))
}

async fn scene(
    State(app): State<Arc<App>>,
    q: Result<Query<WindowQuery>, QueryRejection>,
) -> Result<axum::Json<crate::scene::SceneView>, ApiError> {
    let q = query(q)?;
    let w = app.window(&q.window)?;
    let Some(scenes) = &app.served.scenes else {
        return Err(ApiError::new(
            StatusCode::NOT_FOUND,
            format!(
                "{} has no tracks (a facts: source holds facts only)",
                app.pipeline().label()
            ),
        ));
    };
    Ok(axum::Json(scenes.window(
        &w.id,
        w.first_frame,
        w.last_frame,
    )))
}

/// The longest side of a frame served to the page, in pixels.
pub(super) const FRAME_MAX_SIDE: u32 = 960;

/// Frames already encoded, by frame number: the page shows the same few
/// frames again and again, and a simulated frame is ray-cast anew each
/// time it is asked for.
#[derive(Debug, Default)]
pub(super) struct FrameCache {
    pngs: Mutex<HashMap<u32, Arc<Vec<u8>>>>,
}

/// Frames kept in [`FrameCache`] (about 20 MB of PNG at most).
const FRAME_CACHE_SIZE: usize = 128;

impl FrameCache {
    fn get(&self, frame: u32) -> Option<Arc<Vec<u8>>> {
        let pngs = self.pngs.lock().unwrap_or_else(|e| e.into_inner());
        pngs.get(&frame).cloned()
    }

    fn put(&self, frame: u32, png: Arc<Vec<u8>>) {
        let mut pngs = self.pngs.lock().unwrap_or_else(|e| e.into_inner());
        // Forgetting everything at once keeps the cache bounded without
        // bookkeeping; the page asks again for what it shows.
        if pngs.len() >= FRAME_CACHE_SIZE {
            pngs.clear();
        }
        pngs.insert(frame, png);
    }
}

#[derive(Debug, Deserialize)]
struct FrameQuery {
    window: String,
    /// 0-based position of the frame in the window.
    index: u32,
}

async fn frame(
    State(app): State<Arc<App>>,
    q: Result<Query<FrameQuery>, QueryRejection>,
) -> Result<Response, ApiError> {
    let q = query(q)?;
    let w = app.window(&q.window)?;
    let span = w.last_frame - w.first_frame + 1;
    if q.index >= span {
        return Err(ApiError::bad_request(format!(
            "index {} is past window {}'s {span} frames (0–{})",
            q.index,
            w.id,
            span - 1
        )));
    }
    let frame = w.first_frame + q.index;
    let png = match app.frames.get(frame) {
        Some(png) => png,
        None => {
            let app2 = Arc::clone(&app);
            let png = app
                .work(move || {
                    let images = app2.served.images.as_ref().ok_or_else(|| {
                        ApiError::new(
                            StatusCode::NOT_FOUND,
                            format!("{} has no pictures", app2.pipeline().label()),
                        )
                    })?;
                    let picture = images.get(frame).ok_or_else(|| {
                        ApiError::new(
                            StatusCode::NOT_FOUND,
                            format!(
                                "{} has no picture of frame {frame}",
                                app2.pipeline().label()
                            ),
                        )
                    })?;
                    picture
                        .png(FRAME_MAX_SIDE)
                        .map(Arc::new)
                        .map_err(|e| ApiError::internal(e.to_string()))
                })
                .await?;
            app.frames.put(frame, Arc::clone(&png));
            png
        }
    };
    Ok((
        [
            (header::CONTENT_TYPE, "image/png"),
            (header::CACHE_CONTROL, "private, max-age=3600"),
        ],
        png.as_ref().clone(),
    )
        .into_response())
}

async fn retrieve(
    State(app): State<Arc<App>>,
    JsonBody(req): JsonBody<super::retrieve::RetrieveRequest>,
) -> Result<axum::Json<Value>, ApiError> {
    let a = Arc::clone(&app);
    app.work(move || {
        let page = page_of(&a, req.limit, req.offset)?;
        if req.k == Some(0) {
            return Err(ApiError::bad_request("`k` must be at least 1"));
        }
        let pipeline = a.pipeline();
        // An unknown window is 404 whatever the question.
        pipeline
            .check_window(req.window.as_deref())
            .map_err(window_error)?;
        // A retriever answers every question with documents, perhaps none:
        // a chain that asks something the grammar cannot read goes on
        // without Logic-RAG context, and the response says why.
        let p = match prepare(&a, &req.query) {
            Ok(p) if p.parsed.is_ok() => p,
            Ok(p) => {
                let why = p
                    .parsed
                    .as_ref()
                    .err()
                    .and_then(|d| d.first())
                    .map(|d| d.message.clone())
                    .unwrap_or_default();
                return Ok(axum::Json(json!({
                    "documents": [],
                    "note": format!("the question does not fit the LogicPad ({why}): no Logic-RAG documents"),
                })));
            }
            Err(e) => {
                return Ok(axum::Json(json!({
                    "documents": [],
                    "note": format!("{}: no Logic-RAG documents", e.message),
                })));
            }
        };
        let mut docs = super::retrieve::documents(
            pipeline,
            &p,
            req.window.as_deref(),
            ask_options(&a),
            page,
            req.limits(),
        )
        .map_err(window_error)?;
        if let Some(k) = req.k {
            docs.truncate(k);
        }
        Ok(axum::Json(json!({ "documents": docs })))
    })
    .await
}
