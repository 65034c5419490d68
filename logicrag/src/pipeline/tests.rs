use super::*;
use crate::ask::Outcome;
use crate::engine::TranslatorMode;
use std::sync::atomic::{AtomicUsize, Ordering};

fn braking() -> Pipeline {
    Pipeline::open_default("sim:braking")
}

/// A translator that turns every question into one query and counts
/// the questions it was given.
#[derive(Debug, Default)]
struct Fixed {
    asked: AtomicUsize,
}

impl Translate for Fixed {
    fn mode(&self) -> TranslatorMode {
        TranslatorMode::Llm
    }
    fn translate(&self, engine: &Engine, question: &str) -> Result<Prepared, PrepareError> {
        self.asked.fetch_add(1, Ordering::SeqCst);
        let mut p = engine.prepare_query("Moving(x)");
        p.question = Some(question.to_string());
        Ok(p)
    }
    fn translate_offline(&self, _: &Engine, _: &str) -> Option<Result<Prepared, PrepareError>> {
        None
    }
}

#[test]
fn an_opened_source_answers_window_by_window() {
    let src = braking();
    assert_eq!(src.label(), "sim:braking");
    let n = src.windows().len();
    assert!(n > 1);
    assert_eq!(src.window_count(), n);

    // A wrong window id fails before anything is reasoned.
    let err = crate::json::ask_value(&src, "Moving(x)", Some("nope"), AskOptions::default())
        .expect_err("unknown window");
    assert!(matches!(err, SessionError::UnknownWindow(_)), "{err}");
    assert!(
        err.to_string()
            .starts_with("sim:braking has no window `nope` (it has braking_000000, ")
    );
    assert!(src.reasoned_windows().is_none());

    let all = crate::json::ask_value(&src, "Is a car slowing down?", None, AskOptions::default())
        .expect("asks");
    assert_eq!(all["results"].as_array().map(Vec::len), Some(n));
    assert_eq!(all["summary"]["question"], "Is a car slowing down?");
    assert_eq!(src.reasoned_windows().map(<[_]>::len), Some(n));
    let first = src.windows()[0].id.clone();
    let one = crate::json::ask_value(&src, "Moving(x)", Some(&first), AskOptions::default())
        .expect("asks");
    assert_eq!(one["results"][0]["window"], first.as_str());
    let ctx = crate::json::context_value(&src, "Moving(x)", &first).expect("context");
    assert!(ctx.is_object());

    let err = crate::json::ask_value(
        &src,
        "Is the zorblax frobnicating?",
        None,
        AskOptions::default(),
    )
    .expect_err("untranslatable");
    assert!(
        err.to_string()
            .starts_with("cannot translate the question: "),
        "{err}"
    );
}

#[test]
fn an_unknown_window_is_said_the_same_way_by_every_method() {
    let src = braking();
    let want = src.no_window("nope").to_string();
    assert!(
        want.starts_with("sim:braking has no window `nope`"),
        "{want}"
    );
    let p = src.prepare("Moving(x)").expect("a query");
    let said = |e: SessionError| {
        assert!(matches!(e, SessionError::UnknownWindow(_)), "{e}");
        crate::session::message(&e)
    };
    let opts = AskOptions::default();
    let page = Page {
        offset: 0,
        limit: 1,
    };
    let mut messages = vec![
        said(src.ask(&p, Some("nope"), opts).expect_err("ask")),
        said(
            src.ask_page(&p, Some("nope"), opts, page)
                .expect_err("page"),
        ),
        said(src.contexts(&p, Some("nope")).expect_err("contexts")),
        said(src.select(Some("nope")).expect_err("select")),
        said(src.window("nope").expect_err("window")),
        said(src.position("nope").expect_err("position")),
        said(crate::json::ask_value(&src, "Moving(x)", Some("nope"), opts).expect_err("ask_json")),
        said(crate::json::context_value(&src, "Moving(x)", "nope").expect_err("context")),
    ];
    #[cfg(feature = "serve")]
    messages.push(said(
        crate::serve::retrieve::documents(
            &src,
            &p,
            Some("nope"),
            opts,
            page,
            crate::serve::retrieve::Limits {
                windows: 1,
                facts: 1,
            },
        )
        .expect_err("retrieve"),
    ));
    #[cfg(feature = "arrow")]
    match crate::arrow::facts_table(&src, Some("nope")).expect_err("facts") {
        crate::arrow::TableError::Session(e) => messages.push(said(*e)),
        other => panic!("a window error, not {other}"),
    }
    assert!(
        src.reasoned_windows().is_none(),
        "no reasoning for a wrong id"
    );
    // Reasoned or not, narrowed or not, the same sentence.
    src.kbs().expect("reasons");
    messages.push(said(src.window("nope").expect_err("reasoned")));
    messages.push(said(braking().only(Some("nope")).expect_err("only")));
    for m in &messages {
        assert_eq!(m, &want);
    }
}

#[test]
fn questions_go_through_the_pipelines_translator_and_queries_do_not() {
    let fixed = Arc::new(Fixed::default());
    let src = braking().with_translator(Arc::clone(&fixed) as Arc<dyn Translate>);
    assert_eq!(src.translator().mode(), TranslatorMode::Llm);
    let p = src.prepare("Is anything on the move?").expect("translated");
    assert_eq!(p.query, "Moving(x)");
    assert_eq!(fixed.asked.load(Ordering::SeqCst), 1);
    let answers = src.ask(&p, None, AskOptions::BINDINGS).expect("answers");
    assert_eq!(answers.len(), src.window_count());
    // A query is taken as written, and needs no server.
    let q = src.prepare("Stopped(x)").expect("a query");
    assert_eq!(q.query, "Stopped(x)");
    assert!(src.prepare_offline("Stopped(x)").is_some());
    // A question only the server can translate is not guessed offline.
    assert!(src.prepare_offline("Is anything on the move?").is_none());
    assert_eq!(fixed.asked.load(Ordering::SeqCst), 1);
    let json =
        crate::json::ask_value(&src, "Anything moving?", None, AskOptions::BINDINGS).expect("asks");
    assert_eq!(json["summary"]["query"], "Moving(x)");
    assert_eq!(fixed.asked.load(Ordering::SeqCst), 2);
    // The grammar answers offline, its refusal included.
    let grammar = braking();
    assert!(matches!(
        grammar.prepare_offline("Is the zorblax frobnicating?"),
        Some(Err(PrepareError::Grammar(_)))
    ));
}

#[test]
fn a_temporal_query_is_answered_once_over_the_windows_up_to_the_one_asked() {
    let src = braking();
    let q = "(Decelerate(x)) THEN (Stopped(x))";
    let all = crate::json::ask_value(&src, q, None, AskOptions::default()).expect("asks");
    let results = all["results"].as_array().cloned().unwrap_or_default();
    assert_eq!(results.len(), 1, "{all}");
    assert_eq!(results[0]["window"], "sim:braking");
    assert_eq!(results[0]["temporal"]["form"], "then");
    assert_eq!(all["summary"]["summary"]["answer"], "yes");
    let headline = all["summary"]["headline"].as_str().unwrap_or_default();
    assert!(
        headline.contains(", then `Stopped(x)` in frames "),
        "{headline}"
    );
    // Every asking method gives that one answer, on the last window.
    let p = src.prepare(q).expect("a query");
    let last = src.windows().last().map(|w| w.id.clone());
    for answers in [
        src.ask(&p, None, AskOptions::BINDINGS).expect("ask"),
        src.ask_page(
            &p,
            None,
            AskOptions::BINDINGS,
            Page {
                offset: 0,
                limit: 1,
            },
        )
        .expect("page"),
    ] {
        assert_eq!(answers.len(), 1);
        assert_eq!(Some(answers[0].window.id.clone()), last);
        assert_eq!(answers[0].result.answer, crate::ask::Outcome::Yes);
    }
    assert_eq!(src.contexts(&p, None).expect("contexts").len(), 1);
    // Asked at the first window, only its frames are looked at: the
    // stop is in its future.
    let first = src.windows()[0].id.clone();
    let early = src
        .ask_temporal(&p, Some(&first), AskOptions::BINDINGS)
        .expect("asks")
        .expect("temporal");
    assert_eq!((early.windows, early.result.last_frame), (1, 9));
    assert_ne!(early.result.answer, crate::ask::Outcome::Yes);
    // A query that is not temporal is not answered here.
    let plain = src.prepare("Moving(x)").expect("a query");
    assert!(
        src.ask_temporal(&plain, None, AskOptions::BINDINGS)
            .expect("asks")
            .is_none()
    );
    let err = src
        .ask_temporal(&p, Some("nope"), AskOptions::BINDINGS)
        .expect_err("unknown window");
    assert!(matches!(err, SessionError::UnknownWindow(_)), "{err}");
}

#[test]
fn a_narrowed_pipeline_reasons_its_window_only() {
    let src = braking();
    let second = src.windows()[1].id.clone();
    let one = src.only(Some(&second)).expect("narrowed");
    assert_eq!(one.window_count(), 1);
    let p = one.prepare("Moving(x)").expect("query");
    let answers = one.ask(&p, None, AskOptions::BINDINGS).expect("answers");
    assert_eq!(answers.len(), 1);
    assert_eq!(answers[0].window.id, second);
    assert_eq!(answers[0].result.window, second);
    // Reasoned up front, a pipeline keeps its KBs only.
    let kept = braking().into_reasoned(&|| {}).expect("reasons");
    assert!(kept.windows().is_empty());
    assert!(kept.window_count() > 1);
    assert!(kept.select(None).expect("all").len() > 1);
}

#[cfg(feature = "arrow")]
#[test]
fn answer_tables_go_window_by_window_in_question_order() {
    use crate::arrow::arrow_array::Array;
    use crate::arrow::arrow_array::cast::AsArray;
    use crate::arrow::arrow_array::types::Int64Type;
    let src = braking();
    let texts = ["Moving(x)", "Is a car slowing down?", "Levitates(x)"];
    let batches = crate::arrow::answer_table(&src, &texts, AskOptions::BINDINGS).expect("answers");
    assert_eq!(batches.len(), 1);
    let b = &batches[0];
    assert_eq!(b.num_rows(), texts.len() * src.windows().len());
    let window = b.column(1).as_string::<i32>();
    let question = b.column(4).as_string::<i32>();
    let index = b.column(6).as_primitive::<Int64Type>();
    for (row, (w, i)) in src
        .windows()
        .iter()
        .flat_map(|w| (0..texts.len()).map(move |i| (w, i)))
        .enumerate()
    {
        assert_eq!(window.value(row), w.id);
        assert_eq!(index.value(row), i64::try_from(i).expect("small"));
        assert_eq!(question.is_valid(row), i == 1);
    }
    assert!(b.column(12).is_null(0), "no proofs asked for");
    let err = crate::arrow::answer_table(
        &src,
        &["Moving(x)", "Is the zorblax here?"],
        AskOptions::BINDINGS,
    )
    .expect_err("untranslatable");
    assert!(
        matches!(&err, crate::arrow::TableError::Session(e) if matches!(**e, SessionError::Prepare(_))),
        "{err}"
    );
    let facts = crate::arrow::facts_table(&src, None).expect("facts");
    let total: usize = src.windows().iter().map(|w| w.facts.len()).sum();
    assert_eq!(facts.iter().map(|b| b.num_rows()).sum::<usize>(), total);
}

/// Issue 33: one run policy. Running out of a limit is the answer's
/// `stopped`, with what was found before it — never `invalid` — and a
/// run that found nothing before it is `unknown`, never `no`.
#[test]
fn a_run_that_stops_at_a_limit_keeps_what_it_found_and_says_which() {
    let src = braking();
    let first = src.windows()[0].id.clone();
    let ask = |q: &str, limits: logicpad::Limits| {
        let p = src.prepare(q).expect("prepares");
        let opts = AskOptions {
            limits,
            ..AskOptions::default()
        };
        src.ask(&p, Some(&first), opts)
            .expect("asks")
            .remove(0)
            .result
    };
    let all = ask("Vehicles(x) ^ Vehicles(y)", logicpad::Limits::default());
    assert_eq!((all.answer, all.stopped), (Outcome::Yes, None));
    let few = logicpad::Limits {
        answers: 2,
        ..logicpad::Limits::default()
    };
    let r = ask("Vehicles(x) ^ Vehicles(y)", few);
    assert_eq!(r.answer, Outcome::Yes);
    assert_eq!(r.stopped, Some(logicpad::Stopped::Answers));
    assert_eq!((r.bindings.len(), r.proofs.len()), (2, 2));
    assert!(all.bindings.len() > 2);
    // A count past the limit is a lower bound: it decides "at least 1"
    // and "at most 0", never "at least 5". (`y` is existential, so the
    // distinct `x` are kept and counted against the answer limit.)
    let one = logicpad::Limits {
        answers: 1,
        ..logicpad::Limits::default()
    };
    let vehicles = "Vehicles(x) ^ Vehicles(y)";
    let r = ask(&format!("#{{x: {vehicles}}} >= 1"), one);
    assert_eq!(
        (r.answer, r.stopped),
        (Outcome::Yes, Some(logicpad::Stopped::Answers)),
        "{r:?}"
    );
    let r = ask(&format!("#{{x: {vehicles}}} <= 0"), one);
    assert_eq!(
        (r.answer, r.stopped),
        (Outcome::No, Some(logicpad::Stopped::Answers)),
        "{r:?}"
    );
    let r = ask(&format!("#{{x: {vehicles}}} >= 5"), one);
    assert_eq!(r.answer, Outcome::Unknown, "{r:?}");
    assert!(
        r.reasons.iter().any(|s| s.contains("the answer limit (1)")),
        "{:?}",
        r.reasons
    );
    // Out of steps before anything is found: unknown, saying why (the
    // same query within its limits is a "no").
    let r = ask(
        "Vehicles(x) ^ Moving(x) ^ SpeedUp(x)",
        logicpad::Limits::default(),
    );
    assert_eq!(r.answer, Outcome::No);
    let none = logicpad::Limits {
        steps: Some(1),
        ..logicpad::Limits::default()
    };
    let r = ask("Vehicles(x) ^ Moving(x) ^ SpeedUp(x)", none);
    assert_eq!(r.answer, Outcome::Unknown, "{r:?}");
    assert_eq!(r.stopped, Some(logicpad::Stopped::Steps));
    assert!(r.reasons[0].contains("the step limit"), "{:?}", r.reasons);
}

/// The answers table says when an answer's run stopped at a limit (its
/// bindings are then those found first, its count a lower bound).
#[cfg(feature = "arrow")]
#[test]
fn the_answers_table_says_which_answers_stopped() {
    use crate::arrow::arrow_array::{Array, StringArray};
    let src = braking();
    let few = AskOptions {
        limits: logicpad::Limits {
            answers: 1,
            ..logicpad::Limits::default()
        },
        ..AskOptions::BINDINGS
    };
    let batches =
        crate::arrow::answer_table(&src, &["Vehicles(x) ^ Vehicles(y)", "Levitates(x)"], few)
            .expect("answers");
    let b = &batches[0];
    let stopped = b
        .column_by_name("stopped")
        .and_then(|c| c.as_any().downcast_ref::<StringArray>())
        .expect("a stopped column");
    assert_eq!(stopped.value(0), "answers");
    assert!(stopped.is_null(1), "an invalid query did not stop");
}
