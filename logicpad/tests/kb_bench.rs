//! The shared KB benchmark's `rules.yaml` loads and evaluates correctly:
//! generates the KITTI dataset for two sequences with
//! `../shared/bench/gen_kb_bench.py` and checks every query's answer count
//! against its `expected.tsv`. Skipped (with a notice) only when `../shared`
//! is absent. The timed run over all 796 windows is the `kb_bench` example.

use logicpad::{DiagKind, FactBase, LogicPad, RunConfig, parse_query};
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

#[test]
fn kb_bench_windows_match_expected_answers() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let bench = root.join("shared/bench/gen_kb_bench.py");
    if !bench.exists() {
        println!(
            "NOTICE: {} is absent (no ../shared); KB benchmark check skipped",
            bench.display()
        );
        return;
    }
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("kb-bench-test");
    let status = Command::new("python3")
        .arg(&bench)
        .args(["--datasets", "kitti", "--videos", "0,5", "--out"])
        .arg(&out)
        .status()
        .expect("python3 runs the benchmark generator");
    assert!(status.success(), "gen_kb_bench.py failed");
    let dir = out.join("kitti");
    let pad = LogicPad::load(dir.join("rules.yaml")).expect("rules.yaml loads");
    // The benchmark's rules are plain positive Datalog: no errors. The only
    // findings are the `Not*` base predicates (negation encoded as facts).
    for d in pad.diagnostics() {
        assert_eq!(d.kind, DiagKind::NegationAsPredicate, "{}", d.summary());
    }
    assert_eq!(pad.program().rules().len(), 64);
    let read = |p: &str| std::fs::read_to_string(dir.join(p)).expect("dataset file");
    let mut queries: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for line in read("queries.tsv").lines() {
        let (w, q) = line.split_once('\t').expect("tab");
        queries
            .entry(w.to_string())
            .or_default()
            .push(q.to_string());
    }
    let mut checked = 0;
    let mut yes = 0;
    let expected: BTreeMap<(String, usize), usize> = read("expected.tsv")
        .lines()
        .map(|l| {
            let f: Vec<&str> = l.split('\t').collect();
            (
                (f[0].to_string(), f[1].parse().expect("index")),
                f[3].parse().expect("count"),
            )
        })
        .collect();
    for (w, qs) in &queries {
        let fb = FactBase::from_text(&read(&format!("facts/{w}.facts")), w).expect("facts parse");
        let model = pad.program().evaluate(fb).expect("evaluates");
        for (i, q) in qs.iter().enumerate() {
            let ast = parse_query(q).expect("query parses");
            let answers = model.ask(&ast, RunConfig::default()).expect("answers");
            let want = expected
                .get(&(w.clone(), i))
                .copied()
                .expect("expected entry");
            assert_eq!(answers.len(), want, "window {w} query #{i} {q}");
            checked += 1;
            yes += usize::from(want > 0);
        }
    }
    assert!(
        checked >= 1000 && yes > 100,
        "checked {checked} queries, {yes} with answers"
    );
}
