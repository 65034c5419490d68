//! The LMM client and LLM translator against a scripted OpenAI-compatible
//! server on 127.0.0.1: real sockets, real HTTP and JSON, no mocked client.

use crate::common;
use logicpad::LogicPad;
use logicrag::llm::cache::Cache;
use logicrag::llm::client::{ApiKey, Client, LlmConfig, LlmError, Message};
use logicrag::llm::translate::{LlmTranslateError, LlmTranslator};
use logicrag::llm::{Chat, Condition, Lmm, Templates, Verdict};
use serde_json::Value;
use std::io::{BufReader, Write};
use std::net::TcpListener;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// One request as the server saw it.
#[derive(Debug, Clone)]
struct Seen {
    path: String,
    authorization: Option<String>,
    body: Value,
}

/// A reply: status, extra headers, body.
type Reply = (u16, Vec<(String, String)>, String);

/// A server on 127.0.0.1 answering each request with the next scripted
/// reply (the last one repeats); it records every request.
struct Server {
    url: String,
    seen: Arc<Mutex<Vec<Seen>>>,
}

fn completion(text: &str) -> Reply {
    let body = serde_json::json!({
        "id": "x", "object": "chat.completion",
        "choices": [{"index": 0, "message": {"role": "assistant", "content": text}, "finish_reason": "stop"}]
    });
    (200, Vec::new(), body.to_string())
}

impl Server {
    fn start(script: Vec<Reply>) -> Server {
        let listener = TcpListener::bind("127.0.0.1:0").expect("bind loopback");
        let url = format!("http://{}/v1", listener.local_addr().expect("addr"));
        let seen = Arc::new(Mutex::new(Vec::new()));
        let log = Arc::clone(&seen);
        std::thread::spawn(move || {
            let mut n = 0usize;
            for stream in listener.incoming() {
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
                let (status, headers, text) = script[n.min(script.len() - 1)].clone();
                n += 1;
                let mut resp = format!(
                    "HTTP/1.1 {status} X\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n",
                    text.len()
                );
                for (k, v) in headers {
                    resp.push_str(&format!("{k}: {v}\r\n"));
                }
                resp.push_str("\r\n");
                resp.push_str(&text);
                let _ = stream.write_all(resp.as_bytes());
            }
        });
        Server { url, seen }
    }

    fn seen(&self) -> Vec<Seen> {
        self.seen.lock().expect("log").clone()
    }
}

fn chat(url: &str, key: Option<&str>, cache: Option<Cache>) -> Chat {
    let mut config = LlmConfig::new(url, "test-model", key.and_then(ApiKey::new)).expect("config");
    config.backoff = Duration::from_millis(10);
    config.request_timeout = Duration::from_secs(5);
    config.connect_timeout = Duration::from_secs(2);
    Chat {
        client: Client::new(config).expect("client"),
        cache,
    }
}

fn context() -> logicrag::context::RagContext {
    let pad = LogicPad::builtin();
    let spec = "sim:urban_crossing".parse().expect("spec");
    let loaded =
        logicrag::source::load(&spec, &Default::default(), &mut |_| {}).expect("sim loads");
    let engine = logicrag::engine::Engine::new(pad, loaded.observability.clone()).expect("engine");
    let input = loaded.windows.into_iter().nth(2).expect("window 2");
    let kb = engine.build(input).expect("kb");
    let p = engine
        .prepare("Is the pedestrian walking?")
        .expect("translates");
    let r = engine.ask(&kb, &p, Default::default());
    logicrag::context::RagContext::new(&kb, p.question.as_deref(), &r, engine.words())
}

#[test]
fn c1_carries_no_logic_context_and_c2_c3_do() {
    let server = Server::start(vec![completion("Yes. The pedestrian walks across.")]);
    let lmm = Lmm {
        chat: chat(&server.url, None, None),
        templates: Templates::default(),
    };
    let ctx = context();
    let png = vec![0x89, b'P', b'N', b'G', 1, 2, 3];
    for c in Condition::ALL {
        let a = lmm
            .ask(
                c,
                "Is the pedestrian walking?",
                &ctx,
                &[png.clone(), png.clone()],
            )
            .expect("answer");
        assert_eq!(a.verdict, Verdict::Yes);
        assert_eq!(a.frames, 2);
    }
    let seen = server.seen();
    assert_eq!(seen.len(), 3);
    for s in &seen {
        assert_eq!(s.path, "/v1/chat/completions");
        assert_eq!(s.body["model"], "test-model");
        assert_eq!(s.body["temperature"], 0.0);
        let parts = s.body["messages"][0]["content"]
            .as_array()
            .expect("content parts");
        let images = parts.iter().filter(|p| p["type"] == "image_url").count();
        assert_eq!(images, 2, "every condition attaches the frames");
        assert!(
            parts[0]["image_url"]["url"]
                .as_str()
                .unwrap_or_default()
                .starts_with("data:image/png;base64,")
        );
    }
    let text = |i: usize| -> String {
        seen[i].body["messages"][0]["content"]
            .as_array()
            .and_then(|p| p.last())
            .and_then(|p| p["text"].as_str())
            .unwrap_or_default()
            .to_string()
    };
    assert!(
        !text(0).contains("reasoner") && !text(0).contains("perceived"),
        "C1: {}",
        text(0)
    );
    assert!(text(1).contains("The answer is yes"), "C2: {}", text(1));
    assert!(
        text(2).contains("pedestrian_5 is a pedestrian"),
        "C3: {}",
        text(2)
    );
    assert!(
        !text(2).contains("The answer is"),
        "C3 has no inference: {}",
        text(2)
    );
}

#[test]
fn the_cache_prevents_a_second_request() {
    let server = Server::start(vec![completion("No.")]);
    let dir = std::env::temp_dir().join(format!("logicrag-llm-cache-{}", std::process::id()));
    let c = chat(&server.url, None, Some(Cache::new(&dir)));
    let m = [Message::text("user", "Is it raining?")];
    let (a, cached_a) = c.reply(&m).expect("first");
    let (b, cached_b) = c.reply(&m).expect("second");
    std::fs::remove_dir_all(&dir).expect("clean");
    assert_eq!((a.as_str(), cached_a), ("No.", false));
    assert_eq!((b.as_str(), cached_b), ("No.", true));
    assert_eq!(server.seen().len(), 1);
}

#[test]
fn an_undeclared_predicate_triggers_a_repair_that_quotes_the_diagnostic() {
    let server = Server::start(vec![
        completion("Pedestrian(x)^Strolling(x)"),
        completion("Pedestrian(x)^Walk(x)"),
    ]);
    let pad = LogicPad::builtin();
    let c = chat(&server.url, None, None);
    let templates = Templates::default();
    let t = LlmTranslator {
        chat: &c,
        templates: &templates,
        pad: &pad,
        repairs: 2,
    };
    let out = t
        .translate("Is the pedestrian strolling?")
        .expect("repaired");
    assert_eq!(out.query, "Pedestrian(x)^Walk(x)");
    assert_eq!(out.rounds.len(), 2);
    let seen = server.seen();
    let first = seen[0].body["messages"][0]["content"]
        .as_str()
        .unwrap_or_default();
    assert!(
        first.contains("Walk(x)") && first.contains("Question: Is the pedestrian strolling?"),
        "{first}"
    );
    let repair = seen[1].body["messages"][2]["content"]
        .as_str()
        .unwrap_or_default();
    assert!(repair.contains("unknown predicate `Strolling`"), "{repair}");
    assert_eq!(
        seen[1].body["messages"][1]["content"],
        "Pedestrian(x)^Strolling(x)"
    );
}

#[test]
fn the_llm_translator_takes_the_new_forms_and_checks_each_part() {
    // Scoped negation, a count and a time order are accepted as written;
    // a temporal reply with an unknown predicate in its second part is
    // repaired like any invalid query.
    let pad = LogicPad::builtin();
    let templates = Templates::default();
    for query in [
        "Pedestrian(x)^Walk(x)^¬∃y: (Road(y)^On(x, y))",
        "#{x: TypeOf(x, Car)} > 2",
        "(TypeOf(x, Car)^Decelerate(x)) THEN (TypeOf(x, Car)^Stopped(x))",
    ] {
        let server = Server::start(vec![completion(query)]);
        let c = chat(&server.url, None, None);
        let t = LlmTranslator {
            chat: &c,
            templates: &templates,
            pad: &pad,
            repairs: 1,
        };
        let out = t.translate("an everyday question").expect("accepted");
        assert_eq!(out.query, query);
        assert_eq!(out.rounds.len(), 1);
    }
    let server = Server::start(vec![
        completion("(Decelerate(x)) THEN (Halted(x))"),
        completion("(Decelerate(x)) THEN (Stopped(x))"),
    ]);
    let c = chat(&server.url, None, None);
    let t = LlmTranslator {
        chat: &c,
        templates: &templates,
        pad: &pad,
        repairs: 1,
    };
    let out = t
        .translate("Did it slow down and then halt?")
        .expect("repaired");
    assert_eq!(out.query, "(Decelerate(x)) THEN (Stopped(x))");
    let repair = server.seen()[1].body["messages"][2]["content"]
        .as_str()
        .unwrap_or_default()
        .to_string();
    assert!(repair.contains("Halted"), "{repair}");
}

#[test]
fn a_query_still_invalid_after_the_repairs_is_refused() {
    let server = Server::start(vec![completion("Levitates(x)")]);
    let pad = LogicPad::builtin();
    let c = chat(&server.url, None, None);
    let templates = Templates::default();
    let t = LlmTranslator {
        chat: &c,
        templates: &templates,
        pad: &pad,
        repairs: 1,
    };
    let e = t.translate("Does anything levitate?").expect_err("refused");
    assert!(
        matches!(e, LlmTranslateError::Invalid { rounds: 2, .. }),
        "{e}"
    );
    assert_eq!(server.seen().len(), 2);
    let server = Server::start(vec![completion("CANNOT: nothing describes hats")]);
    let c = chat(&server.url, None, None);
    let t = LlmTranslator { chat: &c, ..t };
    assert!(matches!(
        t.translate("Is the driver wearing a hat?"),
        Err(LlmTranslateError::Cannot(_))
    ));
}

#[test]
fn errors_are_clear_quick_and_keep_the_key_secret() {
    // 500 then 429 with Retry-After, then the server's own message.
    let server = Server::start(vec![
        (500, vec![], r#"{"error": {"message": "boom"}}"#.into()),
        (
            429,
            vec![("Retry-After".into(), "0".into())],
            r#"{"error": {"message": "slow down"}}"#.into(),
        ),
        completion("Yes."),
    ]);
    let c = chat(&server.url, Some("sk-top-secret"), None);
    let (reply, _) = c
        .reply(&[Message::text("user", "q")])
        .expect("retried to success");
    assert_eq!(reply, "Yes.");
    let seen = server.seen();
    assert_eq!(seen.len(), 3);
    assert_eq!(
        seen[0].authorization.as_deref(),
        Some("Bearer sk-top-secret")
    );
    // A 400 is not retried and shows the server's message; the key is redacted.
    let server = Server::start(vec![(
        400,
        vec![],
        r#"{"error": {"message": "bad key sk-top-secret"}}"#.into(),
    )]);
    let c = chat(&server.url, Some("sk-top-secret"), None);
    let e = c.reply(&[Message::text("user", "q")]).expect_err("400");
    let text = e.to_string();
    assert!(
        text.contains("400") && text.contains("bad key <redacted>"),
        "{text}"
    );
    assert!(!text.contains("sk-top-secret") && !format!("{e:?}").contains("sk-top-secret"));
    assert_eq!(server.seen().len(), 1);
    // A server that is down: a clear error within seconds.
    let port = TcpListener::bind("127.0.0.1:0")
        .expect("bind")
        .local_addr()
        .expect("addr")
        .port();
    let c = chat(&format!("http://127.0.0.1:{port}/v1"), None, None);
    let start = Instant::now();
    let e = c.reply(&[Message::text("user", "q")]).expect_err("down");
    assert!(matches!(e, LlmError::Unreachable { .. }), "{e}");
    assert!(start.elapsed() < Duration::from_secs(10));
}

fn logicrag(args: &[&str], env: &[(&str, &str)]) -> std::process::Output {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_logicrag"));
    cmd.args(args)
        .env_remove("LOGICRAG_LLM_URL")
        .env_remove("LOGICRAG_API_KEY")
        .env_remove("OPENAI_API_KEY");
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("logicrag runs")
}

#[test]
fn ask_lmm_attaches_the_kitti_frames_and_prints_the_verdict() {
    let Some(shared) = std::env::var_os("CARGO_MANIFEST_DIR")
        .map(|d| std::path::PathBuf::from(d).join("../../shared"))
        .filter(|p| p.join("data/kitti-tracking/image_02/0001").is_dir())
    else {
        eprintln!("SKIPPED: ../shared is not present");
        return;
    };
    let server = Server::start(vec![completion("No, there is none.")]);
    let kitti = format!("kitti:{}", shared.join("data/kitti-tracking").display());
    let out = logicrag(
        &[
            "ask",
            "--source",
            &kitti,
            "--sequence",
            "0001",
            "--frames",
            "10-19",
            "--lmm",
            "c1",
            "--llm",
            &server.url,
            "--no-lmm-cache",
            "--json",
            "Is there a van on the left?",
        ],
        &[("LOGICRAG_API_KEY", "sk-cli-secret")],
    );
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "{stderr}");
    assert!(!stdout.contains("sk-cli-secret") && !stderr.contains("sk-cli-secret"));
    let first: Value =
        serde_json::from_str(stdout.lines().next().unwrap_or_default()).expect("json");
    assert_eq!(first["lmm"]["verdict"], "no");
    assert_eq!(
        first["lmm"]["frames"], 2,
        "KITTI 0001 has images of frames 10 and 15 in 10-19"
    );
    let seen = server.seen();
    assert_eq!(seen.len(), 1);
    assert_eq!(
        seen[0].authorization.as_deref(),
        Some("Bearer sk-cli-secret")
    );
    let parts = seen[0].body["messages"][0]["content"]
        .as_array()
        .expect("parts");
    assert_eq!(parts.iter().filter(|p| p["type"] == "image_url").count(), 2);
}

#[test]
fn ask_lmm_with_a_server_down_exits_2_quickly_and_a_grammar_refusal_goes_to_the_llm() {
    let port = TcpListener::bind("127.0.0.1:0")
        .expect("bind")
        .local_addr()
        .expect("addr")
        .port();
    let url = format!("http://127.0.0.1:{port}/v1");
    let start = Instant::now();
    let out = logicrag(
        &[
            "ask",
            "--window-id",
            "urban_crossing_000000",
            "--lmm",
            "c2",
            "--llm",
            &url,
            "--no-lmm-cache",
            "Is the pedestrian walking?",
        ],
        &[],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot reach the LLM server"));
    assert!(start.elapsed() < Duration::from_secs(20));
    // No server named: a clear error.
    let out = logicrag(&["ask", "--lmm", "c1", "Is the pedestrian walking?"], &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--llm URL"));
    // auto: the grammar refuses, the LLM's (checked) query is asked.
    let server = Server::start(vec![completion("Pedestrian(x)^Walk(x)")]);
    let out = logicrag(
        &[
            "translate",
            "--translator",
            "auto",
            "--llm",
            &server.url,
            "--no-lmm-cache",
            "Is the pedestrian strolling about?",
        ],
        &[],
    );
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.starts_with("Pedestrian(x)^Walk(x)"), "{stdout}");
    assert!(stdout.contains("translated by the LLM"), "{stdout}");
}

/// `context` translates through the same translator as `ask`: a question
/// the grammar refuses goes to the LLM under `--translator auto`, and its
/// query's answer is the context's inference.
#[test]
fn context_takes_the_translator_of_ask() {
    let server = Server::start(vec![completion("Pedestrian(x)^Walk(x)")]);
    let out = logicrag(
        &[
            "context",
            "--source",
            "sim:urban_crossing",
            "--window-id",
            "urban_crossing_000020",
            "--translator",
            "auto",
            "--llm",
            &server.url,
            "--no-lmm-cache",
            "--json",
            "Is the pedestrian strolling about?",
        ],
        &[],
    );
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("Pedestrian(x)^Walk(x)"), "{stdout}");
    // Without an LLM the grammar's refusal is the error, as for `ask`.
    let out = logicrag(
        &[
            "context",
            "--source",
            "sim:urban_crossing",
            "Is the pedestrian strolling about?",
        ],
        &[],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot translate the question"));
}

/// `eval` goes through the pipeline's translator too: with `--translator
/// auto` a question the grammar refuses is translated by the LLM (once,
/// however often it is asked) and scored; without an LLM it is scored
/// invalid with the grammar's reason.
#[test]
fn eval_takes_the_translator_of_ask() {
    let server = Server::start(vec![completion("Pedestrian(x)^Walk(x)")]);
    let dir = std::env::temp_dir().join(format!("logicrag-eval-llm-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let csv = dir.join("questions.csv");
    std::fs::write(
        &csv,
        "Question,Answer,Window\n\
         Is someone sauntering?,yes,urban_crossing_000030\n\
         Is someone sauntering?,yes,urban_crossing_000030\n\
         Is the pedestrian walking?,yes,urban_crossing_000030\n",
    )
    .expect("write");
    let eval = |extra: &[&str]| {
        let mut args = vec![
            "eval",
            "--source",
            "sim:urban_crossing",
            "--questions",
            csv.to_str().expect("utf-8"),
            "--json",
        ];
        args.extend_from_slice(extra);
        let out = logicrag(&args, &[]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
        v["sources"][0]["records"].clone()
    };
    let records = eval(&[
        "--translator",
        "auto",
        "--llm",
        &server.url,
        "--no-lmm-cache",
    ]);
    assert_eq!(
        records[0]["query"]["Ok"], "Pedestrian(x)^Walk(x)",
        "{records}"
    );
    assert_eq!(records[0]["said"], "yes", "{records}");
    assert_eq!(records[1]["query"], records[0]["query"]);
    assert_eq!(
        records[2]["query"]["Ok"], "Pedestrian(x)^Walk(x)",
        "{records}"
    );
    assert_eq!(
        server.seen().len(),
        1,
        "one translation per distinct question"
    );
    let records = eval(&[]);
    let why = records[0]["query"]["Err"].as_str().unwrap_or_default();
    assert!(!why.is_empty(), "{records}");
    assert!(!why.starts_with("cannot translate"), "{why}");
    assert_eq!(records[0]["said"], "invalid", "{records}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Standard base64 (RFC 4648, padded) back to bytes; `None` on a stray
/// character.
fn unbase64(text: &str) -> Option<Vec<u8>> {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    for c in text.bytes().filter(|c| *c != b'=') {
        let v = ALPHABET.iter().position(|a| *a == c)? as u32;
        acc = (acc << 6) | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
        }
    }
    Some(out)
}

#[test]
fn ask_lmm_on_the_simulator_attaches_its_rendered_camera_frames() {
    let server = Server::start(vec![completion("Yes.")]);
    let out = logicrag(
        &[
            "ask",
            "--source",
            "sim:urban_crossing",
            "--window-id",
            "urban_crossing_000020",
            "--lmm",
            "c1",
            "--llm",
            &server.url,
            "--no-lmm-cache",
            "--json",
            "Is the pedestrian walking?",
        ],
        &[],
    );
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("no pictures"), "{stderr}");
    let first: Value =
        serde_json::from_str(stdout.lines().next().unwrap_or_default()).expect("json");
    assert_eq!(first["lmm"]["frames"], 5);
    let seen = server.seen();
    assert_eq!(seen.len(), 1);
    let parts = seen[0].body["messages"][0]["content"]
        .as_array()
        .expect("parts");
    let images: Vec<&str> = parts
        .iter()
        .filter(|p| p["type"] == "image_url")
        .filter_map(|p| p["image_url"]["url"].as_str())
        .collect();
    assert_eq!(images.len(), 5, "five frames sampled over frames 20–29");
    // Each is a PNG of the camera's view, scaled to the model's size.
    let k = perception::sim::Scenario::builtin("urban_crossing")
        .expect("built in")
        .camera
        .intrinsics;
    for url in &images {
        let data = url
            .strip_prefix("data:image/png;base64,")
            .expect("a PNG data URL");
        let png = image::load_from_memory(&unbase64(data).expect("base64")).expect("decodes");
        assert_eq!(
            png.width(),
            logicrag::images::DEFAULT_MAX_SIDE.min(k.image_width)
        );
        let aspect = f64::from(png.width()) / f64::from(png.height());
        let expected = f64::from(k.image_width) / f64::from(k.image_height);
        assert!((aspect - expected).abs() < 0.02, "{aspect} vs {expected}");
    }
    assert_ne!(images[0], images[4], "the scene changes over the window");
}

#[test]
fn eval_lmm_prints_the_papers_table_saves_every_reply_and_reruns_from_the_cache() {
    let server = Server::start(vec![completion("Yes, clearly.")]);
    let dir = std::env::temp_dir().join(format!("logicrag-eval-lmm-{}", std::process::id()));
    let (out_dir, cache) = (dir.join("out"), dir.join("cache"));
    let args = |out: &str, cache: &str| -> Vec<String> {
        [
            "eval",
            "--source",
            "sim:braking",
            "--lmm",
            "c1,c3",
            "--llm",
            &server.url,
            "--llm-parallel",
            "2",
            "--lmm-cache",
            cache,
            "--out",
            out,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let run = |a: &[String]| {
        let refs: Vec<&str> = a.iter().map(String::as_str).collect();
        logicrag(&refs, &[])
    };
    let a = args(
        out_dir.to_str().expect("utf-8"),
        cache.to_str().expect("utf-8"),
    );
    let out = run(&a);
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let header = stdout
        .lines()
        .find(|l| l.starts_with("category") && l.contains("LR acc"))
        .unwrap_or_default();
    assert!(
        header.contains("LR acc") && header.contains("C1 acc") && header.contains("C3 acc"),
        "{stdout}"
    );
    let jsonl = std::fs::read_to_string(out_dir.join("lmm.jsonl")).expect("lmm.jsonl written");
    let lines: Vec<Value> = jsonl
        .lines()
        .map(|l| serde_json::from_str(l).expect("json line"))
        .collect();
    let questions = lines.len() / 2;
    assert!(
        questions >= 5 && lines.len() == 2 * questions,
        "{} lines",
        lines.len()
    );
    assert!(lines.iter().all(|l| l["verdict"] == "yes"
        && l["reply"] == "Yes, clearly."
        && l["prompt"].is_string()));
    let sent = server.seen().len();
    assert_eq!(sent, lines.len(), "one request per question and condition");
    // A re-run costs no request and gives the same table.
    let again = run(&a);
    assert!(again.status.success());
    assert_eq!(server.seen().len(), sent);
    assert_eq!(String::from_utf8_lossy(&again.stdout), stdout);
    std::fs::remove_dir_all(&dir).expect("clean");
}

/// A LogicPad file to append to: the built-in one, copied.
fn pad_copy(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("logicrag-rule-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("pad.yaml");
    std::fs::write(&path, logicpad::BUILTIN_SOURCE).expect("write pad");
    path
}

#[test]
fn rule_from_english_by_the_grammar_is_appended_and_the_next_question_uses_it() {
    let pad = pad_copy("grammar");
    let sentence = "A pedestrian is jaywalking when it is on a road and moving";
    let out = logicrag(
        &[
            "rule",
            sentence,
            "--append",
            pad.to_str().expect("utf-8"),
            "--json",
        ],
        &[],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(
        v["rule"],
        "∀x : Pedestrian(x) ∧ Road(y) ∧ On(x, y) ∧ Move(x) ==> Jaywalking(x)"
    );
    assert_eq!(v["via"], "grammar");
    let text = std::fs::read_to_string(&pad).expect("read pad");
    let line = v["appended"]["line"].as_u64().expect("line") as usize;
    assert_eq!(
        text.lines().nth(line - 1),
        Some(format!("  # {sentence}").as_str()),
        "the sentence is the comment above the entry"
    );
    // The file loads clean, and a question uses the new predicate; the
    // proof cites the rule.
    let lint = logicrag(&["lint", pad.to_str().expect("utf-8")], &[]);
    assert_eq!(
        lint.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&lint.stdout)
    );
    let ask = logicrag(
        &[
            "ask",
            "--logicpad",
            pad.to_str().expect("utf-8"),
            "--window-id",
            "urban_crossing_000030",
            "Is a pedestrian jaywalking?",
        ],
        &[],
    );
    let said = String::from_utf8_lossy(&ask.stdout).to_string();
    assert!(said.contains("Pedestrian(x)^Jaywalking(x) → YES"), "{said}");
    assert!(
        said.contains("==> Jaywalking(x)]"),
        "the proof cites the rule: {said}"
    );
    // A second definition of a declared predicate is refused; the file is unchanged.
    let before = std::fs::read_to_string(&pad).expect("read pad");
    let out = logicrag(
        &[
            "rule",
            "A car is stopped when it is on a road",
            "--append",
            pad.to_str().expect("utf-8"),
        ],
        &[],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("already declared"));
    assert_eq!(std::fs::read_to_string(&pad).expect("read pad"), before);
}

#[test]
fn rule_from_english_the_grammar_refuses_goes_to_the_llm_whose_rejected_rule_is_repaired() {
    let server = Server::start(vec![
        completion("∀x : Pedestrian(x) ∧ Strolling(x) ==> Dawdling(x)"),
        completion(
            "Rule: `∀x : Pedestrian(x) ∧ ¬Moving(x) ∧ On(x, y) ∧ Sidewalk(y) ==> Dawdling(x)`",
        ),
    ]);
    let pad = pad_copy("llm");
    let out = logicrag(
        &[
            "rule",
            "Pedestrians that linger on the sidewalk are dawdling",
            "--translator",
            "auto",
            "--llm",
            &server.url,
            "--no-lmm-cache",
            "--append",
            pad.to_str().expect("utf-8"),
            "--json",
        ],
        &[],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(v["via"], "llm");
    assert_eq!(v["name"], "Dawdling");
    let seen = server.seen();
    assert_eq!(seen.len(), 2);
    let first = seen[0].body["messages"][0]["content"]
        .as_str()
        .unwrap_or_default();
    assert!(
        first.contains("Definition: Pedestrians that linger on the sidewalk are dawdling"),
        "{first}"
    );
    let repair = seen[1].body["messages"][2]["content"]
        .as_str()
        .unwrap_or_default();
    assert!(repair.contains("unknown predicate `Strolling`"), "{repair}");
    let text = std::fs::read_to_string(&pad).expect("read pad");
    assert!(text.contains("==> Dawdling(x)\""), "{text}");
    // Without --llm the grammar's refusal is the error, with its advice.
    let out = logicrag(&["rule", "Pedestrians that linger are dawdling"], &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot read"));
}

#[test]
fn the_repl_sends_what_the_grammar_refuses_to_the_llm_in_auto_mode_and_switches_modes() {
    use logicrag::engine::{LlmSetup, TranslatorMode};
    let server = Server::start(vec![completion("Pedestrian(x)^Walk(x)")]);
    let loaded = logicrag::source::load(
        &"sim:urban_crossing".parse().expect("spec"),
        &logicrag::source::LoadOptions::default(),
        &mut |_| {},
    )
    .expect("loads");
    let engine =
        logicrag::engine::Engine::new(LogicPad::builtin(), loaded.observability).expect("engine");
    let pipeline = logicrag::pipeline::Pipeline::new(loaded.label, engine, loaded.windows);
    let mut s = logicrag::repl::Session::new(pipeline, None).expect("session");
    // Grammar (the default): refused, with no request sent.
    let out = s.handle("Is someone sauntering?");
    assert!(out.contains("cannot translate the question"), "{out}");
    assert!(s.handle(":translator auto").contains("needs an LLM server"));
    s.set_translator(
        TranslatorMode::Auto,
        Some(LlmSetup {
            chat: chat(&server.url, None, None),
            templates: Templates::default(),
            repairs: 1,
        }),
    );
    assert!(server.seen().is_empty());
    let out = s.handle("Is someone sauntering?");
    assert!(out.contains("query: Pedestrian(x)^Walk(x)"), "{out}");
    assert!(out.contains("translated by the LLM"), "{out}");
    assert_eq!(server.seen().len(), 1);
    // What the grammar reads never reaches the LLM in auto mode.
    let out = s.handle("Is the pedestrian walking?");
    assert!(out.contains("query: Pedestrian(x)^Walk(x)"), "{out}");
    assert_eq!(server.seen().len(), 1);
    // `:define` follows the same mode: what the grammar cannot read goes to
    // the LLM (whose reply here is a query, not a rule: refused, after one
    // repair round, with both reasons).
    let out = s.handle(":define Pedestrians that linger are dawdling");
    assert!(
        out.starts_with("no rule added: cannot make a rule of the definition: the grammar:"),
        "{out}"
    );
    assert!(out.contains("the LLM:"), "{out}");
    assert_eq!(server.seen().len(), 3);
    assert_eq!(
        s.handle(":translator grammar").trim(),
        "translator: grammar"
    );
    assert!(
        s.handle("Is someone sauntering?")
            .contains("cannot translate the question")
    );
    assert!(
        s.handle(":translator")
            .contains("grammar (an LLM server is set)")
    );
    assert!(
        s.handle(":translator sometimes")
            .contains("expected grammar, llm or auto")
    );
}
