//! A blocking client for OpenAI-compatible chat servers (OpenAI, vLLM,
//! llama.cpp, Ollama, LM Studio): `POST {base}/chat/completions` with
//! text and image parts, retries with backoff on 429 and 5xx (honouring
//! `Retry-After`), the server's own error message in errors, and the API
//! key sent as a bearer token and never shown.

use serde::Serialize;
use serde_json::{Value, json};
use std::time::Duration;

/// Errors of a chat request.
#[derive(Debug, thiserror::Error)]
pub enum LlmError {
    /// Occurs when no server URL was given (flag or environment).
    #[error(
        "no LLM server: give --llm URL (e.g. http://127.0.0.1:8080/v1) or set LOGICRAG_LLM_URL"
    )]
    NoServer,
    /// Occurs when the URL is not an http(s) URL.
    #[error("`{0}` is not an http:// or https:// URL")]
    BadUrl(String),
    /// Occurs when the server cannot be reached or the request times out.
    #[error("cannot reach the LLM server at {url}: {message}")]
    Unreachable {
        /// The endpoint.
        url: String,
        /// What failed (key redacted).
        message: String,
    },
    /// Occurs when the server answers with an error status (after retries
    /// for 429 and 5xx).
    #[error("the LLM server at {url} answered {status}: {message}")]
    Status {
        /// The endpoint.
        url: String,
        /// HTTP status.
        status: u16,
        /// The server's own error message (key redacted).
        message: String,
    },
    /// Occurs when the reply is not a chat completion.
    #[error("the LLM server at {url} sent a reply without a message: {body}")]
    Malformed {
        /// The endpoint.
        url: String,
        /// The start of the body (key redacted).
        body: String,
    },
    /// Occurs when the response cache cannot be read or written.
    #[error("response cache {path}: {source}")]
    Cache {
        /// The cache file or directory.
        path: String,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// Occurs when a `--prompt` template file cannot be read (missing, not
    /// a regular file, not UTF-8).
    #[error("prompt template {path}: {source}")]
    Prompt {
        /// The template file.
        path: String,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
}

/// An API key: sent as a bearer token, never printed (its `Debug` says
/// `<redacted>`), and scrubbed from every error message.
#[derive(Clone, PartialEq, Eq)]
pub struct ApiKey(String);

impl ApiKey {
    /// Wraps a key; an empty one is none.
    pub fn new(key: impl Into<String>) -> Option<ApiKey> {
        let k = key.into();
        (!k.trim().is_empty()).then(|| ApiKey(k.trim().to_string()))
    }

    /// The key from `LOGICRAG_API_KEY`, else `OPENAI_API_KEY`.
    pub(crate) fn from_env() -> Option<ApiKey> {
        ["LOGICRAG_API_KEY", "OPENAI_API_KEY"]
            .iter()
            .find_map(|v| std::env::var(v).ok().and_then(ApiKey::new))
    }

    /// `text` with every occurrence of the key replaced.
    pub(crate) fn redact(&self, text: &str) -> String {
        text.replace(&self.0, "<redacted>")
    }
}

impl std::fmt::Debug for ApiKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ApiKey(<redacted>)")
    }
}

/// Where and how to ask.
#[derive(Debug, Clone)]
pub struct LlmConfig {
    /// Base URL ending in the API root, e.g. `http://127.0.0.1:8080/v1`.
    pub base_url: String,
    /// Model name sent in each request.
    pub model: String,
    /// Bearer token, if the server wants one.
    pub api_key: Option<ApiKey>,
    /// Time to establish a connection.
    pub connect_timeout: Duration,
    /// Time for a whole request, reply included.
    pub request_timeout: Duration,
    /// Further attempts after a 429, a 5xx or a dropped connection.
    pub retries: u32,
    /// First backoff; it doubles with each retry (a `Retry-After` wins).
    pub backoff: Duration,
    /// Sampling temperature (0: as deterministic as the server allows).
    pub temperature: f64,
    /// Largest reply, in tokens.
    pub max_tokens: u32,
}

/// Defaults: 10 s to connect, 120 s a request, 3 retries from 1 s.
pub(crate) const DEFAULT_CONNECT_TIMEOUT: Duration = Duration::from_secs(10);
/// See `DEFAULT_CONNECT_TIMEOUT`.
pub const DEFAULT_REQUEST_TIMEOUT: Duration = Duration::from_secs(120);
/// The longest `Retry-After` honoured; a server asking for more gets an error.
pub(crate) const MAX_RETRY_AFTER: Duration = Duration::from_secs(60);

impl LlmConfig {
    /// A configuration for `base_url` and `model` with the defaults.
    pub fn new(
        base_url: &str,
        model: &str,
        api_key: Option<ApiKey>,
    ) -> Result<LlmConfig, LlmError> {
        let base = base_url.trim().trim_end_matches('/');
        if !(base.starts_with("http://") || base.starts_with("https://")) {
            return Err(LlmError::BadUrl(base_url.to_string()));
        }
        Ok(LlmConfig {
            base_url: base.to_string(),
            model: model.to_string(),
            api_key,
            connect_timeout: DEFAULT_CONNECT_TIMEOUT,
            request_timeout: DEFAULT_REQUEST_TIMEOUT,
            retries: 3,
            backoff: Duration::from_secs(1),
            temperature: 0.0,
            max_tokens: 512,
        })
    }

    /// From flags, falling back to `LOGICRAG_LLM_URL`, `LOGICRAG_LLM_MODEL`
    /// and the key variables.
    pub fn from_flags(url: Option<&str>, model: Option<&str>) -> Result<LlmConfig, LlmError> {
        let url = url
            .map(str::to_string)
            .or_else(|| std::env::var("LOGICRAG_LLM_URL").ok())
            .filter(|u| !u.trim().is_empty())
            .ok_or(LlmError::NoServer)?;
        let model = model
            .map(str::to_string)
            .or_else(|| std::env::var("LOGICRAG_LLM_MODEL").ok())
            .unwrap_or_else(|| "default".to_string());
        LlmConfig::new(&url, &model, ApiKey::from_env())
    }

    fn endpoint(&self) -> String {
        format!("{}/chat/completions", self.base_url)
    }
}

/// One part of a message: text, or a PNG image.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize)]
pub enum Part {
    /// Text.
    Text(String),
    /// A PNG image, sent as a `data:image/png;base64,…` URL.
    Png(Vec<u8>),
}

/// A chat message.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize)]
pub struct Message {
    /// `system`, `user` or `assistant`.
    pub role: String,
    /// Its parts, in order.
    pub parts: Vec<Part>,
}

impl Message {
    /// A text-only message.
    pub fn text(role: &str, text: impl Into<String>) -> Message {
        Message {
            role: role.to_string(),
            parts: vec![Part::Text(text.into())],
        }
    }

    /// The OpenAI wire form: a plain string for text only, else content parts.
    fn to_json(&self) -> Value {
        if let [Part::Text(t)] = self.parts.as_slice() {
            return json!({"role": self.role, "content": t});
        }
        let parts: Vec<Value> = self
            .parts
            .iter()
            .map(|p| match p {
                Part::Text(t) => json!({"type": "text", "text": t}),
                Part::Png(bytes) => json!({
                    "type": "image_url",
                    "image_url": {"url": format!("data:image/png;base64,{}", base64(bytes))}
                }),
            })
            .collect();
        json!({"role": self.role, "content": parts})
    }
}

/// Standard base64 with padding (RFC 4648), for image data URLs.
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk.first().copied().unwrap_or(0),
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for (i, shift) in [18u32, 12, 6, 0].into_iter().enumerate() {
            if i <= chunk.len() {
                out.push(char::from(ALPHABET[((n >> shift) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A connection to one server.
#[derive(Debug, Clone)]
pub struct Client {
    config: LlmConfig,
    http: reqwest::blocking::Client,
}

impl Client {
    /// A client for `config`.
    pub fn new(config: LlmConfig) -> Result<Client, LlmError> {
        let http = reqwest::blocking::Client::builder()
            .connect_timeout(config.connect_timeout)
            .timeout(config.request_timeout)
            .build()
            .map_err(|e| LlmError::Unreachable {
                url: config.base_url.clone(),
                message: e.to_string(),
            })?;
        Ok(Client { config, http })
    }

    /// The configuration.
    pub fn config(&self) -> &LlmConfig {
        &self.config
    }

    /// The request body for `messages`, as sent.
    pub fn body(&self, messages: &[Message]) -> Value {
        json!({
            "model": self.config.model,
            "messages": messages.iter().map(Message::to_json).collect::<Vec<_>>(),
            "temperature": self.config.temperature,
            "max_tokens": self.config.max_tokens,
        })
    }

    /// Sends a chat request and returns the reply's text.
    pub fn chat(&self, messages: &[Message]) -> Result<String, LlmError> {
        let url = self.config.endpoint();
        let text = self.send(&self.body(messages))?;
        reply_text(&text).ok_or_else(|| LlmError::Malformed {
            url,
            body: self.redact(&clip(&text, 300)),
        })
    }

    /// Sends a chat request and returns the server's whole chat completion
    /// (id, model, choices, usage), for a proxy that hands it on as it came.
    /// Each field of `extra` (`temperature`, `max_tokens`, `top_p`, `stop`,
    /// …) is sent too, replacing the configuration's; `model` and
    /// `messages` stay this client's.
    pub fn completion(
        &self,
        messages: &[Message],
        extra: &serde_json::Map<String, Value>,
    ) -> Result<Value, LlmError> {
        let url = self.config.endpoint();
        let mut body = self.body(messages);
        if let Some(obj) = body.as_object_mut() {
            for (k, v) in extra {
                if k != "model" && k != "messages" {
                    obj.insert(k.clone(), v.clone());
                }
            }
        }
        let text = self.send(&body)?;
        let malformed = || LlmError::Malformed {
            url: url.clone(),
            body: self.redact(&clip(&text, 300)),
        };
        // A reply that is JSON but no chat completion is an error here
        // too: the proxy's caller expects `choices[0].message`.
        reply_text(&text).ok_or_else(malformed)?;
        serde_json::from_str(&text).map_err(|_| malformed())
    }

    /// Sends `body` exactly as given (the proxy builds it from the
    /// client's own fields, so nothing of this configuration is added)
    /// and returns the server's chat completion.
    pub(crate) fn completion_body(&self, body: &Value) -> Result<Value, LlmError> {
        let url = self.config.endpoint();
        let text = self.send(body)?;
        let malformed = || LlmError::Malformed {
            url: url.clone(),
            body: self.redact(&clip(&text, 300)),
        };
        reply_text(&text).ok_or_else(malformed)?;
        serde_json::from_str(&text).map_err(|_| malformed())
    }

    /// Sends `body` exactly as given, once, and returns the response of a
    /// 2xx reply unread, for a caller that streams it (server-sent events)
    /// or reads it whole when the server did not stream.
    pub(crate) fn post_streaming(
        &self,
        body: &Value,
    ) -> Result<reqwest::blocking::Response, LlmError> {
        let url = self.config.endpoint();
        self.send_once(self.http.post(&url).json(body), url)
    }

    /// Sends `req` (to `url`) once with the key, and returns the response
    /// of a 2xx reply unread; any other reply is [`LlmError::Status`] with
    /// the server's message.
    fn send_once(
        &self,
        req: reqwest::blocking::RequestBuilder,
        url: String,
    ) -> Result<reqwest::blocking::Response, LlmError> {
        let req = match &self.config.api_key {
            Some(k) => req.bearer_auth(&k.0),
            None => req,
        };
        let resp = req.send().map_err(|e| LlmError::Unreachable {
            url: url.clone(),
            message: self.redact(&e.to_string()),
        })?;
        let status = resp.status().as_u16();
        if (200..300).contains(&status) {
            return Ok(resp);
        }
        let text = resp.text().unwrap_or_default();
        Err(LlmError::Status {
            url,
            status,
            message: self.redact(&server_message(&text)),
        })
    }

    /// The server's models (`GET {base}/models`) as it lists them: an
    /// object whose `data` is an array. Sent once, without retries (a
    /// proxy answers its client at once and may fall back).
    pub fn models(&self) -> Result<Value, LlmError> {
        let url = format!("{}/models", self.config.base_url);
        let text = self
            .send_once(self.http.get(&url), url.clone())?
            .text()
            .unwrap_or_default();
        let malformed = || LlmError::Malformed {
            url: url.clone(),
            body: self.redact(&clip(&text, 300)),
        };
        let v: Value = serde_json::from_str(&text).map_err(|_| malformed())?;
        if v.get("data").and_then(Value::as_array).is_none() {
            return Err(malformed());
        }
        Ok(v)
    }

    fn redact(&self, text: &str) -> String {
        match &self.config.api_key {
            Some(k) => k.redact(text),
            None => text.to_string(),
        }
    }

    /// Posts `body` with retries and returns the body of a 2xx reply.
    fn send(&self, body: &Value) -> Result<String, LlmError> {
        let url = self.config.endpoint();
        let redact = |t: &str| self.redact(t);
        let mut attempt = 0;
        loop {
            let mut req = self.http.post(&url).json(body);
            if let Some(k) = &self.config.api_key {
                req = req.bearer_auth(&k.0);
            }
            let wait = match req.send() {
                Err(e) => {
                    let message = redact(&e.to_string());
                    if attempt >= self.config.retries || !(e.is_connect() || e.is_timeout()) {
                        return Err(LlmError::Unreachable { url, message });
                    }
                    None
                }
                Ok(resp) => {
                    let status = resp.status().as_u16();
                    let retry_after = resp
                        .headers()
                        .get("retry-after")
                        .and_then(|v| v.to_str().ok())
                        .and_then(|v| v.trim().parse::<u64>().ok())
                        .map(Duration::from_secs);
                    let text = resp.text().map_err(|e| LlmError::Unreachable {
                        url: url.clone(),
                        message: redact(&e.to_string()),
                    })?;
                    if (200..300).contains(&status) {
                        return Ok(text);
                    }
                    let retryable = status == 429 || status >= 500;
                    let too_long = retry_after.is_some_and(|d| d > MAX_RETRY_AFTER);
                    if !retryable || attempt >= self.config.retries || too_long {
                        return Err(LlmError::Status {
                            url,
                            status,
                            message: redact(&server_message(&text)),
                        });
                    }
                    retry_after
                }
            };
            let backoff = self.config.backoff * 2u32.saturating_pow(attempt);
            std::thread::sleep(wait.unwrap_or(backoff));
            attempt += 1;
        }
    }
}

/// The first choice's message text of a chat completion.
fn reply_text(body: &str) -> Option<String> {
    let v: Value = serde_json::from_str(body).ok()?;
    let content = v.get("choices")?.get(0)?.get("message")?.get("content")?;
    match content {
        Value::String(s) => Some(s.clone()),
        // Some servers answer with content parts.
        Value::Array(parts) => Some(
            parts
                .iter()
                .filter_map(|p| p.get("text").and_then(Value::as_str))
                .collect::<Vec<_>>()
                .join(""),
        ),
        _ => None,
    }
}

/// The server's own error message: `{"error": {"message": …}}`,
/// `{"error": "…"}`, or the start of the body.
fn server_message(body: &str) -> String {
    let parsed: Option<Value> = serde_json::from_str(body).ok();
    let msg = parsed.as_ref().and_then(|v| {
        let e = v.get("error")?;
        e.get("message")
            .and_then(Value::as_str)
            .or_else(|| e.as_str())
            .map(str::to_string)
    });
    msg.unwrap_or_else(|| clip(body.trim(), 300))
}

fn clip(text: &str, max: usize) -> String {
    if text.chars().count() <= max {
        text.to_string()
    } else {
        let cut: String = text.chars().take(max).collect();
        format!("{cut}…")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648_vectors() {
        for (input, want) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(input.as_bytes()), want);
        }
    }

    #[test]
    fn the_key_never_shows() {
        let k = ApiKey::new("sk-secret-123").expect("key");
        assert_eq!(format!("{k:?}"), "ApiKey(<redacted>)");
        assert_eq!(
            k.redact("bad key sk-secret-123 given"),
            "bad key <redacted> given"
        );
        assert!(ApiKey::new("  ").is_none());
    }

    #[test]
    fn server_errors_are_read_from_their_json() {
        assert_eq!(
            server_message(r#"{"error": {"message": "model not found"}}"#),
            "model not found"
        );
        assert_eq!(server_message(r#"{"error": "overloaded"}"#), "overloaded");
        assert_eq!(server_message("Bad Gateway"), "Bad Gateway");
        assert_eq!(
            reply_text(r#"{"choices":[{"message":{"role":"assistant","content":"Yes."}}]}"#)
                .as_deref(),
            Some("Yes.")
        );
        assert!(reply_text(r#"{"choices":[]}"#).is_none());
    }

    #[test]
    fn a_url_must_be_http() {
        assert!(matches!(
            LlmConfig::new("ftp://x", "m", None),
            Err(LlmError::BadUrl(_))
        ));
        let c = LlmConfig::new("http://127.0.0.1:8080/v1/", "m", None).expect("ok");
        assert_eq!(c.endpoint(), "http://127.0.0.1:8080/v1/chat/completions");
    }
}
