//! Every built-in scenario, oracle perception from the simulator, its
//! built-in question set (generated from ground truth): translator +
//! reasoning must answer every question right, in every category.
use logicrag::eval::evaluate;
use logicrag::questions::generate;
use logicrag::source::{LoadOptions, load};

/// The pipeline of a source, opened with the default options.
fn open(source: &str) -> logicrag::pipeline::Pipeline {
    let options = logicrag::pipeline::OpenOptions::default();
    logicrag::pipeline::Pipeline::open(source.parse().expect("a source"), &options, &mut |_| {})
        .expect("opens")
}

#[test]
fn oracle_accuracy_is_one_in_every_category_of_every_scenario() {
    let opts = LoadOptions::default();
    let mut categories = std::collections::BTreeSet::new();
    for name in perception::sim::BUILTIN_NAMES {
        let loaded = load(&format!("sim:{name}").parse().unwrap(), &opts, &mut |_| {}).unwrap();
        let run = loaded.sim.as_ref().unwrap();
        let windows = perception::window_facts(&run.sequence, opts.windows, &opts.config).unwrap();
        let questions = generate(run, &windows, &opts.config);
        assert!(
            questions.len() >= 10,
            "{name}: only {} questions",
            questions.len()
        );
        let yes = questions.iter().filter(|q| q.answer).count();
        assert!(
            yes > 0 && yes < questions.len(),
            "{name}: unbalanced question set"
        );
        let pipeline = open(&format!("sim:{name}"));
        let report = evaluate(pipeline, &questions, name).unwrap();
        for r in &report.records {
            assert!(
                r.correct,
                "{name}: [{}] {} → {:?} said {:?}, expected {}",
                r.window, r.question, r.query, r.said, r.expected
            );
            categories.insert(r.category.clone());
        }
    }
    for c in ["U1", "U2", "U3", "U4", "B1", "B2"] {
        assert!(categories.contains(c), "no {c} question in any scenario");
    }
}

#[test]
fn evaluation_reports_progress_window_by_window() {
    use std::sync::Mutex;
    let opts = LoadOptions::default();
    let loaded = load(&"sim:intersection".parse().unwrap(), &opts, &mut |_| {}).unwrap();
    let run = loaded.sim.as_ref().unwrap();
    let windows = perception::window_facts(&run.sequence, opts.windows, &opts.config).unwrap();
    let questions = generate(run, &windows, &opts.config);
    let asked: std::collections::BTreeSet<&str> =
        questions.iter().map(|q| q.window.as_str()).collect();
    assert!(
        asked.len() > 1,
        "the scenario's questions should span several windows"
    );
    let calls = Mutex::new(Vec::new());
    let pipeline = open("sim:intersection");
    let report =
        logicrag::eval::evaluate_with_progress(pipeline, &questions, "intersection", &|n| {
            calls.lock().unwrap().push(n)
        })
        .unwrap();
    let calls = calls.into_inner().unwrap();
    assert_eq!(
        calls.len(),
        asked.len(),
        "one progress call per window with questions"
    );
    assert_eq!(calls.iter().sum::<usize>(), questions.len());
    assert_eq!(report.records.len(), questions.len());
}
