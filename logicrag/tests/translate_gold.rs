//! The translator against the reviewed gold queries of the paper's KITTI
//! questions, judged by `../shared/tools/query_equiv.py`.
//!
//! Needs `../shared` (the project's read-only data) and `python3`; without
//! them the test prints why it did not run and passes.

use std::path::PathBuf;
use std::process::Command;

use logicrag::translate::Translator;

#[test]
fn gold_questions_all_agree() {
    let shared = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared");
    let gold = shared.join("data/logicrag-reference/kitti_translations_gold.csv");
    let judge = shared.join("tools/query_equiv.py");
    if !gold.exists() || !judge.exists() {
        println!(
            "SKIPPED: {} or {} not found (../shared is absent)",
            gold.display(),
            judge.display()
        );
        return;
    }
    if Command::new("python3").arg("--version").output().is_err() {
        println!(
            "SKIPPED: python3 is not available to run {}",
            judge.display()
        );
        return;
    }
    let text = std::fs::read_to_string(&gold).expect("gold file readable");
    let out_csv = Translator::builtin()
        .translate_csv(&text)
        .expect("gold file is CSV with a Question column");
    let out = std::env::temp_dir().join(format!(
        "logicrag_translate_gold_{}.csv",
        std::process::id()
    ));
    std::fs::write(&out, &out_csv).expect("temp file writable");
    let run = Command::new("python3")
        .arg(&judge)
        .arg(&gold)
        .arg(&out)
        .output()
        .expect("python3 runs");
    let _ = std::fs::remove_file(&out);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "judge failed: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    let line = stdout
        .lines()
        .find(|l| l.starts_with("agreement:"))
        .expect("judge prints an agreement line");
    println!("{line}");
    // "agreement: K/N = R"
    let frac = line
        .trim_start_matches("agreement:")
        .split('=')
        .next()
        .unwrap_or("")
        .trim();
    let (k, n) = frac.split_once('/').expect("K/N");
    let (k, n): (usize, usize) = (k.trim().parse().expect("K"), n.trim().parse().expect("N"));
    assert_eq!(n, 57, "the gold file holds 57 questions");
    let misses: Vec<&str> = stdout.lines().filter(|l| l.starts_with("MISS")).collect();
    assert_eq!(
        k,
        n,
        "translations that differ from gold:\n{}\n{stdout}",
        misses.join("\n")
    );
}
