//! Opt-in: the translator and C2 against a real OpenAI-compatible server
//! (`scripts/local-llm.sh`). Ignored by default; run with
//! `LOGICRAG_LLM_URL=http://127.0.0.1:8080/v1 cargo test -p logicrag --test integration llm_real:: -- --ignored`.

use logicpad::LogicPad;
use logicrag::llm::client::{Client, LlmConfig};
use logicrag::llm::translate::{LlmTranslateError, LlmTranslator};
use logicrag::llm::{Chat, Condition, Lmm, Templates};

fn chat() -> Option<Chat> {
    let Ok(url) = std::env::var("LOGICRAG_LLM_URL") else {
        eprintln!("SKIPPED: set LOGICRAG_LLM_URL to a running server (scripts/local-llm.sh)");
        return None;
    };
    let model = std::env::var("LOGICRAG_LLM_MODEL").unwrap_or_else(|_| "gemma-3-270m".into());
    let config = LlmConfig::new(&url, &model, None).expect("a valid URL");
    Some(Chat {
        client: Client::new(config).expect("client"),
        cache: None,
    })
}

#[test]
#[ignore = "needs a running server: scripts/local-llm.sh"]
fn a_real_server_translates_and_answers_c2() {
    let Some(chat) = chat() else { return };
    let pad = LogicPad::builtin();
    let templates = Templates::default();
    let t = LlmTranslator {
        chat: &chat,
        templates: &templates,
        pad: &pad,
        repairs: 2,
    };
    // A tiny model may fail to produce a valid query: then it must be a
    // clear refusal, never a weakened query.
    match t.translate("Is the pedestrian walking?") {
        Ok(out) => {
            assert!(
                logicrag::ask::prepare(&pad, &out.query).is_ok(),
                "{}",
                out.query
            );
            eprintln!("translated in {} round(s): {}", out.rounds.len(), out.query);
        }
        Err(e @ (LlmTranslateError::Invalid { .. } | LlmTranslateError::Cannot(_))) => {
            eprintln!("refused: {e}");
        }
        Err(e) => panic!("the server failed: {e}"),
    }
    let spec = "sim:urban_crossing".parse().expect("spec");
    let loaded = logicrag::source::load(&spec, &Default::default(), &mut |_| {}).expect("sim");
    let engine =
        logicrag::engine::Engine::new(pad.clone(), loaded.observability.clone()).expect("engine");
    let kb = engine
        .build(loaded.windows.into_iter().nth(2).expect("window"))
        .expect("kb");
    let p = engine
        .prepare("Is the pedestrian walking?")
        .expect("grammar");
    let r = engine.ask(&kb, &p, Default::default());
    let ctx = logicrag::context::RagContext::new(&kb, p.question.as_deref(), &r, engine.words());
    let lmm = Lmm { chat, templates };
    let a = lmm
        .ask(Condition::C2, "Is the pedestrian walking?", &ctx, &[])
        .expect("a reply");
    eprintln!("C2 reply ({}): {}", a.verdict.as_str(), a.reply);
    assert!(!a.reply.trim().is_empty());
}
