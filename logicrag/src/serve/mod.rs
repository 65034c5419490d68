//! `logicrag serve`: a source's windows, reasoned once at start, served from
//! memory over HTTP — a self-contained web page (`GET /`), a JSON API
//! (`/api/…`), a LangChain-style retriever (`POST /v1/retrieve`) and an
//! OpenAI-compatible Logic-RAG proxy (`POST /v1/chat/completions`). Every
//! answer comes from the same [`Engine`] and the same JSON objects
//! ([`crate::json`]) as the command line, so the page, the API and
//! `ask --json` can never disagree.
//!
//! Main types: [`Served`] (what is served: the engine, the reasoned
//! windows, their scenes and frames), [`ServeOptions`] (token, body limit,
//! proxy), [`router`] (the routes, for embedding in another axum app) and
//! [`run`] (bind and serve until Ctrl-C).
//!
//! Safety rules, each enforced here rather than left to the caller:
//! - a non-loopback address needs a token ([`ServeError::TokenRequired`]);
//!   with a token every request must carry it, as `Authorization: Bearer`
//!   or (for the page and its pictures, which a browser fetches without
//!   headers) the RFC 6750 `access_token` query parameter, compared in
//!   constant time;
//! - request bodies are limited ([`ServeOptions::max_body_bytes`]: 413);
//! - a request names windows by id and frames by index, never by path, so
//!   nothing outside the loaded source can be read;
//! - a malformed request gets 400 and a JSON error, never a panic.

mod api;
mod proxy;
pub mod retrieve;

use crate::engine::Engine;
use crate::images::FrameImages;
use crate::kb::WindowKb;
use crate::scene::Scenes;
use axum::Router;
use axum::extract::{DefaultBodyLimit, FromRequest, Request, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use serde_json::json;
use std::collections::HashMap;
use std::net::SocketAddr;
use std::sync::Arc;

/// Errors that keep the server from starting or running.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// Occurs when a non-loopback address is asked for without a token:
    /// anyone on the network could read the data and spend the model.
    #[error(
        "{addr} is not a loopback address: give --token TOKEN (every request must then carry it), or serve on 127.0.0.1"
    )]
    TokenRequired {
        /// The address asked for.
        addr: SocketAddr,
    },
    /// Occurs when the token is empty or not printable ASCII (it must fit
    /// an `Authorization` header).
    #[error("the token must be 1 to 256 printable ASCII characters without spaces")]
    BadToken,
    /// Occurs when the address cannot be bound or serving fails.
    #[error("serving on {addr}: {source}")]
    Io {
        /// The address.
        addr: String,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
}

/// What the server serves, built once at start.
///
/// Invariant: window ids are unique (the server looks windows up by id).
#[derive(Debug)]
pub struct Served {
    /// The source's label (`sim:urban_crossing`, `kitti:0000`).
    pub label: String,
    /// The engine every answer comes from.
    pub engine: Engine,
    /// The reasoned windows, in source order.
    pub windows: Vec<WindowKb>,
    /// Tracks and ego-motion, for sources with a sequence (not `facts:`).
    pub scenes: Option<Scenes>,
    /// The frames as pictures, where the source has them.
    pub images: Option<FrameImages>,
}

/// The Logic-RAG proxy's upstream: a multimodal model and its prompts.
#[derive(Debug, Clone)]
pub struct Proxy {
    /// The upstream chat server and the condition templates (its cache is
    /// not used: a proxy answers live).
    pub lmm: crate::llm::Lmm,
    /// Frames attached per request, sampled evenly over the window.
    pub frames: usize,
}

/// How to serve.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    /// The bearer token every request must carry (`None`: no token).
    pub token: Option<String>,
    /// The largest request body accepted, in bytes.
    pub max_body_bytes: usize,
    /// The most bindings one query may have (as `ask --max-answers`).
    pub max_answers: usize,
    /// The upstream model for `/v1/chat/completions` (`None`: that route
    /// answers 404 with a message saying how to enable it).
    pub proxy: Option<Proxy>,
}

/// The default body limit: a question is a few hundred bytes and a chat
/// request with a long history a few tens of kilobytes.
pub const DEFAULT_MAX_BODY_BYTES: usize = 256 * 1024;

impl Default for ServeOptions {
    fn default() -> Self {
        ServeOptions {
            token: None,
            max_body_bytes: DEFAULT_MAX_BODY_BYTES,
            max_answers: logicpad::DEFAULT_MAX_ANSWERS,
            proxy: None,
        }
    }
}

/// The server's shared state.
struct App {
    served: Served,
    by_id: HashMap<String, usize>,
    /// SHA-256 of the token: requests are compared digest to digest, so
    /// the comparison's time says nothing about the token.
    token_digest: Option<[u8; 32]>,
    opts: ServeOptions,
    frames: api::FrameCache,
}

impl App {
    /// The window named `id`.
    fn window(&self, id: &str) -> Result<&WindowKb, ApiError> {
        self.by_id
            .get(id)
            .and_then(|&i| self.served.windows.get(i))
            .ok_or_else(|| {
                let known: Vec<&str> = self
                    .served
                    .windows
                    .iter()
                    .take(3)
                    .map(|w| w.id.as_str())
                    .collect();
                ApiError::new(
                    StatusCode::NOT_FOUND,
                    format!(
                        "{} has no window `{id}` (GET /api/windows lists them: {}, …)",
                        self.served.label,
                        known.join(", ")
                    ),
                )
            })
    }

    /// The windows a request asks about: the one it names, or all.
    fn windows(&self, id: Option<&str>) -> Result<Vec<&WindowKb>, ApiError> {
        match id {
            Some(id) => Ok(vec![self.window(id)?]),
            None => Ok(self.served.windows.iter().collect()),
        }
    }
}

/// An error answered as JSON in the OpenAI shape
/// (`{"error": {"message", "type", "code"}}`), which OpenAI clients read.
#[derive(Debug)]
pub(crate) struct ApiError {
    status: StatusCode,
    message: String,
}

impl ApiError {
    fn new(status: StatusCode, message: impl Into<String>) -> ApiError {
        ApiError {
            status,
            message: message.into(),
        }
    }

    fn bad_request(message: impl Into<String>) -> ApiError {
        ApiError::new(StatusCode::BAD_REQUEST, message)
    }

    fn internal(message: impl Into<String>) -> ApiError {
        ApiError::new(StatusCode::INTERNAL_SERVER_ERROR, message)
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let kind = match self.status {
            StatusCode::UNAUTHORIZED => "authentication_error",
            StatusCode::NOT_FOUND => "not_found_error",
            StatusCode::PAYLOAD_TOO_LARGE => "request_too_large",
            s if s.is_client_error() => "invalid_request_error",
            StatusCode::BAD_GATEWAY => "upstream_error",
            _ => "server_error",
        };
        let body = json!({"error": {
            "message": self.message,
            "type": kind,
            "code": self.status.as_u16(),
        }});
        let mut resp = (self.status, axum::Json(body)).into_response();
        if self.status == StatusCode::UNAUTHORIZED {
            resp.headers_mut().insert(
                header::WWW_AUTHENTICATE,
                HeaderValue::from_static("Bearer realm=\"logicrag\""),
            );
        }
        resp
    }
}

/// A JSON request body: read within the body limit (413 past it) and
/// parsed (400 with serde's message, line and column, when malformed). Any
/// content type is accepted: `curl -d` sends a form type for JSON text.
pub(crate) struct JsonBody<T>(T);

impl<S: Send + Sync, T: serde::de::DeserializeOwned> FromRequest<S> for JsonBody<T> {
    type Rejection = ApiError;

    async fn from_request(req: Request, state: &S) -> Result<Self, Self::Rejection> {
        let bytes = axum::body::Bytes::from_request(req, state)
            .await
            .map_err(|r| {
                let status = r.status();
                if status == StatusCode::PAYLOAD_TOO_LARGE {
                    ApiError::new(
                        status,
                        "the request body is larger than this server accepts",
                    )
                } else {
                    ApiError::new(status, r.body_text())
                }
            })?;
        if bytes.is_empty() {
            return Err(ApiError::bad_request(
                "the request has no body: expected a JSON object",
            ));
        }
        serde_json::from_slice(&bytes)
            .map(JsonBody)
            .map_err(|e| ApiError::bad_request(format!("the body is not the JSON expected: {e}")))
    }
}

/// SHA-256 of a token.
fn digest(token: &str) -> [u8; 32] {
    use sha2::Digest as _;
    sha2::Sha256::digest(token.as_bytes()).into()
}

/// Equality of two digests in time independent of where they differ.
fn same_digest(a: &[u8; 32], b: &[u8; 32]) -> bool {
    a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
}

/// The token a request carries: `Authorization: Bearer T`, else the
/// `access_token` query parameter (RFC 6750 §2.3).
fn request_token(req: &Request) -> Option<String> {
    let header = req
        .headers()
        .get(header::AUTHORIZATION)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| {
            let (scheme, token) = v.trim().split_once(' ')?;
            scheme
                .eq_ignore_ascii_case("bearer")
                .then(|| token.trim().to_string())
        });
    header.or_else(|| {
        axum::extract::Query::<HashMap<String, String>>::try_from_uri(req.uri())
            .ok()
            .and_then(|q| q.0.get("access_token").cloned())
    })
}

/// Refuses a request without the server's token (when it has one).
async fn auth(State(app): State<Arc<App>>, req: Request, next: Next) -> Response {
    if let Some(want) = &app.token_digest {
        let ok = request_token(&req).is_some_and(|t| same_digest(&digest(&t), want));
        if !ok {
            return ApiError::new(
                StatusCode::UNAUTHORIZED,
                "this server needs its token: send `Authorization: Bearer TOKEN` (or ?access_token=TOKEN for the page)",
            )
            .into_response();
        }
    }
    next.run(req).await
}

/// Checks a token's form; see [`ServeError::BadToken`].
fn check_token(token: &str) -> Result<(), ServeError> {
    let ok = !token.is_empty() && token.len() <= 256 && token.bytes().all(|b| b.is_ascii_graphic());
    if ok {
        Ok(())
    } else {
        Err(ServeError::BadToken)
    }
}

/// The routes over `served`, with the token check and the body limit.
pub fn router(served: Served, opts: ServeOptions) -> Result<Router, ServeError> {
    if let Some(t) = &opts.token {
        check_token(t)?;
    }
    let by_id = served
        .windows
        .iter()
        .enumerate()
        .map(|(i, w)| (w.id.clone(), i))
        .collect();
    let limit = opts.max_body_bytes;
    let app = Arc::new(App {
        token_digest: opts.token.as_deref().map(digest),
        served,
        by_id,
        opts,
        frames: api::FrameCache::default(),
    });
    Ok(api::routes()
        .merge(proxy::routes())
        .fallback(|| async {
            ApiError::new(
                StatusCode::NOT_FOUND,
                "no such endpoint (see docs/serve.md)",
            )
        })
        .layer(DefaultBodyLimit::max(limit))
        .layer(axum::middleware::from_fn_with_state(Arc::clone(&app), auth))
        .with_state(app))
}

/// Serves `served` on `addr` until Ctrl-C; `on_bound` is told the bound
/// address (port 0 picks a free port) before the first request is taken.
/// A non-loopback address without a token is refused.
pub fn run(
    served: Served,
    opts: ServeOptions,
    addr: SocketAddr,
    on_bound: impl FnOnce(SocketAddr),
) -> Result<(), ServeError> {
    if !addr.ip().is_loopback() && opts.token.is_none() {
        return Err(ServeError::TokenRequired { addr });
    }
    let io = |source| ServeError::Io {
        addr: addr.to_string(),
        source,
    };
    let app = router(served, opts)?;
    let rt = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(io)?;
    rt.block_on(async move {
        let listener = tokio::net::TcpListener::bind(addr).await.map_err(io)?;
        on_bound(listener.local_addr().map_err(io)?);
        axum::serve(listener, app)
            .with_graceful_shutdown(async {
                // Without a signal handler the server runs until killed,
                // which is what a failed install of the handler leaves.
                if tokio::signal::ctrl_c().await.is_err() {
                    std::future::pending::<()>().await;
                }
            })
            .await
            .map_err(io)
    })
}

/// Runs blocking work (reasoning, rendering, the upstream model) off the
/// async workers, so one slow request does not stall the others.
async fn blocking<T: Send + 'static>(
    f: impl FnOnce() -> Result<T, ApiError> + Send + 'static,
) -> Result<T, ApiError> {
    tokio::task::spawn_blocking(f)
        .await
        .map_err(|e| ApiError::internal(format!("the request's worker failed: {e}")))?
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digests_compare_equal_only_for_the_same_token() {
        let a = digest("s3cret");
        assert!(same_digest(&a, &digest("s3cret")));
        assert!(!same_digest(&a, &digest("s3cret ")));
        assert!(!same_digest(&a, &digest("")));
    }

    #[test]
    fn tokens_must_fit_a_header() {
        assert!(check_token("abc-123_XYZ").is_ok());
        for bad in ["", "has space", "tab\t", "é", &"x".repeat(257)] {
            assert!(check_token(bad).is_err(), "{bad:?}");
        }
    }
}
