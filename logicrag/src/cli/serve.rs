//! `logicrag serve`: loads a source, reasons every window once (with a
//! progress bar) and serves the page, the JSON API, the retriever and —
//! with `--llm` — the OpenAI-compatible Logic-RAG proxy from memory
//! (`logicrag::serve`; endpoints in docs/serve.md).

use super::{SourceArgs, load_engine, load_options, load_source};
use anyhow::{Result, bail};
use clap::Args;
use logicrag::serve::{DEFAULT_MAX_BODY_BYTES, Proxy, ServeError, ServeOptions, Served};
use std::io::Write as _;
use std::net::{IpAddr, SocketAddr};
use std::process::ExitCode;

#[derive(Args)]
pub struct ServeArgs {
    #[command(flatten)]
    pub src: SourceArgs,
    /// Address to listen on; anything but loopback needs --token.
    #[arg(long, default_value = "127.0.0.1")]
    pub host: IpAddr,
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
    /// The most bindings a query may have (as `ask --max-answers`).
    #[arg(long = "max-answers", default_value_t = logicpad::DEFAULT_MAX_ANSWERS)]
    pub max_answers: usize,
    /// Upstream OpenAI-compatible server for /v1/chat/completions, e.g.
    /// http://127.0.0.1:8081/v1 (the key comes from $LOGICRAG_API_KEY or
    /// $OPENAI_API_KEY). Without it the proxy is off.
    #[arg(long)]
    pub llm: Option<String>,
    /// Upstream model name (default: $LOGICRAG_LLM_MODEL, else "default").
    #[arg(long = "llm-model", requires = "llm")]
    pub llm_model: Option<String>,
    /// Frames attached to each proxied question, sampled evenly over the window.
    #[arg(long = "lmm-frames", default_value_t = 5)]
    pub lmm_frames: usize,
}

pub fn run(a: ServeArgs) -> Result<ExitCode> {
    let token = a
        .token
        .clone()
        .or_else(|| std::env::var("LOGICRAG_SERVE_TOKEN").ok())
        .filter(|t| !t.is_empty());
    let addr = SocketAddr::new(a.host, a.port);
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
    let proxy = match &a.llm {
        Some(url) => {
            let config =
                logicrag::llm::client::LlmConfig::from_flags(Some(url), a.llm_model.as_deref())?;
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
    let config = load_options(&a.src)?.config;
    let mut loaded = load_source(&a.src)?;
    let engine = load_engine(&a.src.logicpad, loaded.observability.clone())?;
    let scenes = loaded
        .sequence
        .as_ref()
        .map(|seq| logicrag::scene::Scenes::new(seq, &config));
    let images = loaded.images.take();
    let inputs = std::mem::take(&mut loaded.windows);
    let pb = indicatif::ProgressBar::new(inputs.len() as u64);
    pb.set_style(
        indicatif::ProgressStyle::with_template("reasoning [{bar:30}] {pos}/{len} windows")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let windows = engine.build_all(inputs, &|| pb.inc(1))?;
    pb.finish_and_clear();
    let served = Served {
        label: loaded.label.clone(),
        engine,
        windows,
        scenes,
        images,
    };
    let opts = ServeOptions {
        token,
        max_body_bytes: a.max_body,
        max_answers: a.max_answers,
        proxy,
    };
    let windows = served.windows.len();
    let label = served.label.clone();
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
