//! The web page and the JSON API: windows, answers, context, facts, the
//! scene (boxes and bird's-eye tracks) and frames as PNG.

use super::{ApiError, App, JsonBody, blocking};
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
    let list: Vec<Value> = s
        .windows
        .iter()
        .map(|w| {
            json!({
                "id": w.id, "index": w.index, "first_frame": w.first_frame,
                "last_frame": w.last_frame, "objects": w.objects.len(), "facts": w.fact_count(),
            })
        })
        .collect();
    axum::Json(json!({
        "source": s.label,
        "images": s.images.as_ref().is_some_and(|i| !i.is_empty()),
        "scene": s.scenes.is_some(),
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
}

/// Translates (or takes as written) a question; 400 when the grammar
/// cannot read it, in the words `logicrag ask` uses.
pub(super) fn prepare(app: &App, text: &str) -> Result<Prepared, ApiError> {
    let text = text.trim();
    if text.is_empty() {
        return Err(ApiError::bad_request("the question is empty"));
    }
    app.served
        .engine
        .prepare(text)
        .map_err(|e| ApiError::bad_request(format!("cannot translate the question: {e}")))
}

/// How the server asks: everything `ask` shows, within its answer limit.
pub(super) fn ask_options(app: &App) -> AskOptions {
    AskOptions {
        max_answers: app.opts.max_answers,
        ..AskOptions::default()
    }
}

/// The answers of `req` as `ask --json` prints them: one object per window
/// (`results`) and the summary object (`summary`).
fn answer(app: &App, req: &AskRequest) -> Result<Value, ApiError> {
    let p = prepare(app, &req.question)?;
    let engine = &app.served.engine;
    let results: Vec<AskResult> = app
        .windows(req.window.as_deref())?
        .into_iter()
        .map(|kb| engine.ask(kb, &p, ask_options(app)))
        .collect();
    crate::json::ask_object(engine.words(), &p, &results)
        .map_err(|e| ApiError::internal(e.to_string()))
}

async fn ask(
    State(app): State<Arc<App>>,
    JsonBody(req): JsonBody<AskRequest>,
) -> Result<axum::Json<Value>, ApiError> {
    blocking(move || answer(&app, &req)).await.map(axum::Json)
}

async fn context(
    State(app): State<Arc<App>>,
    JsonBody(req): JsonBody<AskRequest>,
) -> Result<axum::Json<Value>, ApiError> {
    blocking(move || {
        let p = prepare(&app, &req.question)?;
        let engine = &app.served.engine;
        let contexts: Vec<crate::context::RagContext> = app
            .windows(req.window.as_deref())?
            .into_iter()
            .map(|kb| engine.context(kb, &p, &engine.ask(kb, &p, ask_options(&app))))
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
    crate::json::facts_object(&app.served.label, place, w.facts(), true)
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
                app.served.label
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
pub const FRAME_MAX_SIDE: u32 = 960;

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
            let png = blocking(move || {
                let images = app2.served.images.as_ref().ok_or_else(|| {
                    ApiError::new(
                        StatusCode::NOT_FOUND,
                        format!("{} has no pictures", app2.served.label),
                    )
                })?;
                let picture = images.get(frame).ok_or_else(|| {
                    ApiError::new(
                        StatusCode::NOT_FOUND,
                        format!("{} has no picture of frame {frame}", app2.served.label),
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
    blocking(move || {
        let p = prepare(&app, &req.query)?;
        let windows = app.windows(req.window.as_deref())?;
        let docs = super::retrieve::documents(
            &app.served.engine,
            &app.served.label,
            &windows,
            &p,
            ask_options(&app),
            req.limits(),
        );
        Ok(axum::Json(json!({ "documents": docs })))
    })
    .await
}
