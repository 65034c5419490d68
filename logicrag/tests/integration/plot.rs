//! `logicrag plot bev`, `plot eval` and `eval --plot` as a user runs them:
//! the file is written, a PNG has the size asked for and is not blank, an
//! SVG names what it shows. With `LOGICRAG_UPDATE_DOCS=1` the pictures
//! replace `docs/plot-bev.png` and `docs/plot-eval.png` (shown in the README).

use serde_json::{Value, json};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn logicrag(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_logicrag"))
        .args(args)
        .output()
        .expect("the logicrag binary runs")
}

fn ok(args: &[&str]) {
    let out = logicrag(args);
    assert!(
        out.status.success(),
        "logicrag {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A scratch directory under the target directory, emptied first.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("plot-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// Checks a PNG's size and that it shows something: many colours (lines,
/// antialiased text) and a fair share of non-white pixels.
fn assert_picture(path: &Path, size: (u32, u32)) {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8();
    assert_eq!((img.width(), img.height()), size, "{}", path.display());
    let colours: HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    assert!(
        colours.len() > 40,
        "{}: only {} colours",
        path.display(),
        colours.len()
    );
    let inked = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
    let share = inked as f64 / f64::from(size.0 * size.1);
    assert!(
        share > 0.03,
        "{}: {share:.3} of the pixels are not white",
        path.display()
    );
}

fn text(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn to_docs(from: &Path, name: &str) {
    if std::env::var_os("LOGICRAG_UPDATE_DOCS").is_some() {
        let docs = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../docs")
            .join(name);
        std::fs::copy(from, docs).expect("docs picture");
    }
}

#[test]
fn a_bird_s_eye_view_is_drawn_as_png_and_svg() {
    let dir = scratch("bev");
    let png = dir.join("bev.png");
    let svg = dir.join("bev.svg");
    let window = [
        "--source",
        "sim:intersection",
        "--window-id",
        "intersection_000010",
    ];
    ok(&[
        &["plot", "bev"][..],
        &window[..],
        &[
            "--out",
            png.to_str().expect("path"),
            "--width",
            "1000",
            "--height",
            "800",
        ],
    ]
    .concat());
    assert_picture(&png, (1000, 800));
    ok(&[
        &["plot", "bev"][..],
        &window[..],
        &["--out", svg.to_str().expect("path")],
    ]
    .concat());
    let s = text(&svg);
    assert!(s.starts_with("<svg") && s.contains("width=\"1000\"") && s.contains("height=\"800\""));
    for label in [
        "intersection_000010: frames 10–19",
        "pedestrian_3 (#3)",
        "pedestrian_4 (#4)",
        "car_1 (#1)",
        "ego (camera) path",
        "metres ahead",
    ] {
        assert!(s.contains(label), "the SVG should name `{label}`");
    }
    to_docs(&png, "plot-bev.png");
    // The first window when none is named.
    let first = dir.join("first.svg");
    ok(&[
        "plot",
        "bev",
        "--source",
        "sim:urban_crossing",
        "--out",
        first.to_str().expect("path"),
    ]);
    assert!(text(&first).contains("urban_crossing_000000: frames 0–9"));
}

#[test]
fn an_evaluation_is_drawn_per_category_for_each_column() {
    let dir = scratch("eval");
    let report = dir.join("report.json");
    let png = dir.join("eval.png");
    let svg = dir.join("eval.svg");
    // `eval --plot` and the report that `plot eval` reads back.
    ok(&[
        "eval",
        "--all-scenarios",
        "--report",
        report.to_str().expect("path"),
        "--plot",
        png.to_str().expect("path"),
    ]);
    assert_picture(&png, (1100, 760));
    let r: Value = serde_json::from_str(&text(&report)).expect("the report is JSON");
    let columns = r["columns"].as_array().expect("columns");
    assert_eq!(columns.len(), 1);
    assert_eq!(columns[0]["name"], json!("LR"));
    assert_eq!(columns[0]["overall"], r["overall"]);
    ok(&[
        "plot",
        "eval",
        "--report",
        report.to_str().expect("path"),
        "--out",
        svg.to_str().expect("path"),
    ]);
    let s = text(&svg);
    for label in ["accuracy", "F1", "LR", "U1 (n=", "B2 (n=", "all (n="] {
        assert!(s.contains(label), "the SVG should name `{label}`");
    }
    to_docs(&png, "plot-eval.png");

    // A report with the model's conditions gets a bar per condition.
    let scores = |acc: f64, f1: f64| {
        json!({
            "n": 10, "accuracy": acc, "balanced_accuracy": acc, "precision": acc, "recall": acc, "f1": f1,
            "always_yes_accuracy": 0.5, "always_no_accuracy": 0.5, "always_yes_f1": 0.67
        })
    };
    let mut cols = Vec::new();
    for (name, acc) in [("LR", 1.0), ("C1", 0.55), ("C2", 0.9), ("C3", 0.7)] {
        cols.push(json!({"name": name, "overall": scores(acc, acc), "by_category": {"U1": scores(acc, acc - 0.05), "B1": scores(acc - 0.1, acc)}}));
    }
    let lmm_report = dir.join("lmm-report.json");
    std::fs::write(&lmm_report, json!({"columns": cols}).to_string()).expect("write");
    let lmm_png = dir.join("lmm.png");
    ok(&[
        "plot",
        "eval",
        "--report",
        lmm_report.to_str().expect("path"),
        "--out",
        lmm_png.to_str().expect("path"),
        "--width",
        "900",
        "--height",
        "600",
    ]);
    assert_picture(&lmm_png, (900, 600));
    let lmm_svg = dir.join("lmm.svg");
    ok(&[
        "plot",
        "eval",
        "--report",
        lmm_report.to_str().expect("path"),
        "--out",
        lmm_svg.to_str().expect("path"),
    ]);
    let s = text(&lmm_svg);
    for label in [
        "LR",
        "C1",
        "C2",
        "C3",
        "0.55",
        "0.90",
        "U1 (n=10)",
        "B1 (n=10)",
    ] {
        assert!(s.contains(label), "the SVG should name `{label}`");
    }
}

/// Issue 36 item 3: `plot reliability` draws the reliability diagram of
/// an `eval` report, one curve per noise level.
#[test]
fn a_reliability_diagram_is_drawn_from_an_eval_report() {
    let dir = scratch("reliability");
    let report = dir.join("report.json");
    ok(&[
        "eval",
        "--source",
        "sim:braking",
        "--noise",
        "high,high*2",
        "--seeds",
        "1",
        "--report",
        report.to_str().expect("path"),
    ]);
    let png = dir.join("reliability.png");
    ok(&[
        "plot",
        "reliability",
        "--report",
        report.to_str().expect("path"),
        "--out",
        png.to_str().expect("path"),
    ]);
    assert_picture(&png, (900, 900));
    let svg = dir.join("reliability.svg");
    ok(&[
        "plot",
        "reliability",
        "--all-questions",
        "--report",
        report.to_str().expect("path"),
        "--out",
        svg.to_str().expect("path"),
        "--width",
        "700",
        "--height",
        "600",
    ]);
    let s = text(&svg);
    for label in [
        "noise high",
        "noise high*2",
        "perfectly calibrated",
        "all questions",
    ] {
        assert!(s.contains(label), "the SVG should name `{label}`");
    }
    // A report without forecasts says what is missing.
    let bare = dir.join("bare.json");
    std::fs::write(&bare, "{}").expect("write");
    let out = logicrag(&[
        "plot",
        "reliability",
        "--report",
        bare.to_str().expect("path"),
        "--out",
        png.to_str().expect("path"),
    ]);
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("has no `skill`"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn bad_plot_requests_are_refused_with_a_message() {
    let dir = scratch("bad");
    for (args, says) in [
        (
            vec!["plot", "bev", "--out", "x.jpg"],
            "must end in .png or .svg",
        ),
        (
            vec!["plot", "eval", "--out", "x"],
            "must end in .png or .svg",
        ),
        (
            vec!["plot", "bev", "--out", "x.png", "--width", "10"],
            "each side must be 200 to 8000",
        ),
        (
            vec!["plot", "bev", "--window-id", "nope", "--out", "x.png"],
            "has no window `nope`",
        ),
        (vec!["eval", "--plot", "x.gif"], "must end in .png or .svg"),
    ] {
        let out = logicrag(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{args:?}: {err}");
    }
    let not_report = dir.join("r.json");
    std::fs::write(&not_report, "{\"overall\": {}}").expect("write");
    let out = logicrag(&[
        "plot",
        "eval",
        "--report",
        not_report.to_str().expect("path"),
        "--out",
        "x.png",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("has no `columns`"));
    let facts = dir.join("w.facts");
    std::fs::write(&facts, "Vehicles(car_1)\n").expect("write");
    let out = logicrag(&[
        "plot",
        "bev",
        "--source",
        &format!("facts:{}", facts.display()),
        "--out",
        "x.png",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("has no tracks to draw"));
}
