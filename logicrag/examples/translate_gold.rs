//! Translates the `Question` column of the gold file and judges the result.
//!
//! Usage: `cargo run --release -p logicrag --example translate_gold [GOLD_CSV [OUT_CSV]]`
//! Defaults: `../shared/data/logicrag-reference/kitti_translations_gold.csv`
//! (relative to the workspace root) and `translate_gold_out.csv` in the
//! system temp directory. Writes `Question,Query,Error`, prints each
//! translation, the time per translation, and, when `python3` and
//! `../shared/tools/query_equiv.py` are present, the judge's verdict.

use std::path::PathBuf;
use std::process::Command;
use std::time::Instant;

use logicrag::translate::{Translator, csv};

fn main() -> anyhow::Result<()> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let shared = root.join("../shared");
    let mut args = std::env::args().skip(1);
    let gold = args
        .next()
        .map(PathBuf::from)
        .unwrap_or_else(|| shared.join("data/logicrag-reference/kitti_translations_gold.csv"));
    let out = args
        .next()
        .map(PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("translate_gold_out.csv"));
    let text =
        std::fs::read_to_string(&gold).map_err(|e| anyhow::anyhow!("{}: {e}", gold.display()))?;
    let questions =
        csv::column(&text, "Question").map_err(|e| anyhow::anyhow!("{}: {e}", gold.display()))?;

    let t0 = Instant::now();
    let translator = Translator::builtin();
    let build = t0.elapsed();
    let csv_out = translator
        .translate_csv(&text)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    std::fs::write(&out, &csv_out)?;

    let mut failed = 0;
    for q in &questions {
        match translator.translate(q) {
            Ok(t) => {
                println!("{q}\n    {}", t.query);
                for n in &t.notes {
                    println!("    note: {n}");
                }
            }
            Err(e) => {
                failed += 1;
                println!("{q}\n    ERROR {e}");
            }
        }
    }
    // Timing: every question many times over.
    let rounds = 200;
    let t1 = Instant::now();
    let mut atoms = 0usize;
    for _ in 0..rounds {
        for q in &questions {
            if let Ok(t) = translator.translate(q) {
                atoms += t.atoms.len();
            }
        }
    }
    let per = t1.elapsed().as_secs_f64() * 1e6 / (rounds * questions.len().max(1)) as f64;
    println!(
        "\n{} questions, {} not translated; lexicon built in {:.1} µs; {:.1} µs per translation ({} atoms)",
        questions.len(),
        failed,
        build.as_secs_f64() * 1e6,
        per,
        atoms / rounds
    );
    println!("wrote {}", out.display());

    let judge = shared.join("tools/query_equiv.py");
    if judge.exists() {
        match Command::new("python3")
            .arg(&judge)
            .arg(&gold)
            .arg(&out)
            .output()
        {
            Ok(o) => {
                let s = String::from_utf8_lossy(&o.stdout);
                for line in s
                    .lines()
                    .filter(|l| l.starts_with("MISS") || l.starts_with("agreement"))
                {
                    println!("{line}");
                }
                let lines: Vec<&str> = s.lines().collect();
                for (i, l) in lines.iter().enumerate() {
                    if l.starts_with("MISS") {
                        for extra in lines.iter().skip(i + 1).take(2) {
                            println!("{extra}");
                        }
                    }
                }
            }
            Err(e) => println!("could not run python3: {e}"),
        }
    } else {
        println!(
            "judge {} not found; agreement not measured",
            judge.display()
        );
    }
    Ok(())
}
