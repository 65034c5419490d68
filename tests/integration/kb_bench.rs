//! The shared KB benchmark (KITTI windows, the reference rules as a
//! LogicPad, ~100 queries per window) through the same batch path as
//! `logicrag ask --source facts:DIR --logicpad RULES --queries FILE`:
//! every answer and count must match the fixpoint oracle. Two sequences
//! keep the test fast; the full set is timed by `--release` runs (README).
use logicpad::LogicPad;
use logicrag::ask::{AskOptions, Outcome};
use logicrag::batch::{parse_queries, run_batch};
use std::process::Command;

#[test]
fn kitti_kb_bench_answers_match_the_oracle() {
    let Some(shared) = integration_tests::shared_dir() else {
        integration_tests::missing_input("../shared is not present");
        return;
    };
    let out = std::env::temp_dir().join(format!("logicrag-kb-bench-{}", std::process::id()));
    let status = Command::new("python3")
        .arg(shared.join("bench/gen_kb_bench.py"))
        .args(["--datasets", "kitti", "--videos", "0,13", "--out"])
        .arg(&out)
        .output();
    let Ok(status) = status else {
        integration_tests::missing_input("python3 is not available");
        return;
    };
    assert!(
        status.status.success(),
        "generator failed: {}",
        String::from_utf8_lossy(&status.stderr)
    );
    let d = out.join("kitti");
    let pad = LogicPad::load(d.join("rules.yaml")).unwrap();
    assert!(!pad.has_errors(), "{:?}", pad.diagnostics());
    let text = std::fs::read_to_string(d.join("queries.tsv")).unwrap();
    let queries = parse_queries(&text, "queries.tsv").unwrap();
    let options = logicrag::pipeline::OpenOptions {
        logicpad: logicrag::pipeline::PadChoice::Loaded(pad),
        ..Default::default()
    };
    let pipeline = logicrag::pipeline::Pipeline::open(
        format!("facts:{}", d.join("facts").display())
            .parse()
            .unwrap(),
        &options,
        &mut |_| {},
    )
    .unwrap();
    let results = run_batch(pipeline, &queries, "queries.tsv", AskOptions::COUNT).unwrap();
    let expected = std::fs::read_to_string(d.join("expected.tsv")).unwrap();
    let mut want = std::collections::HashMap::new();
    for line in expected.lines() {
        let f: Vec<&str> = line.split('\t').collect();
        want.insert(
            (f[0].to_string(), f[1].parse::<usize>().unwrap()),
            (f[2] == "yes", f[3].parse::<usize>().unwrap()),
        );
    }
    assert_eq!(want.len(), queries.len());
    for (q, r) in queries.iter().zip(&results) {
        let (yes, count) = want[&(q.window.clone(), q.index)];
        assert_eq!(
            (r.answer == Outcome::Yes, r.count),
            (yes, count),
            "{} #{}: {}",
            q.window,
            q.index,
            q.query
        );
        assert!(matches!(r.answer, Outcome::Yes | Outcome::No));
    }
    let _ = std::fs::remove_dir_all(&out);
}
