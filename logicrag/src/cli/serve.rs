//! `logicrag serve`: loads a source, reasons every window once (with a
//! progress bar) and serves the page, the JSON API, the retriever and —
//! with `--llm` — the OpenAI-compatible Logic-RAG proxy from memory
//! (`logicrag::serve`; endpoints in docs/serve.md).

use super::SourceArgs;
use anyhow::{Result, bail};
use clap::Args;
use logicrag::serve::{
    DEFAULT_HEADER_TIMEOUT, DEFAULT_MAX_ANSWERS, DEFAULT_MAX_BODY_BYTES, DEFAULT_MAX_CONNECTIONS,
    DEFAULT_MAX_QUERY_TIME, DEFAULT_REQUEST_TIMEOUT, DEFAULT_SHUTDOWN_GRACE,
    DEFAULT_UPSTREAM_CONCURRENCY, DEFAULT_UPSTREAM_TIMEOUT, Proxy, ServeError, ServeOptions,
    Served,
};
use std::io::Write as _;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::process::ExitCode;
use std::time::Duration;

#[derive(Args)]
pub struct ServeArgs {
    #[command(flatten)]
    pub src: SourceArgs,
    /// Address to listen on: an IP address or `localhost` (127.0.0.1);
    /// anything but loopback needs --token.
    #[arg(long, default_value = "127.0.0.1")]
    pub host: String,
    /// Port to listen on (0: any free port; the address is printed).
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// Bearer token every request must carry (default:
    /// $LOGICRAG_SERVE_TOKEN). Required off loopback. The page takes it
    /// as /?access_token=TOKEN.
    #[arg(long)]
    pub token: Option<String>,
    /// Largest request body accepted, in bytes.
    #[arg(long = "max-body", default_value_t = DEFAULT_MAX_BODY_BYTES)]
    pub max_body: usize,
    /// The most bindings one window's answer lists; past it the engine
    /// stops, the answer lists a page (`limit`/`offset` in the request) and
    /// says `truncated`.
    #[arg(long = "max-answers", default_value_t = DEFAULT_MAX_ANSWERS)]
    pub max_answers: usize,
    /// The most seconds one window's query may take in the engine.
    #[arg(long = "query-time", default_value_t = DEFAULT_MAX_QUERY_TIME.as_secs_f64())]
    pub query_time: f64,
    /// The most seconds a request may take (503 past it; the proxy has
    /// --upstream-timeout).
    #[arg(long = "request-timeout", default_value_t = DEFAULT_REQUEST_TIMEOUT.as_secs_f64())]
    pub request_timeout: f64,
    /// The most seconds a client may take to send a request's headers,
    /// and a kept-alive connection may sit idle, before it is closed.
    #[arg(long = "header-timeout", default_value_t = DEFAULT_HEADER_TIMEOUT.as_secs_f64())]
    pub header_timeout: f64,
    /// The most connections served at once (more wait to be taken).
    #[arg(long = "max-connections", default_value_t = DEFAULT_MAX_CONNECTIONS)]
    pub max_connections: usize,
    /// Seconds Ctrl-C waits for requests in flight before stopping anyway.
    #[arg(long = "shutdown-grace", default_value_t = DEFAULT_SHUTDOWN_GRACE.as_secs_f64())]
    pub shutdown_grace: f64,
    /// Another host name the Host header may carry besides localhost and
    /// the bound address (repeatable; `*`: any). Others get 421, which
    /// stops DNS rebinding.
    #[arg(long = "allow-host")]
    pub allow_host: Vec<String>,
    /// Upstream OpenAI-compatible server for /v1/chat/completions, e.g.
    /// http://127.0.0.1:8081/v1 (the key comes from $LOGICRAG_API_KEY or
    /// $OPENAI_API_KEY). Without it the proxy is off.
    #[arg(long)]
    pub llm: Option<String>,
    /// Upstream model name (default: $LOGICRAG_LLM_MODEL, else "default").
    #[arg(long = "llm-model", requires = "llm")]
    pub llm_model: Option<String>,
    /// Question → query: the grammar, the --llm server, or the grammar then
    /// the LLM for the questions the grammar refuses.
    #[arg(long, value_enum, default_value = "grammar")]
    pub translator: super::TranslatorMode,
    /// Repair rounds for an LLM query the LogicPad rejects.
    #[arg(long = "llm-repairs", default_value_t = 2)]
    pub llm_repairs: u32,
    /// Frames attached to each proxied question, sampled evenly over the window.
    #[arg(long = "lmm-frames", default_value_t = 5)]
    pub lmm_frames: usize,
    /// The most seconds an upstream call may take (504 past it).
    #[arg(long = "upstream-timeout", default_value_t = DEFAULT_UPSTREAM_TIMEOUT.as_secs_f64())]
    pub upstream_timeout: f64,
    /// The most upstream calls at once (one more gets 503 after 1 s).
    #[arg(long = "upstream-concurrency", default_value_t = DEFAULT_UPSTREAM_CONCURRENCY)]
    pub upstream_concurrency: usize,
}

/// `--host`: an IP address, or `localhost`.
fn host_ip(host: &str) -> Result<IpAddr> {
    if host.eq_ignore_ascii_case("localhost") {
        return Ok(IpAddr::V4(Ipv4Addr::LOCALHOST));
    }
    host.trim_start_matches('[')
        .trim_end_matches(']')
        .parse()
        .map_err(|_| {
            anyhow::anyhow!(
                "--host {host}: give an IP address (127.0.0.1, ::1, 0.0.0.0) or `localhost`"
            )
        })
}

/// A duration flag in seconds: positive and finite.
fn seconds(flag: &str, s: f64) -> Result<Duration> {
    if !(s.is_finite() && s > 0.0 && s <= 86_400.0) {
        bail!("--{flag} must be a number of seconds above 0 (at most a day), not {s}");
    }
    Ok(Duration::from_secs_f64(s))
}

pub fn run(a: ServeArgs) -> Result<ExitCode> {
    let token = match &a.token {
        Some(t) if t.is_empty() => bail!(
            "--token is empty: give a token (every request must then carry it), or leave --token out to serve without one on loopback"
        ),
        Some(t) => Some(t.clone()),
        None => match std::env::var("LOGICRAG_SERVE_TOKEN") {
            Ok(t) if t.is_empty() => bail!(
                "LOGICRAG_SERVE_TOKEN is set but empty: give it a token, or unset it to serve without one on loopback"
            ),
            Ok(t) => Some(t),
            Err(_) => None,
        },
    };
    let addr = SocketAddr::new(host_ip(&a.host)?, a.port);
    // Refused before minutes of loading, not after.
    if !addr.ip().is_loopback() && token.is_none() {
        return Err(ServeError::TokenRequired { addr }.into());
    }
    if a.max_body == 0 {
        bail!("--max-body must be at least 1 byte");
    }
    if a.max_answers == 0 {
        bail!("--max-answers must be at least 1");
    }
    if a.max_connections == 0 {
        bail!("--max-connections must be at least 1");
    }
    if a.upstream_concurrency == 0 {
        bail!("--upstream-concurrency must be at least 1");
    }
    let upstream_timeout = seconds("upstream-timeout", a.upstream_timeout)?;
    let proxy = match &a.llm {
        Some(url) => {
            let mut config =
                logicrag::llm::client::LlmConfig::from_flags(Some(url), a.llm_model.as_deref())?;
            // A proxy hands an error back at once: its client retries if
            // it wants to, and a retried hang would hold a slot for minutes.
            // The server's own deadline answers 504 first; the client's, a
            // second later, ends the abandoned call and frees its slot.
            config.request_timeout = upstream_timeout + Duration::from_secs(1);
            config.retries = 0;
            Some(Proxy {
                lmm: logicrag::llm::Lmm {
                    chat: logicrag::llm::Chat {
                        client: logicrag::llm::client::Client::new(config)?,
                        cache: None,
                    },
                    templates: logicrag::llm::Templates::default(),
                },
                frames: a.lmm_frames,
            })
        }
        None => None,
    };
    let llm_translator = match (a.translator, &a.llm) {
        (super::TranslatorMode::Grammar, _) => None,
        (mode, None) => bail!(
            "--translator {} needs --llm URL (the server that translates what the grammar cannot)",
            if mode == super::TranslatorMode::Llm {
                "llm"
            } else {
                "auto"
            }
        ),
        (_, Some(url)) => {
            let mut config =
                logicrag::llm::client::LlmConfig::from_flags(Some(url), a.llm_model.as_deref())?;
            config.request_timeout = upstream_timeout;
            config.retries = 0;
            Some(logicrag::engine::LlmSetup {
                chat: logicrag::llm::Chat {
                    client: logicrag::llm::client::Client::new(config)?,
                    cache: None,
                },
                templates: logicrag::llm::Templates::default(),
                repairs: a.llm_repairs,
            })
        }
    };
    let translator = logicrag::engine::translator(a.translator, llm_translator)?;
    let options = logicrag::pipeline::OpenOptions {
        keep_scene: true,
        ..a.src.open_options(Some(translator))
    };
    let mut pipeline = super::open(a.src.spec()?, &options)?;
    let scenes = logicrag::scene::Scenes::of(&pipeline);
    let images = pipeline.take_images();
    let pb = indicatif::ProgressBar::new(pipeline.window_count() as u64);
    pb.set_style(
        indicatif::ProgressStyle::with_template("reasoning [{bar:30}] {pos}/{len} windows")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    // The sequence is drawn from `scenes` now; the pipeline keeps only
    // the reasoned windows.
    pipeline.drop_scene();
    let pipeline = pipeline.into_reasoned(&|| pb.inc(1))?;
    pb.finish_and_clear();
    let served = Served {
        pipeline,
        scenes,
        images,
    };
    let opts = ServeOptions {
        token,
        max_body_bytes: a.max_body,
        max_answers: a.max_answers,
        max_query_time: seconds("query-time", a.query_time)?,
        request_timeout: seconds("request-timeout", a.request_timeout)?,
        header_timeout: seconds("header-timeout", a.header_timeout)?,
        max_connections: a.max_connections,
        shutdown_grace: seconds("shutdown-grace", a.shutdown_grace)?,
        upstream_timeout,
        upstream_concurrency: a.upstream_concurrency,
        allowed_hosts: a.allow_host.clone(),
        proxy,
        ..ServeOptions::default()
    };
    let windows = served.pipeline.window_count();
    let label = served.pipeline.label().to_string();
    let guarded = opts.token.is_some();
    let proxied = opts.proxy.is_some();
    logicrag::serve::run(served, opts, addr, |bound| {
        // The first line of stdout is the address, for scripts and tests
        // that start the server on port 0.
        let mut out = std::io::stdout();
        let _ = writeln!(out, "listening on http://{bound}/");
        let _ = writeln!(
            out,
            "serving {windows} windows of {label}{}{}; Ctrl-C stops",
            if guarded {
                " (every request needs the token)"
            } else {
                ""
            },
            if proxied {
                "; Logic-RAG proxy at /v1/chat/completions"
            } else {
                ""
            }
        );
        let _ = out.flush();
    })?;
    Ok(ExitCode::SUCCESS)
}
