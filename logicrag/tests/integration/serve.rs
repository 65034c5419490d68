//! `logicrag serve` over real HTTP on a free loopback port: every endpoint,
//! the errors a client can cause (400, 401, 404, 413), the token, a bounded
//! concurrent load whose every answer must equal the library's, and the
//! OpenAI-compatible proxy against a scripted upstream on 127.0.0.1.

use crate::common::{self, Served, client};
use logicpad::LogicPad;
use logicrag::ask::AskOptions;
use logicrag::engine::{Engine, Summary};
use logicrag::kb::WindowKb;
use logicrag::source::LoadOptions;
use reqwest::StatusCode;
use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Write};
use std::net::TcpListener;
use std::sync::{Arc, Mutex};

const SOURCE: &str = "sim:urban_crossing";
const WINDOW: &str = "urban_crossing_000020";

/// The library's engine and reasoned windows for [`SOURCE`], as the server
/// builds them.
fn library() -> (Engine, Vec<WindowKb>) {
    let spec = SOURCE.parse().expect("source");
    let loaded = logicrag::source::load(&spec, &LoadOptions::default(), &mut |_| {})
        .expect("the built-in scenario loads");
    let engine = Engine::new(LogicPad::builtin(), loaded.observability.clone()).expect("engine");
    let kbs = loaded
        .windows
        .into_iter()
        .map(|w| engine.build(w).expect("window"))
        .collect();
    (engine, kbs)
}

/// What `POST /api/ask` must answer: the objects `ask --json` prints, from
/// the library directly.
fn expected_answer(
    engine: &Engine,
    kbs: &[WindowKb],
    question: &str,
    window: Option<&str>,
) -> Value {
    let p = engine.prepare(question).expect("the question translates");
    let results: Vec<_> = kbs
        .iter()
        .filter(|kb| window.is_none_or(|w| kb.id == w))
        .map(|kb| engine.ask(kb, &p, AskOptions::default()))
        .collect();
    let summary = Summary::new(engine.words(), &p, &results);
    let objects: Vec<Value> = results
        .iter()
        .map(|r| logicrag::json::answer_object(r, &p, None).expect("json"))
        .collect();
    json!({"results": objects, "summary": logicrag::json::summary_object(&summary, &p)})
}

/// A JSON error body in the OpenAI shape, with the status as its code.
fn assert_json_error(resp: reqwest::blocking::Response, status: StatusCode, says: &str) {
    assert_eq!(resp.status(), status, "{:?}", resp.text().ok());
    let v: Value = resp.json().expect("an error is JSON");
    let msg = v["error"]["message"].as_str().expect("error.message");
    assert_eq!(v["error"]["code"], json!(status.as_u16()), "{v}");
    assert!(msg.contains(says), "`{msg}` should say `{says}`");
}

#[test]
fn every_endpoint_answers_on_loopback() {
    let s = Served::start(&["--source", SOURCE], &[]);
    let http = client();
    let (engine, kbs) = library();

    // The page: one self-contained document, its script and style inlined.
    let page = http.get(s.at("/")).send().expect("GET /");
    assert_eq!(page.status(), StatusCode::OK);
    assert!(
        page.headers()["content-type"]
            .to_str()
            .unwrap_or_default()
            .starts_with("text/html")
    );
    let html = page.text().expect("html");
    assert!(html.contains("<script>") && html.contains("function renderBev"));
    assert!(!html.contains("/*APP_JS*/") && !html.contains("/*APP_CSS*/"));
    for external in [
        "src=\"http",
        "href=\"http",
        "src=\"//",
        "href=\"//",
        "@import",
        "url(http",
    ] {
        assert!(
            !html.contains(external),
            "the page loads nothing from elsewhere: {external}"
        );
    }

    let w: Value = http
        .get(s.at("/api/windows"))
        .send()
        .expect("windows")
        .json()
        .expect("json");
    assert_eq!(w["source"], json!(SOURCE));
    assert_eq!(w["images"], json!(true));
    let ids: Vec<&str> = w["windows"]
        .as_array()
        .expect("windows")
        .iter()
        .map(|w| w["id"].as_str().expect("id"))
        .collect();
    assert_eq!(ids.len(), kbs.len());
    assert!(ids.iter().zip(&kbs).all(|(a, kb)| *a == kb.id));
    let first = &w["windows"][2];
    assert_eq!(first["first_frame"], json!(20));
    assert_eq!(first["last_frame"], json!(29));
    assert_eq!(first["objects"], json!(kbs[2].objects.len()));

    // Ask: one window, then all of them; exactly the library's objects.
    for window in [Some(WINDOW), None] {
        let mut body = json!({"question": "Is the pedestrian walking?"});
        if let Some(w) = window {
            body["window"] = json!(w);
        }
        let got = http
            .post(s.at("/api/ask"))
            .json(&body)
            .send()
            .expect("ask")
            .text()
            .expect("text");
        assert_eq!(
            got,
            expected_answer(&engine, &kbs, "Is the pedestrian walking?", window).to_string()
        );
    }
    let one: Value = http
        .post(s.at("/api/ask"))
        .json(&json!({"question": "Is the pedestrian walking?", "window": WINDOW}))
        .send()
        .expect("ask")
        .json()
        .expect("json");
    assert_eq!(one["results"][0]["answer"], json!("yes"));
    assert_eq!(
        one["results"][0]["bindings"],
        json!([[["x", "pedestrian_5"]]])
    );
    assert!(
        !one["results"][0]["proofs"][0]
            .as_array()
            .expect("proof")
            .is_empty()
    );
    assert_eq!(one["summary"]["headline"], json!("yes — in frames 20–29"));

    let ctx: Value = http
        .post(s.at("/api/context"))
        .json(&json!({"question": "Is the pedestrian walking?", "window": WINDOW}))
        .send()
        .expect("context")
        .json()
        .expect("json");
    let c = &ctx["contexts"][0];
    assert_eq!(c["window"], json!(WINDOW));
    assert!(
        c["c2"][0]
            .as_str()
            .expect("c2")
            .starts_with("The answer is yes"),
        "{c}"
    );
    assert!(
        c["c3"].as_array().expect("c3").iter().any(|s| s
            .as_str()
            .is_some_and(|s| s.starts_with("pedestrian_5 is a pedestrian"))),
        "{c}"
    );

    let facts: Value = http
        .get(s.at(&format!("/api/facts?window={WINDOW}")))
        .send()
        .expect("facts")
        .json()
        .expect("json");
    assert_eq!(facts["window"], json!(WINDOW));
    let list = facts["facts"].as_array().expect("facts");
    assert_eq!(list.len(), kbs[2].fact_count());
    assert!(
        list.iter()
            .all(|f| f["provenance"]["frames"] == json!([20, 29]))
    );
    assert!(list.iter().all(|f| {
        f["why"]
            .as_str()
            .is_some_and(|w| w.contains("frames 20–29"))
    }));

    let scene: Value = http
        .get(s.at(&format!("/api/scene?window={WINDOW}")))
        .send()
        .expect("scene")
        .json()
        .expect("json");
    assert_eq!(scene["frames"].as_array().map(Vec::len), Some(10));
    assert_eq!(scene["ego"].as_array().map(Vec::len), Some(10));
    assert!(
        scene["tracks"]
            .as_array()
            .expect("tracks")
            .iter()
            .any(|t| t["name"] == json!("pedestrian_5"))
    );

    let frame = http
        .get(s.at(&format!("/api/frame?window={WINDOW}&index=9")))
        .send()
        .expect("frame");
    assert_eq!(frame.status(), StatusCode::OK);
    assert_eq!(frame.headers()["content-type"], "image/png");
    let png = image::load_from_memory(&frame.bytes().expect("bytes")).expect("a PNG");
    assert_eq!((png.width(), png.height()), (960, 290));

    let docs: Value = http
        .post(s.at("/v1/retrieve"))
        .json(&json!({"query": "Is the pedestrian walking?"}))
        .send()
        .expect("retrieve")
        .json()
        .expect("json");
    let docs = docs["documents"].as_array().expect("documents");
    assert_eq!(docs[0]["metadata"]["kind"], json!("answer"));
    assert!(
        docs[0]["page_content"]
            .as_str()
            .expect("text")
            .contains("yes — in 6 of 8 windows")
    );
    let proofs: Vec<&Value> = docs
        .iter()
        .filter(|d| d["metadata"]["kind"] == json!("proof"))
        .collect();
    assert_eq!(proofs.len(), logicrag::serve::retrieve::DEFAULT_WINDOWS);
    assert!(
        proofs
            .iter()
            .all(|d| d["metadata"]["answer"] == json!("yes"))
    );
    assert!(
        proofs[0]["page_content"]
            .as_str()
            .expect("text")
            .contains("Walk(pedestrian_5) follows by the rule")
    );
    let facts: Vec<&Value> = docs
        .iter()
        .filter(|d| d["metadata"]["kind"] == json!("fact"))
        .collect();
    assert!(!facts.is_empty());
    assert!(facts.iter().all(|d| {
        d["metadata"]["objects"]
            .as_array()
            .is_some_and(|o| o.contains(&json!("pedestrian_5")))
    }));
    assert!(
        facts[0]["page_content"]
            .as_str()
            .expect("text")
            .starts_with("pedestrian_5 is a pedestrian")
    );
    // One window, and the limits.
    let one: Value = http
        .post(s.at("/v1/retrieve"))
        .json(&json!({"question": "Is the pedestrian walking?", "window": "urban_crossing_000000", "facts": 2}))
        .send()
        .expect("retrieve")
        .json()
        .expect("json");
    let docs = one["documents"].as_array().expect("documents");
    assert_eq!(docs.len(), 1 + 1 + 2, "{one}");
    assert_eq!(docs[1]["metadata"]["answer"], json!("no"));

    // Without --llm the proxy says how to turn it on.
    let r = http
        .post(s.at("/v1/chat/completions"))
        .json(&json!({"messages": [{"role": "user", "content": "Is the pedestrian walking?"}]}))
        .send()
        .expect("chat");
    assert_json_error(r, StatusCode::NOT_FOUND, "--llm");
}

#[test]
fn bad_requests_get_a_json_error_and_no_path_reads_outside_the_data() {
    let s = Served::start(&["--source", SOURCE], &[]);
    let http = client();
    let post = |path: &str, body: &str| {
        http.post(s.at(path))
            .header("content-type", "application/json")
            .body(body.to_string())
            .send()
            .expect("request")
    };
    for (path, body, says) in [
        ("/api/ask", "{\"question\": ", "EOF while parsing"),
        ("/api/ask", "not json", "expected"),
        ("/api/ask", "", "no body"),
        ("/api/ask", "{}", "missing field `question`"),
        ("/api/ask", "{\"question\": 3}", "invalid type"),
        (
            "/api/ask",
            "{\"question\": \"Moving(x)\", \"windw\": \"a\"}",
            "unknown field `windw`",
        ),
        ("/api/ask", "{\"question\": \"   \"}", "empty"),
        (
            "/api/ask",
            "{\"question\": \"Does the moon dance tango?\"}",
            "cannot translate the question",
        ),
        ("/api/context", "[1, 2]", "invalid type"),
        (
            "/v1/retrieve",
            "{\"question\": \"Moving(x)\", \"kk\": 3}",
            "unknown field `kk`",
        ),
    ] {
        assert_json_error(post(path, body), StatusCode::BAD_REQUEST, says);
    }
    for (path, status, says) in [
        (
            "/api/facts",
            StatusCode::BAD_REQUEST,
            "missing field `window`",
        ),
        (
            "/api/frame?window=urban_crossing_000020&index=abc",
            StatusCode::BAD_REQUEST,
            "index",
        ),
        (
            "/api/frame?window=urban_crossing_000020&index=10",
            StatusCode::BAD_REQUEST,
            "past window",
        ),
        (
            "/api/frame?window=urban_crossing_000020&index=-1",
            StatusCode::BAD_REQUEST,
            "index",
        ),
        (
            "/api/facts?window=nope",
            StatusCode::NOT_FOUND,
            "no window `nope`",
        ),
        // A window is an id looked up in memory, never a path.
        (
            "/api/facts?window=../../../../etc/passwd",
            StatusCode::NOT_FOUND,
            "no window `../../../../etc/passwd`",
        ),
        (
            "/api/frame?window=%2Fetc%2Fpasswd&index=0",
            StatusCode::NOT_FOUND,
            "no window `/etc/passwd`",
        ),
        (
            "/../../etc/passwd",
            StatusCode::NOT_FOUND,
            "no such endpoint",
        ),
        (
            "/assets/../Cargo.toml",
            StatusCode::NOT_FOUND,
            "no such endpoint",
        ),
        ("/api/nothing", StatusCode::NOT_FOUND, "no such endpoint"),
    ] {
        let r = http.get(s.at(path)).send().expect("request");
        assert_json_error(r, status, says);
    }
    // A valid query that asks about an unknown window is an error, not all windows.
    assert_json_error(
        post(
            "/api/ask",
            "{\"question\": \"Moving(x)\", \"window\": \"urban_crossing_999999\"}",
        ),
        StatusCode::NOT_FOUND,
        "no window",
    );
    // An invalid query is an answer ("invalid", with diagnostics), not a 400.
    let v: Value = post(
        "/api/ask",
        "{\"question\": \"Levitates(x)\", \"window\": \"urban_crossing_000020\"}",
    )
    .json()
    .expect("json");
    assert_eq!(v["results"][0]["answer"], json!("invalid"));
    // The server is still well after all of that.
    assert_eq!(
        http.get(s.at("/api/windows"))
            .send()
            .expect("windows")
            .status(),
        StatusCode::OK
    );
}

#[test]
fn an_oversized_body_is_refused_with_413() {
    let s = Served::start(&["--source", SOURCE, "--max-body", "4096"], &[]);
    let http = client();
    let question = "x".repeat(8192);
    let r = http
        .post(s.at("/api/ask"))
        .json(&json!({"question": question}))
        .send()
        .expect("request");
    assert_json_error(
        r,
        StatusCode::PAYLOAD_TOO_LARGE,
        "larger than this server accepts",
    );
    // Without a length announced up front (chunked), the limit holds too.
    let chunks: Vec<Vec<u8>> = (0..8).map(|_| vec![b' '; 1024]).collect();
    let status = chunked_post(&s.url, "/v1/retrieve", &chunks);
    assert_eq!(status.as_deref(), Some("HTTP/1.1 413 Payload Too Large"));
    // Just under the limit is fine.
    let r = http
        .post(s.at("/api/ask"))
        .json(&json!({"question": "Is the pedestrian walking?", "window": WINDOW}))
        .send()
        .expect("request");
    assert_eq!(r.status(), StatusCode::OK);
}

/// Posts `chunks` with chunked transfer encoding (no length up front) over
/// a raw connection and returns the response's status line.
fn chunked_post(url: &str, path: &str, chunks: &[Vec<u8>]) -> Option<String> {
    let addr = url.trim_start_matches("http://");
    let mut stream = std::net::TcpStream::connect(addr).expect("connect");
    stream
        .set_read_timeout(Some(std::time::Duration::from_secs(30)))
        .expect("timeout");
    let mut req = format!(
        "POST {path} HTTP/1.1\r\nHost: {addr}\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n"
    )
    .into_bytes();
    for c in chunks {
        req.extend(format!("{:x}\r\n", c.len()).bytes());
        req.extend(c);
        req.extend(b"\r\n");
    }
    req.extend(b"0\r\n\r\n");
    stream
        .write_all(&req)
        .expect("the request fits the socket's buffers");
    let mut line = String::new();
    BufReader::new(stream).read_line(&mut line).ok()?;
    Some(line.trim_end().to_string())
}

#[test]
fn a_token_guards_every_request() {
    let token = "s3cret-Token_42";
    let s = Served::start(&["--source", SOURCE, "--token", token], &[]);
    let http = client();
    let ask = json!({"question": "Is the pedestrian walking?", "window": WINDOW});
    for path in [
        "/",
        "/api/windows",
        "/api/facts?window=urban_crossing_000020",
        "/api/frame?window=urban_crossing_000020&index=0",
    ] {
        assert_json_error(
            http.get(s.at(path)).send().expect("get"),
            StatusCode::UNAUTHORIZED,
            "token",
        );
        for wrong in [
            "Bearer s3cret-Token_4",
            "Bearer s3cret-Token_42x",
            "Basic czNjcmV0",
            "s3cret-Token_42",
            "Bearer ",
        ] {
            let r = http
                .get(s.at(path))
                .header("authorization", wrong)
                .send()
                .expect("get");
            assert_json_error(r, StatusCode::UNAUTHORIZED, "token");
        }
        let sep = if path.contains('?') { '&' } else { '?' };
        let r = http
            .get(s.at(&format!("{path}{sep}access_token=wrong")))
            .send()
            .expect("get");
        assert_json_error(r, StatusCode::UNAUTHORIZED, "token");
        let r = http.get(s.at(path)).bearer_auth(token).send().expect("get");
        assert_eq!(r.status(), StatusCode::OK, "{path}");
        // The page and its pictures are fetched by a browser, without headers.
        let r = http
            .get(s.at(&format!("{path}{sep}access_token={token}")))
            .send()
            .expect("get");
        assert_eq!(r.status(), StatusCode::OK, "{path}");
    }
    let r = http.post(s.at("/api/ask")).json(&ask).send().expect("post");
    assert_eq!(r.status(), StatusCode::UNAUTHORIZED);
    assert!(r.headers().get("www-authenticate").is_some());
    let r = http
        .post(s.at("/api/ask"))
        .bearer_auth("nope")
        .json(&ask)
        .send()
        .expect("post");
    assert_eq!(r.status(), StatusCode::UNAUTHORIZED);
    let r = http
        .post(s.at("/api/ask"))
        .bearer_auth(token)
        .json(&ask)
        .send()
        .expect("post");
    assert_eq!(r.status(), StatusCode::OK);
    // Unknown endpoints say nothing to a caller without the token either.
    let r = http.get(s.at("/nothing")).send().expect("get");
    assert_eq!(r.status(), StatusCode::UNAUTHORIZED);
}

#[test]
fn a_non_loopback_address_needs_a_token() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_logicrag"))
        .args(["serve", "--host", "0.0.0.0", "--port", "0"])
        .env_remove("LOGICRAG_SERVE_TOKEN")
        .output()
        .expect("the binary runs");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("0.0.0.0:0 is not a loopback address: give --token"),
        "{err}"
    );
    assert!(out.stdout.is_empty(), "nothing was served");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_logicrag"))
        .args(["serve", "--token", "has space", "--port", "0"])
        .output()
        .expect("the binary runs");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("printable ASCII"));
}

#[test]
fn a_thousand_asks_from_sixteen_clients_are_all_right() {
    const CLIENTS: usize = 16;
    const ASKS: usize = 1000;
    let s = Served::start(&["--source", SOURCE], &[]);
    let (engine, kbs) = library();
    let questions = [
        "Is the pedestrian walking?",
        "How many pedestrians are there?",
        "Which vehicles are moving?",
        "Is the pedestrian crossing the road?",
        "What colour is the van?",
        "Is there a white car?",
        "TypeOf(x, Van) ^ ColorOf(x, y)",
    ];
    let mut windows: Vec<Option<String>> = kbs.iter().map(|kb| Some(kb.id.clone())).collect();
    windows.push(None);
    // Every (question, window) pair's answer, from the library.
    let mut expected: BTreeMap<(usize, usize), String> = BTreeMap::new();
    for (qi, q) in questions.iter().enumerate() {
        for (wi, w) in windows.iter().enumerate() {
            expected.insert(
                (qi, wi),
                expected_answer(&engine, &kbs, q, w.as_deref()).to_string(),
            );
        }
    }
    let expected = Arc::new(expected);
    let windows = Arc::new(windows);
    let url = s.at("/api/ask");
    let handles: Vec<_> = (0..CLIENTS)
        .map(|c| {
            let (expected, windows, url) =
                (Arc::clone(&expected), Arc::clone(&windows), url.clone());
            std::thread::spawn(move || -> Result<usize, String> {
                let http = client();
                let mut done = 0;
                for i in (c..ASKS).step_by(CLIENTS) {
                    let (qi, wi) = (i % questions.len(), (i / questions.len()) % windows.len());
                    let mut body = json!({"question": questions[qi]});
                    if let Some(w) = &windows[wi] {
                        body["window"] = json!(w);
                    }
                    let resp = http
                        .post(&url)
                        .json(&body)
                        .send()
                        .map_err(|e| format!("ask {i}: {e}"))?;
                    if resp.status() != StatusCode::OK {
                        return Err(format!("ask {i}: status {}", resp.status()));
                    }
                    // Compared as text: the very bytes `ask --json`'s
                    // objects serialise to (a parse would round floats).
                    let got = resp.text().map_err(|e| format!("ask {i}: {e}"))?;
                    let want = &expected[&(qi, wi)];
                    if &got != want {
                        let parsed: Value = serde_json::from_str(&got).unwrap_or(Value::Null);
                        let want_v: Value = serde_json::from_str(want).unwrap_or(Value::Null);
                        return Err(format!(
                            "ask {i} ({}, {:?}) differs from the library at {}",
                            questions[qi],
                            windows[wi],
                            first_difference(&parsed, &want_v, "")
                        ));
                    }
                    done += 1;
                }
                Ok(done)
            })
        })
        .collect();
    let mut total = 0;
    for h in handles {
        total += h
            .join()
            .expect("a client thread")
            .expect("every answer is right");
    }
    assert_eq!(total, ASKS);
}

/// Where two JSON values first differ, and how.
fn first_difference(a: &Value, b: &Value, at: &str) -> String {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for k in x.keys().chain(y.keys()) {
                let (u, v) = (
                    x.get(k).unwrap_or(&Value::Null),
                    y.get(k).unwrap_or(&Value::Null),
                );
                if u != v {
                    return first_difference(u, v, &format!("{at}.{k}"));
                }
            }
            String::new()
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
            for (i, (u, v)) in x.iter().zip(y).enumerate() {
                if u != v {
                    return first_difference(u, v, &format!("{at}[{i}]"));
                }
            }
            String::new()
        }
        _ => format!("{at}: server {a} vs library {b} (after parsing)"),
    }
}

/// One request as the scripted upstream saw it.
#[derive(Debug, Clone)]
struct Seen {
    path: String,
    authorization: Option<String>,
    body: Value,
}

/// A scripted OpenAI-compatible upstream on 127.0.0.1: answers each
/// request with the next reply (the last repeats) and records it.
fn upstream(script: Vec<(u16, String)>) -> (String, Arc<Mutex<Vec<Seen>>>) {
    let listener = TcpListener::bind("127.0.0.1:0").expect("bind loopback");
    let url = format!("http://{}/v1", listener.local_addr().expect("addr"));
    let seen = Arc::new(Mutex::new(Vec::new()));
    let log = Arc::clone(&seen);
    std::thread::spawn(move || {
        for (n, stream) in listener.incoming().enumerate() {
            let Ok(mut stream) = stream else { continue };
            let mut reader = BufReader::new(stream.try_clone().expect("clone"));
            let Some(req) = common::read_request(&mut reader) else {
                continue;
            };
            log.lock().expect("log").push(Seen {
                path: req.path,
                authorization: req.authorization,
                body: serde_json::from_slice(&req.body).unwrap_or(Value::Null),
            });
            let (status, text) = script[n.min(script.len() - 1)].clone();
            let resp = format!(
                "HTTP/1.1 {status} X\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{text}",
                text.len()
            );
            let _ = stream.write_all(resp.as_bytes());
        }
    });
    (url, seen)
}

fn completion(text: &str) -> Value {
    json!({
        "id": "chatcmpl-1", "object": "chat.completion", "created": 1, "model": "upstream-model",
        "choices": [{"index": 0, "message": {"role": "assistant", "content": text}, "finish_reason": "stop"}],
        "usage": {"prompt_tokens": 10, "completion_tokens": 2, "total_tokens": 12}
    })
}

/// The text parts and the number of image parts of an upstream message.
fn parts(m: &Value) -> (String, usize) {
    match &m["content"] {
        Value::String(s) => (s.clone(), 0),
        Value::Array(ps) => (
            ps.iter()
                .filter_map(|p| p["text"].as_str())
                .collect::<Vec<_>>()
                .join("\n"),
            ps.iter()
                .filter(|p| p["type"] == json!("image_url"))
                .count(),
        ),
        _ => (String::new(), 0),
    }
}

#[test]
fn the_proxy_adds_logic_rag_context_and_returns_the_upstream_reply() {
    let reply = completion("Yes. The pedestrian is walking.");
    let (url, seen) = upstream(vec![
        (
            200,
            json!({"object": "list", "data": [{"id": "upstream-model", "object": "model", "owned_by": "up"}]})
                .to_string(),
        ),
        (200, reply.to_string()),
        (200, completion("Maybe.").to_string()),
        (200, completion("Hello.").to_string()),
        (
            400,
            json!({"error": {"message": "model `m` does not exist"}}).to_string(),
        ),
    ]);
    let s = Served::start(
        &[
            "--source",
            SOURCE,
            "--llm",
            &url,
            "--llm-model",
            "test-model",
            "--lmm-frames",
            "2",
        ],
        &[("LOGICRAG_API_KEY", "sk-upstream")],
    );
    let http = client();

    let models: Value = http
        .get(s.at("/v1/models"))
        .send()
        .expect("models")
        .json()
        .expect("json");
    // The upstream's own list (regression: the configured name was
    // returned without asking).
    assert_eq!(models["data"][0]["id"], json!("upstream-model"), "{models}");
    assert_eq!(seen.lock().expect("log")[0].path, "/v1/models");

    // C2 (the default), a chosen window, a system message and sampling options.
    let got: Value = http
        .post(s.at("/v1/chat/completions"))
        .json(&json!({
            "model": "gpt-4o-mini",
            "messages": [
                {"role": "system", "content": "Answer briefly."},
                {"role": "user", "content": [{"type": "text", "text": "Is the pedestrian walking?"}]}
            ],
            "temperature": 0.3, "max_tokens": 64, "stop": ["\n\n"],
            "logicrag": {"window": WINDOW}
        }))
        .send()
        .expect("chat")
        .json()
        .expect("json");
    let mut want = reply.clone();
    want["logicrag"] = json!({
        "context_added": true,
        "window": WINDOW, "frames": [20, 29], "images": 2, "client_images": 0, "condition": "c2",
        "question": "Is the pedestrian walking?", "query": "Pedestrian(x)^Walk(x)",
        "answer": "yes", "notes": [],
    });
    assert_eq!(
        got, want,
        "the upstream's completion, plus what Logic-RAG used"
    );
    let sent = seen.lock().expect("log")[1].clone();
    assert_eq!(sent.path, "/v1/chat/completions");
    assert_eq!(sent.authorization.as_deref(), Some("Bearer sk-upstream"));
    assert_eq!(
        sent.body["model"],
        json!("test-model"),
        "the upstream's model, not the caller's"
    );
    assert_eq!(sent.body["temperature"], json!(0.3));
    assert_eq!(sent.body["max_tokens"], json!(64));
    assert_eq!(sent.body["stop"], json!(["\n\n"]));
    assert!(sent.body.get("logicrag").is_none());
    let messages = sent.body["messages"].as_array().expect("messages");
    assert_eq!(messages.len(), 2);
    assert_eq!(
        messages[0],
        json!({"role": "system", "content": "Answer briefly."})
    );
    let (text, images) = parts(&messages[1]);
    assert_eq!(images, 2, "the window's frames are attached");
    assert!(
        text.contains("Question: Is the pedestrian walking?"),
        "{text}"
    );
    assert!(
        text.contains("The answer is yes: 1 binding satisfies the query."),
        "C2: {text}"
    );
    assert!(
        text.contains("Walk(pedestrian_5) follows by the rule"),
        "C2: {text}"
    );

    // C3 without a window: the first window that says yes is used.
    let got: Value = http
        .post(s.at("/v1/chat/completions"))
        .json(&json!({
            "messages": [{"role": "user", "content": "Is the pedestrian crossing the road?"}],
            "logicrag": {"condition": "c3"}
        }))
        .send()
        .expect("chat")
        .json()
        .expect("json");
    assert_eq!(got["choices"][0]["message"]["content"], json!("Maybe."));
    assert_eq!(got["logicrag"]["window"], json!("urban_crossing_000030"));
    assert_eq!(got["logicrag"]["condition"], json!("c3"));
    let sent = seen.lock().expect("log")[2].clone();
    let (text, _) = parts(&sent.body["messages"][0]);
    assert!(
        text.contains("pedestrian_5 is a pedestrian"),
        "C3 facts: {text}"
    );
    assert!(
        !text.contains("The answer is yes"),
        "C3 has no inference: {text}"
    );

    // A question the grammar cannot read goes upstream unchanged, and the
    // answer says no Logic-RAG context was added and why (it used to fall
    // back to C3 on the first window without a word: issue 23).
    let got: Value = http
        .post(s.at("/v1/chat/completions"))
        .json(&json!({"messages": [{"role": "user", "content": "Describe the weather please"}]}))
        .send()
        .expect("chat")
        .json()
        .expect("json");
    assert_eq!(got["logicrag"]["context_added"], json!(false));
    assert_eq!(got["logicrag"]["window"], Value::Null);
    assert!(
        got["logicrag"]["notes"][0]
            .as_str()
            .expect("note")
            .contains("cannot translate the question")
    );
    let sent = seen.lock().expect("log")[3].clone();
    assert_eq!(
        sent.body["messages"],
        json!([{"role": "user", "content": "Describe the weather please"}])
    );

    // An upstream error is a 502 with the upstream's message.
    let r = http
        .post(s.at("/v1/chat/completions"))
        .json(&json!({"messages": [{"role": "user", "content": "Is the pedestrian walking?"}]}))
        .send()
        .expect("chat");
    assert_json_error(r, StatusCode::BAD_GATEWAY, "model `m` does not exist");
    let upstream_calls = seen.lock().expect("log").len();
    assert_eq!(upstream_calls, 5);

    // Requests the proxy refuses never reach the upstream.
    for (body, says) in [
        (json!({"messages": []}), "`messages` is empty"),
        (
            json!({"messages": [{"role": "assistant", "content": "Hi"}]}),
            "last message must be the user's",
        ),
        (
            json!({"messages": [{"role": "user", "content": [{"image_url": {"url": "data:image/png;base64,AA=="}}]}]}),
            "without a `type`",
        ),
        (
            json!({"messages": [{"role": "user", "content": "Moving(x)"}], "logicrag": {"condition": "c4"}}),
            "not a condition",
        ),
        (
            json!({"messages": [{"role": "user", "content": "Moving(x)"}], "logicrag": {"window": "nope"}}),
            "no window `nope`",
        ),
        (
            json!({"messages": [{"role": "user", "content": "Moving(x)"}], "logicrag": {"windows": "x"}}),
            "unknown field `windows`",
        ),
        (json!({"messages": "hi"}), "invalid type"),
    ] {
        let r = http
            .post(s.at("/v1/chat/completions"))
            .json(&body)
            .send()
            .expect("chat");
        let status = if says.starts_with("no window") {
            StatusCode::NOT_FOUND
        } else {
            StatusCode::BAD_REQUEST
        };
        assert_json_error(r, status, says);
    }
    assert_eq!(seen.lock().expect("log").len(), upstream_calls);
}

#[test]
fn serve_translates_what_the_grammar_refuses_through_the_llm_with_translator_auto() {
    let (url, seen) = upstream(vec![(200, completion("Pedestrian(x)^Walk(x)").to_string())]);
    let s = Served::start(
        &["--source", SOURCE, "--translator", "auto", "--llm", &url],
        &[],
    );
    let http = client();
    let ask = |q: &str| -> (StatusCode, Value) {
        let r = http
            .post(s.at("/api/ask"))
            .json(&json!({"question": q, "window": "urban_crossing_000030"}))
            .send()
            .expect("ask");
        let status = r.status();
        (status, r.json().expect("json"))
    };
    // The grammar reads this one: no request reaches the LLM.
    let (status, v) = ask("Is the pedestrian walking?");
    assert_eq!(status, StatusCode::OK, "{v}");
    assert!(seen.lock().expect("log").is_empty());
    // The grammar refuses this one: the LLM's checked query is answered.
    let (status, v) = ask("Is someone sauntering?");
    assert_eq!(status, StatusCode::OK, "{v}");
    assert_eq!(v["summary"]["query"], json!("Pedestrian(x)^Walk(x)"), "{v}");
    assert_eq!(v["results"][0]["answer"], json!("yes"), "{v}");
    assert_eq!(seen.lock().expect("log").len(), 1);
    // Without --llm, an LLM translator is refused at start.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_logicrag"))
        .args([
            "serve",
            "--port",
            "0",
            "--source",
            SOURCE,
            "--translator",
            "llm",
        ])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--translator llm needs --llm URL"));
}
