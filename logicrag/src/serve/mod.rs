//! `logicrag serve`: a source's windows, reasoned once at start, served from
//! memory over HTTP — a self-contained web page (`GET /`), a JSON API
//! (`/api/…`), a LangChain-style retriever (`POST /v1/retrieve`) and an
//! OpenAI-compatible Logic-RAG proxy (`POST /v1/chat/completions`). Every
//! answer comes from the same [`Pipeline`] and the same JSON objects
//! ([`crate::json`]) as the command line, so the page, the API and
//! `ask --json` can never disagree.
//!
//! Main types: [`Served`] (what is served: the pipeline — engine,
//! translator, reasoned windows — and the windows' scenes and frames), [`ServeOptions`] (token, body limit,
//! proxy), [`router`] (the routes, for embedding in another axum app) and
//! [`run`] (bind and serve until Ctrl-C).
//!
//! Safety rules, each enforced here rather than left to the caller:
//! - a non-loopback address needs a token ([`ServeError::TokenRequired`]);
//!   with a token every request must carry it, as `Authorization: Bearer`
//!   or (for the page and its pictures, which a browser fetches without
//!   headers) the RFC 6750 `access_token` query parameter, compared in
//!   constant time;
//! - request bodies are limited ([`ServeOptions::max_body_bytes`]: 413,
//!   before the body when its length is announced);
//! - answers are bounded: the engine stops one binding past
//!   [`ServeOptions::max_answers`] and within
//!   [`ServeOptions::max_query_time`], and the response lists a page
//!   marked `truncated`;
//! - connections are bounded: a header-read timeout that also ends idle
//!   keep-alive connections, a cap on connections and on requests
//!   reasoning at once, a request deadline, and a shutdown with a grace
//!   period (`run_until`);
//! - the `Host` header must name this server (421: DNS rebinding), and a
//!   request other than GET/HEAD must not be cross-site (403) and must
//!   send JSON (415);
//! - upstream model calls have their own bounded pool and deadline, so a
//!   hung upstream never starves the API;
//! - a request names windows by id and frames by index, never by path, so
//!   nothing outside the loaded source can be read;
//! - a malformed request gets 400 and a JSON error, never a panic.

mod api;
mod proxy;
pub mod retrieve;

use crate::images::FrameImages;
use crate::kb::WindowKb;
use crate::pipeline::Pipeline;
use crate::scene::Scenes;
use axum::Router;
use axum::extract::{DefaultBodyLimit, FromRequest, Request, State};
use axum::http::{HeaderValue, Method, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use serde_json::json;
use std::collections::HashMap;
use std::net::{IpAddr, SocketAddr};
use std::sync::Arc;
use std::time::Duration;
use tokio::sync::Semaphore;

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
    /// Occurs when the pipeline's windows cannot be reasoned.
    #[error(transparent)]
    Reason(#[from] crate::session::SessionError),
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
    /// Every answer comes from it: the source's label, the engine, the
    /// translator (`--translator`, `--llm`) and the windows, reasoned
    /// before the server answers.
    pub pipeline: Pipeline,
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

/// How to serve. Every limit is named here, with its default below, so
/// that the command line, the docs and the tests speak of the same ones.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    /// The bearer token every request must carry (`None`: no token).
    pub token: Option<String>,
    /// The largest request body accepted, in bytes.
    pub max_body_bytes: usize,
    /// The most bindings one window's answer may have before it is cut to
    /// a page (`limit`/`offset`) and marked `truncated`; the engine stops
    /// looking at one more than this, so it bounds work and memory too.
    pub max_answers: usize,
    /// The most time one window's query may take in the engine.
    pub max_query_time: Duration,
    /// The most time a request may take, from its headers to its answer
    /// (the proxy has [`ServeOptions::upstream_timeout`] instead): 503
    /// past it.
    pub request_timeout: Duration,
    /// The most time a client may take to send a request's headers, and
    /// the most time a kept-alive connection may sit idle: closed past it.
    pub header_timeout: Duration,
    /// The most connections served at once; more wait in the listen
    /// queue until one closes.
    pub max_connections: usize,
    /// The most requests reasoning (or rendering) at once; more wait, up
    /// to their request timeout.
    pub max_busy: usize,
    /// How long Ctrl-C waits for requests in flight before the server
    /// stops whatever the clients do.
    pub shutdown_grace: Duration,
    /// The most time an upstream model call may take (504 past it).
    pub upstream_timeout: Duration,
    /// The most upstream calls at once; one more waits
    /// `UPSTREAM_QUEUE_WAIT`, then gets 503.
    pub upstream_concurrency: usize,
    /// Host names accepted in the `Host` header besides the localhost
    /// names and the bound address (`*`: any). Anything else gets 421,
    /// which stops DNS rebinding.
    pub allowed_hosts: Vec<String>,
    /// The upstream model for `/v1/chat/completions` (`None`: that route
    /// answers 404 with a message saying how to enable it).
    pub proxy: Option<Proxy>,
}

/// The default body limit: a question is a few hundred bytes and a chat
/// request with a long history a few tens of kilobytes.
pub const DEFAULT_MAX_BODY_BYTES: usize = 256 * 1024;
/// Bindings per window in one response by default: far below the
/// command line's [`logicpad::DEFAULT_MAX_ANSWERS`], since a server's
/// answers are held in memory and sent over the network.
pub const DEFAULT_MAX_ANSWERS: usize = 1000;
/// The furthest page a client may ask for: `offset + limit` beyond it is
/// refused (each page is found again from the start).
pub(crate) const MAX_OFFSET: usize = 100_000;
/// Default of [`ServeOptions::max_query_time`].
pub const DEFAULT_MAX_QUERY_TIME: Duration = Duration::from_secs(5);
/// Default of [`ServeOptions::request_timeout`].
pub const DEFAULT_REQUEST_TIMEOUT: Duration = Duration::from_secs(30);
/// Default of [`ServeOptions::header_timeout`].
pub const DEFAULT_HEADER_TIMEOUT: Duration = Duration::from_secs(5);
/// Default of [`ServeOptions::max_connections`]: well under the usual
/// 1,024 open files.
pub const DEFAULT_MAX_CONNECTIONS: usize = 512;
/// Default of [`ServeOptions::shutdown_grace`].
pub const DEFAULT_SHUTDOWN_GRACE: Duration = Duration::from_secs(5);
/// Default of [`ServeOptions::upstream_timeout`].
pub const DEFAULT_UPSTREAM_TIMEOUT: Duration = Duration::from_secs(120);
/// Default of [`ServeOptions::upstream_concurrency`].
pub const DEFAULT_UPSTREAM_CONCURRENCY: usize = 8;
/// How long a proxy call waits for a free upstream slot before 503.
pub(crate) const UPSTREAM_QUEUE_WAIT: Duration = Duration::from_secs(1);

/// Default of [`ServeOptions::max_busy`]: two per core, so that a slow
/// request does not idle a core, and few enough that the memory of the
/// requests in flight stays small.
pub(crate) fn default_max_busy() -> usize {
    std::thread::available_parallelism().map_or(4, |n| 2 * n.get())
}

impl Default for ServeOptions {
    fn default() -> Self {
        ServeOptions {
            token: None,
            max_body_bytes: DEFAULT_MAX_BODY_BYTES,
            max_answers: DEFAULT_MAX_ANSWERS,
            max_query_time: DEFAULT_MAX_QUERY_TIME,
            request_timeout: DEFAULT_REQUEST_TIMEOUT,
            header_timeout: DEFAULT_HEADER_TIMEOUT,
            max_connections: DEFAULT_MAX_CONNECTIONS,
            max_busy: default_max_busy(),
            shutdown_grace: DEFAULT_SHUTDOWN_GRACE,
            upstream_timeout: DEFAULT_UPSTREAM_TIMEOUT,
            upstream_concurrency: DEFAULT_UPSTREAM_CONCURRENCY,
            allowed_hosts: Vec::new(),
            proxy: None,
        }
    }
}

/// The server's shared state.
struct App {
    served: Served,
    /// SHA-256 of the token: requests are compared digest to digest, so
    /// the comparison's time says nothing about the token.
    token_digest: Option<[u8; 32]>,
    opts: ServeOptions,
    frames: api::FrameCache,
    /// The proxy's rendered frames, by window: rendering and encoding five
    /// frames cost more than the rest of a proxied request.
    proxy_frames: proxy::FramesCache,
    /// Host names accepted in the `Host` header (lower case; `*`: any).
    hosts: Vec<String>,
    /// Permits for reasoning and rendering ([`ServeOptions::max_busy`]).
    busy: Arc<Semaphore>,
    /// Permits for upstream calls ([`ServeOptions::upstream_concurrency`]).
    upstream: Arc<Semaphore>,
}

impl App {
    /// The pipeline every answer comes from.
    fn pipeline(&self) -> &Pipeline {
        &self.served.pipeline
    }

    /// Every window, reasoned ([`router`] reasons them before serving).
    fn all_windows(&self) -> &[WindowKb] {
        self.pipeline().reasoned_windows().unwrap_or_default()
    }

    /// The window named `id`.
    fn window(&self, id: &str) -> Result<&WindowKb, ApiError> {
        self.pipeline().window(id).map_err(window_error)
    }

    /// The windows a request asks about: the one it names, or all.
    fn windows(&self, id: Option<&str>) -> Result<Vec<&WindowKb>, ApiError> {
        self.pipeline().select(id).map_err(window_error)
    }
}

/// A pipeline's error about the window a request names: 404 for an
/// unknown one, in the words every front end uses.
pub(crate) fn window_error(e: crate::session::SessionError) -> ApiError {
    match e {
        crate::session::SessionError::UnknownWindow(no) => ApiError::new(
            StatusCode::NOT_FOUND,
            format!("{no}; GET /api/windows lists them"),
        ),
        other => ApiError::internal(other.to_string()),
    }
}

/// The most characters of a client's text that an error message repeats.
pub(crate) const MAX_ECHO_CHARS: usize = 80;

/// `text`, cut to `max` characters with `…` when longer.
pub(crate) fn clip(text: &str, max: usize) -> String {
    match text.char_indices().nth(max) {
        Some((i, _)) => format!("{}… ({} bytes)", &text[..i], text.len()),
        None => text.to_string(),
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

    fn unavailable(message: impl Into<String>) -> ApiError {
        ApiError::new(StatusCode::SERVICE_UNAVAILABLE, message)
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
            StatusCode::FORBIDDEN | StatusCode::MISDIRECTED_REQUEST => "permission_error",
            s if s.is_client_error() => "invalid_request_error",
            StatusCode::BAD_GATEWAY | StatusCode::GATEWAY_TIMEOUT => "upstream_error",
            StatusCode::SERVICE_UNAVAILABLE => "overloaded_error",
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
/// parsed (400 with serde's message, line and column, when malformed).
/// Its content type was checked by [`guard`] before the body was read.
pub(crate) struct JsonBody<T>(T);

impl<S: Send + Sync, T: serde::de::DeserializeOwned> FromRequest<S> for JsonBody<T> {
    type Rejection = ApiError;

    async fn from_request(req: Request, state: &S) -> Result<Self, Self::Rejection> {
        let bytes = axum::body::Bytes::from_request(req, state)
            .await
            .map_err(|r| {
                let status = r.status();
                if status == StatusCode::PAYLOAD_TOO_LARGE {
                    too_large()
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

/// The host part of a `Host` header or an origin's authority, lower case,
/// without port or trailing dot (`[::1]` keeps its brackets).
fn host_name(authority: &str) -> String {
    let a = authority.trim().to_ascii_lowercase();
    let host = if a.starts_with('[') {
        match a.find(']') {
            Some(i) => a[..=i].to_string(),
            None => a,
        }
    } else {
        a.split(':').next().unwrap_or_default().to_string()
    };
    host.trim_end_matches('.').to_string()
}

/// The host names a server accepts: the localhost names, the address it is
/// bound to and the configured ones.
fn allowed_hosts(opts: &ServeOptions, bound: Option<IpAddr>) -> Vec<String> {
    let mut hosts: Vec<String> = ["localhost", "127.0.0.1", "[::1]"]
        .iter()
        .map(|h| h.to_string())
        .collect();
    if let Some(ip) = bound {
        hosts.push(match ip {
            IpAddr::V4(v4) => v4.to_string(),
            IpAddr::V6(v6) => format!("[{v6}]"),
        });
    }
    hosts.extend(opts.allowed_hosts.iter().map(|h| host_name(h)));
    hosts.sort();
    hosts.dedup();
    hosts
}

/// Whether `host` (from [`host_name`]) is one the server accepts. Names
/// under `.localhost` are loopback by definition (RFC 6761).
fn host_allowed(hosts: &[String], host: &str) -> bool {
    host.ends_with(".localhost") || hosts.iter().any(|h| h == "*" || h == host)
}

/// Whether `ct` is a JSON media type (`application/json`, with parameters).
fn is_json(ct: &str) -> bool {
    let essence = ct.split(';').next().unwrap_or_default().trim();
    essence.eq_ignore_ascii_case("application/json")
}

/// Checks that come before the token and before any body is read:
/// - the `Host` header names this server (421 otherwise: DNS rebinding
///   makes a browser send an attacker's name to a loopback server);
/// - a request that changes or spends something (not GET/HEAD) is not
///   cross-site: its `Origin`, when sent, is the server's own and its
///   `Sec-Fetch-Site` is `same-origin` or `none` (403 otherwise);
/// - a POST body is `application/json` (415 otherwise: a cross-site page
///   can only send form and text types without a preflight);
/// - an announced `Content-Length` past the body limit is refused at once
///   (413), so a client that sent `Expect: 100-continue` sends nothing.
async fn guard(State(app): State<Arc<App>>, req: Request, next: Next) -> Response {
    let headers = req.headers();
    let host = headers
        .get(header::HOST)
        .and_then(|v| v.to_str().ok())
        .map(str::to_string)
        .or_else(|| req.uri().authority().map(|a| a.to_string()));
    let Some(host) = host else {
        return ApiError::new(
            StatusCode::MISDIRECTED_REQUEST,
            "the request has no Host header",
        )
        .into_response();
    };
    if !host_allowed(&app.hosts, &host_name(&host)) {
        return ApiError::new(
            StatusCode::MISDIRECTED_REQUEST,
            format!(
                "this server does not answer for host `{}` (it answers for {}; start it with --allow-host NAME to add one)",
                clip(&host, MAX_ECHO_CHARS),
                app.hosts.join(", ")
            ),
        )
        .into_response();
    }
    let method = req.method();
    if method != Method::GET && method != Method::HEAD {
        if let Some(origin) = headers.get(header::ORIGIN) {
            let origin = origin.to_str().unwrap_or_default();
            let authority = origin
                .split_once("://")
                .map(|(_, a)| a.trim_end_matches('/'))
                .unwrap_or_default();
            if !authority.eq_ignore_ascii_case(host.trim()) {
                return ApiError::new(
                    StatusCode::FORBIDDEN,
                    format!(
                        "cross-site request refused: Origin `{}` is not this server ({host})",
                        clip(origin, MAX_ECHO_CHARS)
                    ),
                )
                .into_response();
            }
        }
        if let Some(site) = headers.get("sec-fetch-site") {
            let site = site.to_str().unwrap_or_default();
            if !(site.eq_ignore_ascii_case("same-origin") || site.eq_ignore_ascii_case("none")) {
                return ApiError::new(
                    StatusCode::FORBIDDEN,
                    format!(
                        "cross-site request refused (Sec-Fetch-Site: {})",
                        clip(site, MAX_ECHO_CHARS)
                    ),
                )
                .into_response();
            }
        }
    }
    if method == Method::POST {
        let ct = headers
            .get(header::CONTENT_TYPE)
            .and_then(|v| v.to_str().ok())
            .unwrap_or_default();
        if !is_json(ct) {
            return ApiError::new(
                StatusCode::UNSUPPORTED_MEDIA_TYPE,
                format!(
                    "the body must be JSON sent as `Content-Type: application/json`, not `{}`",
                    clip(ct, MAX_ECHO_CHARS)
                ),
            )
            .into_response();
        }
    }
    let announced = headers
        .get(header::CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.trim().parse::<u64>().ok());
    if announced.is_some_and(|n| n > app.opts.max_body_bytes as u64) {
        return too_large().into_response();
    }
    next.run(req).await
}

/// 413, in the words of every body limit.
fn too_large() -> ApiError {
    ApiError::new(
        StatusCode::PAYLOAD_TOO_LARGE,
        "the request body is larger than this server accepts",
    )
}

/// Ends a request that takes longer than [`ServeOptions::request_timeout`]
/// with 503 (the proxy has its own, longer, upstream deadline).
async fn deadline(State(app): State<Arc<App>>, req: Request, next: Next) -> Response {
    if req.uri().path() == "/v1/chat/completions" {
        return next.run(req).await;
    }
    let limit = app.opts.request_timeout;
    match tokio::time::timeout(limit, next.run(req)).await {
        Ok(resp) => resp,
        Err(_) => ApiError::new(
            StatusCode::SERVICE_UNAVAILABLE,
            format!(
                "the request took longer than this server allows ({} s)",
                limit.as_secs_f64()
            ),
        )
        .into_response(),
    }
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
/// The `Host` header may name localhost or [`ServeOptions::allowed_hosts`]
/// ([`run`] adds the address it binds).
pub fn router(served: Served, opts: ServeOptions) -> Result<Router, ServeError> {
    router_for(served, opts, None)
}

fn router_for(
    served: Served,
    opts: ServeOptions,
    bound: Option<IpAddr>,
) -> Result<Router, ServeError> {
    if let Some(t) = &opts.token {
        check_token(t)?;
    }
    // Reasoned now, not on the first request: a request never waits for
    // every window, and the windows stay reasoned for the server's life.
    served.pipeline.kbs()?;
    let limit = opts.max_body_bytes;
    let app = Arc::new(App {
        token_digest: opts.token.as_deref().map(digest),
        hosts: allowed_hosts(&opts, bound),
        busy: Arc::new(Semaphore::new(opts.max_busy.max(1))),
        upstream: Arc::new(Semaphore::new(opts.upstream_concurrency.max(1))),
        served,
        opts,
        frames: api::FrameCache::default(),
        proxy_frames: proxy::FramesCache::default(),
    });
    Ok(api::routes()
        .merge(proxy::routes())
        .fallback(|| async {
            ApiError::new(
                StatusCode::NOT_FOUND,
                "no such endpoint (see docs/serve.md)",
            )
        })
        .method_not_allowed_fallback(|method: Method| async move {
            ApiError::new(
                StatusCode::METHOD_NOT_ALLOWED,
                format!("{method} is not allowed on this endpoint (see docs/serve.md)"),
            )
        })
        .layer(DefaultBodyLimit::max(limit))
        .layer(axum::middleware::from_fn_with_state(
            Arc::clone(&app),
            deadline,
        ))
        .layer(axum::middleware::from_fn_with_state(Arc::clone(&app), auth))
        .layer(axum::middleware::from_fn_with_state(
            Arc::clone(&app),
            guard,
        ))
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
    run_until(served, opts, addr, on_bound, async {
        // Without a signal handler the server runs until killed, which is
        // what a failed install of the handler leaves.
        if tokio::signal::ctrl_c().await.is_err() {
            std::future::pending::<()>().await;
        }
    })
}

/// [`run`], stopping when `stop` completes instead of on Ctrl-C: no new
/// connection is taken, idle ones close, and requests in flight get
/// [`ServeOptions::shutdown_grace`] to finish before every connection is
/// dropped.
pub(crate) fn run_until(
    served: Served,
    opts: ServeOptions,
    addr: SocketAddr,
    on_bound: impl FnOnce(SocketAddr),
    stop: impl Future<Output = ()> + Send,
) -> Result<(), ServeError> {
    if !addr.ip().is_loopback() && opts.token.is_none() {
        return Err(ServeError::TokenRequired { addr });
    }
    let io = |source| ServeError::Io {
        addr: addr.to_string(),
        source,
    };
    let conns = ConnLimits {
        header_timeout: opts.header_timeout,
        max_connections: opts.max_connections.max(1),
        grace: opts.shutdown_grace,
    };
    let app = router_for(served, opts, Some(addr.ip()))?;
    let rt = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(io)?;
    let served = rt.block_on(async move {
        let listener = tokio::net::TcpListener::bind(addr).await.map_err(io)?;
        on_bound(listener.local_addr().map_err(io)?);
        accept_loop(listener, app, conns, stop).await;
        Ok(())
    });
    // Work still running on blocking threads (a query, an upstream call)
    // is not waited for past the grace period.
    rt.shutdown_timeout(conns.grace);
    served
}

/// What [`accept_loop`] enforces on connections.
#[derive(Debug, Clone, Copy)]
struct ConnLimits {
    header_timeout: Duration,
    max_connections: usize,
    grace: Duration,
}

/// Takes connections until `stop`, each served by hyper with a
/// header-read timeout that also bounds keep-alive idleness (hyper starts
/// it whenever it waits for a request's head), at most `max_connections`
/// at once. `axum::serve` offers neither, nor a bound on shutdown.
async fn accept_loop(
    listener: tokio::net::TcpListener,
    app: Router,
    limits: ConnLimits,
    stop: impl Future<Output = ()> + Send,
) {
    use hyper_util::rt::{TokioIo, TokioTimer};
    let slots = Arc::new(Semaphore::new(limits.max_connections));
    let (closing, closed) = tokio::sync::watch::channel(false);
    let mut tasks = tokio::task::JoinSet::new();
    tokio::pin!(stop);
    loop {
        let permit = tokio::select! {
            p = Arc::clone(&slots).acquire_owned() => match p {
                Ok(p) => p,
                Err(_) => break,
            },
            () = &mut stop => break,
        };
        let stream = tokio::select! {
            r = listener.accept() => match r {
                Ok((s, _)) => s,
                Err(_) => {
                    // Out of file descriptors or a connection reset before
                    // it was taken: wait a little rather than spin.
                    tokio::time::sleep(Duration::from_millis(50)).await;
                    continue;
                }
            },
            () = &mut stop => break,
        };
        // Reap finished connections so the set does not grow.
        while tasks.try_join_next().is_some() {}
        let service = hyper_util::service::TowerToHyperService::new(app.clone());
        let mut closed = closed.clone();
        tasks.spawn(async move {
            let _permit = permit;
            let mut builder = hyper::server::conn::http1::Builder::new();
            builder
                .timer(TokioTimer::new())
                .header_read_timeout(limits.header_timeout)
                .keep_alive(true);
            let conn = builder.serve_connection(TokioIo::new(stream), service);
            tokio::pin!(conn);
            tokio::select! {
                _ = conn.as_mut() => {}
                _ = closed.changed() => {
                    conn.as_mut().graceful_shutdown();
                    let _ = conn.await;
                }
            }
        });
    }
    drop(listener);
    let _ = closing.send(true);
    let drain = async { while tasks.join_next().await.is_some() {} };
    if tokio::time::timeout(limits.grace, drain).await.is_err() {
        tasks.abort_all();
    }
}

impl App {
    /// Runs blocking work (reasoning, rendering) off the async workers, so
    /// that one slow request does not stall the others, and at most
    /// [`ServeOptions::max_busy`] at once, so that memory stays bounded
    /// under load; a request waiting for its turn is ended by its
    /// deadline.
    async fn work<T: Send + 'static>(
        &self,
        f: impl FnOnce() -> Result<T, ApiError> + Send + 'static,
    ) -> Result<T, ApiError> {
        let permit = Arc::clone(&self.busy)
            .acquire_owned()
            .await
            .map_err(|e| ApiError::internal(format!("the server is stopping: {e}")))?;
        tokio::task::spawn_blocking(move || {
            let _permit = permit;
            f()
        })
        .await
        .map_err(|e| ApiError::internal(format!("the request's worker failed: {e}")))?
    }
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

    fn braking() -> Pipeline {
        Pipeline::open_default("sim:braking")
    }

    /// A pipeline given unreasoned is reasoned before the routes answer.
    #[test]
    fn the_router_reasons_the_windows_first() {
        let served = Served {
            pipeline: braking(),
            scenes: None,
            images: None,
        };
        assert!(served.pipeline.reasoned_windows().is_none());
        let app = router(served, ServeOptions::default());
        assert!(app.is_ok());
    }

    /// An unknown window is 404 in the pipeline's words, and how to list
    /// the windows.
    #[test]
    fn an_unknown_window_is_404_in_the_pipelines_words() {
        let pipeline = braking();
        let want = pipeline.no_window("nope").to_string();
        let e = window_error(pipeline.window("nope").expect_err("unknown"));
        assert_eq!(e.status, StatusCode::NOT_FOUND);
        assert_eq!(e.message, format!("{want}; GET /api/windows lists them"));
    }
}
