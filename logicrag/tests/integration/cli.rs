//! The `logicrag` binary as a user runs it: exit codes, what reaches stdout
//! and stderr, and the wording of the messages a person reads.
use std::io::Write;
use std::process::{Command, Output, Stdio};

fn logicrag(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_logicrag"))
        .args(args)
        .output()
        .expect("the logicrag binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A scratch directory, removed when dropped.
struct TempDir(std::path::PathBuf);

impl TempDir {
    fn new(test: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("logicrag-cli-{}-{test}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        TempDir(dir)
    }

    fn file(&self, name: &str, contents: &str) -> std::path::PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, contents).expect("temp file");
        path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

const BROKEN_PAD: &str = "atomic_predicates:\n  tracker:\n    - Vehicles(x)\nderived_predicates:\n  - name: Fast\n    logic: \"∀x : Vehicles(x) ∧ ¬Slow(x) ==> Fast(x)\"\n";

#[test]
fn how_many_questions_print_the_count() {
    let out = logicrag(&[
        "ask",
        "--window-id",
        "urban_crossing_000000",
        "How many pedestrians are there?",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains("Pedestrian(x) → YES (1 answer)"),
        "{stdout}"
    );
}

#[test]
fn a_missing_file_is_reported_once_with_exit_code_2() {
    // Regression: the cause was printed twice ("No such file … : No such file …").
    let out = logicrag(&[
        "ask",
        "--source",
        "json:/nonexistent/t.json",
        "Pedestrian(x)",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = text(&out.stderr);
    assert!(
        stderr.starts_with("error: /nonexistent/t.json: "),
        "{stderr}"
    );
    assert_eq!(stderr.matches("No such file").count(), 1, "{stderr}");
}

#[test]
fn lint_exit_codes_follow_the_worst_diagnostic() {
    let tmp = TempDir::new("lint");
    let clean = tmp.file("clean.yaml", logicpad::BUILTIN_SOURCE);
    let out = logicrag(&["lint", clean.to_str().expect("utf-8 path")]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stdout));
    let warned = tmp.file(
        "warned.yaml",
        &format!("{}\nextras:\n  - x\n", logicpad::BUILTIN_SOURCE.trim_end()),
    );
    let out = logicrag(&["lint", warned.to_str().expect("utf-8 path")]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stdout));
    let all = text(&out.stdout) + &text(&out.stderr);
    assert!(all.contains("unknown top-level key `extras`"), "{all}");
    let broken = tmp.file("broken.yaml", BROKEN_PAD);
    let out = logicrag(&["lint", broken.to_str().expect("utf-8 path")]);
    assert_eq!(out.status.code(), Some(2));
    let all = text(&out.stdout) + &text(&out.stderr);
    assert!(all.contains("unknown predicate `Slow`"), "{all}");
    assert!(all.contains("broken.yaml:6:"), "{all}");
}

#[test]
fn a_predicate_whose_rules_failed_to_load_is_unknown_and_says_why() {
    // Regression: "this source cannot observe `Fast`" blamed the source for
    // a LogicPad error.
    let tmp = TempDir::new("fast");
    let broken = tmp.file("fast.yaml", BROKEN_PAD);
    let out = logicrag(&[
        "ask",
        "--logicpad",
        broken.to_str().expect("utf-8 path"),
        "--window-id",
        "urban_crossing_000000",
        "Fast(x)",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(stdout.contains("→ UNKNOWN"), "{stdout}");
    assert!(
        stdout.contains("`Fast` is derived but none of its rules loaded"),
        "{stdout}"
    );
    assert!(text(&out.stderr).contains("has 1 error(s)"));
}

#[test]
fn the_repl_reads_piped_stdin() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_logicrag"))
        .arg("repl")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the repl starts");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(b"help\nIs there a pedestrian?\n:quit\n")
        .expect("write stdin");
    let out = child.wait_with_output().expect("the repl ends");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    // `help` without its colon is the command (it printed only a hint before).
    assert!(stdout.contains(":windows"), "{stdout}");
    assert!(
        stdout.contains("YES (1 answer) (window urban_crossing_000000)"),
        "{stdout}"
    );
}

#[test]
fn translate_prints_the_query() {
    let out = logicrag(&[
        "translate",
        "Is there a white car moving at constant speed?",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(
        text(&out.stdout).trim(),
        "TypeOf(x, Car)^ColorOf(x, White)^Move(x)^ConstantSpeed(x)"
    );
}

#[test]
fn perceive_uses_the_camera_calibration_and_frame_rate() {
    let tmp = TempDir::new("frames");
    let dir = &tmp.0;
    for i in 0..3 {
        image::RgbImage::from_pixel(32, 32, image::Rgb([250, 250, 250]))
            .save(dir.join(format!("{i:06}.png")))
            .expect("frame");
    }
    let models = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../perception/models/test/tiny_gfl.yaml"
    );
    let camera = tmp.file(
        "cam.yaml",
        "fx: 40\nfy: 41\ncx: 15.5\ncy: 14\nheight_m: 1.2\n",
    );
    let out_file = dir.join("tracks.json");
    let source = format!("frames:{}", dir.display());
    let out = logicrag(&[
        "perceive",
        "--source",
        &source,
        "--models",
        models,
        "--camera",
        camera.to_str().expect("utf-8 path"),
        "--fps",
        "25",
        "--out",
        out_file.to_str().expect("utf-8 path"),
    ]);
    let stderr = text(&out.stderr);
    if stderr.contains("ONNX Runtime library not found") {
        eprintln!("skipped: no ONNX Runtime ({stderr})");
        return;
    }
    assert!(out.status.success(), "{stderr}");
    let tracks: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out_file).expect("tracks written"))
            .expect("tracks are JSON");
    assert_eq!(tracks["fps"], 25.0);
    assert_eq!(tracks["camera"]["intrinsics"]["fy"], 41.0);
    assert_eq!(tracks["camera"]["height_m"], 1.2);
    assert!(!stderr.contains("no --camera"), "{stderr}");
    // Without a calibration the assumption is said aloud.
    let out = logicrag(&["perceive", "--source", &source, "--models", models]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("note: no --camera calibration"));
}

#[test]
fn frames_only_flags_are_checked_everywhere() {
    // Flags the chosen source would ignore are an error, not silence, in
    // every command that loads a source (`eval` ignored them).
    for (args, message) in [
        (
            &["ask", "--camera", "x.yaml", "Pedestrian(x)"][..],
            "--camera applies to frames:DIR sources only",
        ),
        (
            &["facts", "--models", "m.yaml"][..],
            "--models applies to frames:DIR sources only",
        ),
        (
            &["eval", "--fps", "5"][..],
            "--fps applies to frames:DIR sources only",
        ),
        (
            &["eval", "--all-scenarios", "--camera", "c.yaml"][..],
            "--camera applies",
        ),
    ] {
        let out = logicrag(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let stderr = text(&out.stderr);
        assert!(stderr.contains(message), "{args:?}: {stderr}");
    }
    // A frames directory is one sequence, numbered by file order: a
    // sequence name or a range past its end is refused before any model runs.
    let tmp = TempDir::new("flags");
    for i in [10, 15, 20] {
        tmp.file(&format!("{i:06}.png"), "not decoded before the checks");
    }
    let source = format!("frames:{}", tmp.0.display());
    for (flag, value, message) in [
        (
            "--sequence",
            "0001",
            "--sequence does not apply to frames:DIR",
        ),
        (
            "--frames",
            "10-20",
            "has 3 frames, numbered 0–2 by their order",
        ),
    ] {
        let out = logicrag(&[
            "facts", "--source", &source, "--models", "m.yaml", flag, value,
        ]);
        assert_eq!(out.status.code(), Some(2), "{flag}");
        let stderr = text(&out.stderr);
        assert!(stderr.contains(message), "{flag}: {stderr}");
    }
    // A frame rate must be a positive number (checked before any model runs).
    for fps in ["0", "-5", "NaN", "inf"] {
        let out = logicrag(&[
            "facts",
            "--source",
            "frames:/nonexistent",
            "--models",
            "m.yaml",
            &format!("--fps={fps}"),
        ]);
        assert_eq!(out.status.code(), Some(2), "{fps}");
        assert!(
            text(&out.stderr).contains("--fps must be a positive number"),
            "{fps}: {}",
            text(&out.stderr)
        );
    }
}

/// The examples of issue "answers you can trust", as a user runs them.
#[test]
fn constants_stay_constants_and_nothing_is_weakened() {
    // `car_3` is not in frames 20-29: it was made a variable and bound to sedan_6.
    let out = logicrag(&["ask", "--frames", "20-29", "TypeOf(car_3, Sedan)"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(stdout.contains("TypeOf(car_3, Sedan) → NO"), "{stdout}");
    assert!(
        stdout.contains("car_3 is not seen in frames 20–29"),
        "{stdout}"
    );
    let out = logicrag(&["ask", "--frames", "20-29", "Moving(foo)"]);
    assert!(
        text(&out.stdout).contains("Moving(foo) → NO"),
        "{}",
        text(&out.stdout)
    );
    let out = logicrag(&["ask", "--frames", "20-29", "Moving(x) ^ x != car_1"]);
    assert!(text(&out.stdout).contains("→ YES"), "{}", text(&out.stdout));
    // The quantifier was silently dropped: YES (2 answers).
    let out = logicrag(&["ask", "--frames", "20-29", "forall x: Moving(x)"]);
    let stdout = text(&out.stdout);
    assert!(stdout.contains("→ INVALID"), "{stdout}");
    assert!(stdout.contains("ranges over everything"), "{stdout}");
    let out = logicrag(&[
        "ask",
        "--frames",
        "20-29",
        "forall x: Vehicles(x) -> Moving(x)",
    ]);
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains("→ NO") || stdout.contains("→ YES"),
        "{stdout}"
    );
}

#[test]
fn everyday_people_words_and_relations_between_objects() {
    for (q, want, not) in [
        ("Is the person walking?", "Walk(x)", ""),
        ("Are any people walking?", "Walk(x)", ""),
        ("Is there a person?", "IsPerson(x)", "Person(x)^"),
        (
            "Which vehicles are to the right of the pedestrian?",
            "RightOf(x, y)",
            "InitialLocation",
        ),
    ] {
        let out = logicrag(&["translate", q]);
        assert!(out.status.success(), "{q}: {}", text(&out.stderr));
        let stdout = text(&out.stdout);
        let query = stdout.lines().next().unwrap_or_default();
        assert!(query.contains(want), "{q} → {query}");
        assert!(not.is_empty() || !query.starts_with(not), "{q} → {query}");
    }
}

#[test]
fn answers_across_windows_start_with_one_overall_line() {
    let out = logicrag(&["ask", "Is there a pedestrian?"]);
    let stdout = text(&out.stdout);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("answer:"))
        .unwrap_or_default();
    assert!(
        line.contains("yes — in 8 of 8 windows: frames 0–9, 10–19"),
        "{stdout}"
    );
    let out = logicrag(&["ask", "How many pedestrians are there?"]);
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains("answer:   1 pedestrian — in 8 of 8 windows"),
        "{stdout}"
    );
    // JSON keeps one object per window and ends with the summary.
    let out = logicrag(&["ask", "--json", "Is there a pedestrian?"]);
    let stdout = text(&out.stdout);
    let last: serde_json::Value =
        serde_json::from_str(stdout.lines().last().unwrap_or_default()).expect("summary JSON");
    assert_eq!(last["summary"]["answer"], "yes");
    assert_eq!(stdout.lines().count(), 9);
    // translate's notes go to stdout with the query.
    let out = logicrag(&["translate", "Is there a parked car?"]);
    assert!(
        text(&out.stdout).contains("note: "),
        "{}",
        text(&out.stdout)
    );
}

#[test]
fn simulate_writes_one_camera_frame_per_frame_as_numbered_pngs() {
    let tmp = TempDir::new("frames-out");
    // A directory not there yet is created.
    let dir = tmp.0.join("frames");
    let out = logicrag(&[
        "simulate",
        "urban_crossing",
        "--frames-out",
        &dir.display().to_string(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let scenario = perception::sim::Scenario::builtin("urban_crossing").expect("built in");
    let k = scenario.camera.intrinsics;
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains(&format!(
            "wrote 80 frames ({}×{})",
            k.image_width, k.image_height
        )),
        "{stderr}"
    );
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("frames dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let expected: Vec<String> = (0..80).map(|f| format!("{f:06}.png")).collect();
    assert_eq!(names, expected);
    assert_eq!(scenario.frames, 80);
    // Valid PNGs at the scenario camera's size.
    let img = image::open(dir.join("000040.png"))
        .expect("decodes")
        .to_rgb8();
    assert_eq!(img.dimensions(), (k.image_width, k.image_height));
    // Sky at the top, something else (the road) at the bottom.
    let centre = k.image_width / 2;
    assert_ne!(
        img.get_pixel(centre, 0),
        img.get_pixel(centre, k.image_height - 1)
    );
}

#[test]
fn a_fifo_or_a_huge_window_ends_in_an_error_not_a_hang_or_abort() {
    let tmp = TempDir::new("fifo");
    let fifo = tmp.0.join("in.yaml");
    let made = Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    assert!(made, "mkfifo (coreutils) makes the test's FIFO");
    {
        let f = fifo.to_str().expect("utf-8 path");
        let q = tmp.0.join("q.tsv");
        let made_q = Command::new("mkfifo")
            .arg(&q)
            .status()
            .map(|s| s.success())
            .unwrap_or(false);
        assert!(made_q, "mkfifo makes the queries FIFO");
        let mut cases: Vec<Vec<&str>> = vec![
            vec!["lint", f],
            vec!["ask", "--logicpad", f, "Pedestrian(x)"],
            vec!["ask", "--source", "json:IN", "Pedestrian(x)"],
            vec!["ask", "--config", f, "Pedestrian(x)"],
        ];
        let json_src = format!("json:{f}");
        cases[2][2] = &json_src;
        let qs = q.to_str().expect("utf-8 path").to_string();
        cases.push(vec!["ask", "--queries", &qs]);
        for args in cases {
            let start = std::time::Instant::now();
            let out = logicrag(&args);
            assert_eq!(
                out.status.code(),
                Some(2),
                "{args:?}: {}",
                text(&out.stderr)
            );
            assert!(
                text(&out.stdout).contains("not a regular file")
                    || text(&out.stderr).contains("not a regular file"),
                "{args:?}"
            );
            assert!(start.elapsed() < std::time::Duration::from_secs(20));
        }
    }
    // Regression: a 12-atom cross product took 2.8 GB and aborted.
    let q = (0..12)
        .map(|i| format!("Vehicles(v{i})"))
        .collect::<Vec<_>>()
        .join(" ^ ");
    let out = logicrag(&["ask", "--window-id", "urban_crossing_000000", &q]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("YES (at least 100000 answers)"),
        "{}",
        text(&out.stdout)
    );
}

#[test]
fn simulate_writes_only_inside_its_output_folder() {
    // Regression: a scenario named `../../x` wrote outside --out and said it succeeded.
    let tmp = TempDir::new("escape");
    let scenario = perception::sim::builtin_text("urban_crossing").expect("built-in scenario");
    let hostile = scenario.replacen("name: urban_crossing", "name: ../../escaped", 1);
    assert_ne!(hostile, scenario, "the scenario names itself");
    let file = tmp.file("hostile.yaml", &hostile);
    let out_dir = tmp.0.join("out/inner");
    let out = logicrag(&[
        "simulate",
        file.to_str().expect("utf-8 path"),
        "--out",
        out_dir.to_str().expect("utf-8 path"),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", text_of(&out));
    assert!(
        text(&out.stderr).contains("it names files"),
        "{}",
        text(&out.stderr)
    );
    assert!(
        !tmp.0.join("escaped_000000.facts").exists()
            && !tmp.0.join("out/escaped_000000.facts").exists()
    );
}

fn text_of(out: &Output) -> String {
    text(&out.stdout) + &text(&out.stderr)
}

#[test]
fn a_long_chain_of_disequalities_is_answered() {
    // Regression: `Moving(x) ∧ x != c0 ∧ … ∧ x != c20000` grew memory
    // quadratically (1.9 GB); the constants are constants by their spelling
    // and the query answers.
    let tmp = TempDir::new("neq");
    let chain: Vec<String> = (0..20_000).map(|i| format!("x != c{i}")).collect();
    let q = tmp.file(
        "q.tsv",
        &format!("urban_crossing_000020\tMoving(x) ^ {}\n", chain.join(" ^ ")),
    );
    let out = logicrag(&["ask", "--queries", q.to_str().expect("utf-8 path"), "--tsv"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    // Moving: the sedan, the pedestrian and the ego (braking from 5.4 to
    // 2.9 m/s over frames 20-29).
    assert_eq!(text(&out.stdout).trim(), "urban_crossing_000020\t0\tyes\t3");
}

#[test]
fn batch_json_lines_name_each_key_once() {
    // Regression: a batch line carried `"query"` twice, the query as run
    // and its index in the window; a JSON reader keeps only one of them.
    let tmp = TempDir::new("batch-json");
    let q = tmp.file(
        "q.tsv",
        "urban_crossing_000020\tMoving(x)\nurban_crossing_000020\tMoving(nobody)\n",
    );
    let out = logicrag(&[
        "ask",
        "--queries",
        q.to_str().expect("utf-8 path"),
        "--json",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    for (i, line) in lines.iter().enumerate() {
        let keys = top_level_keys(line);
        let mut unique = keys.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(keys.len(), unique.len(), "duplicate keys in {line}");
        let v: serde_json::Value = serde_json::from_str(line).expect("a JSON line");
        assert_eq!(v["query_index"], i);
        assert_eq!(v["query_text"], v["query"]);
    }
}

/// The keys of a JSON object's top level, in order, duplicates kept
/// (`serde_json::Value` would keep only the last of a repeated key).
fn top_level_keys(line: &str) -> Vec<String> {
    struct Keys(Vec<String>);
    impl<'de> serde::Deserialize<'de> for Keys {
        fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Keys, D::Error> {
            struct V;
            impl<'de> serde::de::Visitor<'de> for V {
                type Value = Keys;
                fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                    f.write_str("a JSON object")
                }
                fn visit_map<A: serde::de::MapAccess<'de>>(
                    self,
                    mut m: A,
                ) -> Result<Keys, A::Error> {
                    let mut keys = Vec::new();
                    while let Some((k, _)) = m.next_entry::<String, serde::de::IgnoredAny>()? {
                        keys.push(k);
                    }
                    Ok(Keys(keys))
                }
            }
            d.deserialize_map(V)
        }
    }
    serde_json::from_str::<Keys>(line).expect("a JSON object").0
}

/// `facts --parquet DIR` and `ask --queries FILE --parquet OUT` write what
/// `--json` prints, in the same order (read back through the library's
/// Parquet reader; the Python tests read the same files with DuckDB).
#[cfg(feature = "arrow")]
#[test]
fn parquet_files_hold_what_json_prints() {
    use logicrag::arrow::arrow_array::cast::AsArray;
    use logicrag::arrow::arrow_array::types::{Float64Type, Int64Type};
    use logicrag::arrow::arrow_array::{Array, RecordBatch};
    use logicrag::arrow::read_parquet;

    /// A small file reads back as one batch.
    fn one(mut batches: Vec<RecordBatch>) -> RecordBatch {
        assert_eq!(batches.len(), 1);
        batches.remove(0)
    }
    let tmp = TempDir::new("parquet");
    let source = ["--source", "sim:braking"];

    // Facts: one file per window, rows in `facts --json` order.
    let dir = tmp.0.join("facts");
    let dir_arg = dir.to_str().expect("utf-8 path");
    let out = logicrag(&[&["facts", "--parquet", dir_arg][..], &source].concat());
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(out.stdout.is_empty());
    let out = logicrag(&[&["facts", "--json"][..], &source].concat());
    assert!(out.status.success(), "{}", text(&out.stderr));
    let windows: Vec<serde_json::Value> = text(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("json"))
        .collect();
    assert!(windows.len() > 1);
    let mut measured = 0;
    for w in &windows {
        let id = w["window"].as_str().expect("id");
        let batch = one(read_parquet(&dir.join(format!("{id}.parquet"))).expect("reads"));
        let facts = w["facts"].as_array().expect("facts");
        assert_eq!(batch.num_rows(), facts.len(), "{id}");
        let window = batch.column(1).as_string::<i32>();
        let index = batch.column(2).as_primitive::<Int64Type>();
        let predicate = batch.column(5).as_string::<i32>();
        let args = batch.column(6).as_list::<i32>();
        let prov = batch.column(7).as_struct();
        let m = prov.column(4).as_primitive::<Float64Type>();
        for (i, f) in facts.iter().enumerate() {
            assert_eq!(window.value(i), id);
            assert_eq!(Some(index.value(i)), w["index"].as_i64());
            assert_eq!(predicate.value(i), f["predicate"].as_str().expect("pred"));
            let a = args.value(i);
            let a: Vec<&str> = a.as_string::<i32>().iter().flatten().collect();
            let expected: Vec<&str> = f["args"]
                .as_array()
                .expect("args")
                .iter()
                .filter_map(|v| v.as_str())
                .collect();
            assert_eq!(a, expected);
            match f["provenance"]["measured"].as_f64() {
                Some(v) => {
                    // serde_json (without `float_roundtrip`) may read the
                    // printed number a bit off; the Python tests, whose
                    // `json` reads exactly, compare bit for bit.
                    assert!((m.value(i) - v).abs() <= v.abs() * 4.0 * f64::EPSILON);
                    measured += 1;
                }
                None => assert!(m.is_null(i)),
            }
        }
    }
    assert!(measured > 0, "some facts are measured");

    // Answers: one file, rows in the order of the queries file.
    let queries: String = windows
        .iter()
        .flat_map(|w| {
            let id = w["window"].as_str().unwrap_or_default().to_string();
            ["Moving(x)", "Levitates(x)", "TypeOf(x, Car) ^ SpeedDown(x)"]
                .map(move |q| format!("{id}\t{q}\n"))
        })
        .collect();
    let qfile = tmp.file("queries.tsv", &queries);
    let qfile = qfile.to_str().expect("utf-8 path");
    let answers = tmp.0.join("answers.parquet");
    let answers_arg = answers.to_str().expect("utf-8 path");
    let out = logicrag(
        &[
            &["ask", "--queries", qfile, "--parquet", answers_arg][..],
            &source,
        ]
        .concat(),
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let out = logicrag(&[&["ask", "--queries", qfile, "--json"][..], &source].concat());
    let lines: Vec<serde_json::Value> = text(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("json"))
        .collect();
    let batch = one(read_parquet(&answers).expect("reads"));
    assert_eq!(batch.num_rows(), lines.len());
    let window = batch.column(1).as_string::<i32>();
    let question = batch.column(4).as_string::<i32>();
    let query = batch.column(5).as_string::<i32>();
    let query_index = batch.column(6).as_primitive::<Int64Type>();
    let answer = batch.column(7).as_string::<i32>();
    let count = batch.column(8).as_primitive::<Int64Type>();
    for (i, l) in lines.iter().enumerate() {
        assert_eq!(Some(window.value(i)), l["window"].as_str());
        assert!(question.is_null(i));
        assert_eq!(Some(query.value(i)), l["query_text"].as_str());
        assert_eq!(Some(query_index.value(i)), l["query_index"].as_i64());
        assert_eq!(Some(answer.value(i)), l["answer"].as_str());
        assert_eq!(Some(count.value(i)), l["count"].as_i64());
        let p = logicrag::arrow::read_proofs(batch.column(12), i).expect("proofs");
        assert_eq!(serde_json::to_value(p).expect("json"), l["proofs"]);
    }
    let said: std::collections::BTreeSet<&str> = answer.iter().flatten().collect();
    assert!(said.contains("yes") && said.contains("invalid"), "{said:?}");

    // --parquet belongs to a batch.
    let out = logicrag(&["ask", "--parquet", answers_arg, "Moving(x)"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn every_front_end_reports_an_unknown_window_with_the_same_message() {
    let want = "sim:urban_crossing has no window `nope` (it has urban_crossing_000000, urban_crossing_000010, urban_crossing_000020, urban_crossing_000030, urban_crossing_000040, …)";
    let stderr = |o: &Output| String::from_utf8_lossy(&o.stderr).to_string();
    let ask = logicrag(&["ask", "--window-id", "nope", "Vehicles(x)"]);
    assert_eq!(ask.status.code(), Some(2));
    assert!(stderr(&ask).contains(want), "ask: {}", stderr(&ask));
    let context = logicrag(&["context", "--window-id", "nope", "Vehicles(x)"]);
    assert!(
        stderr(&context).contains(want),
        "context: {}",
        stderr(&context)
    );
    // The batch says where, then the same sentence.
    let dir = std::env::temp_dir().join(format!("logicrag-nowindow-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let q = dir.join("q.tsv");
    std::fs::write(
        &q,
        "urban_crossing_000000\tVehicles(x)\nnope\tVehicles(x)\n",
    )
    .expect("write");
    let batch = logicrag(&["ask", "--queries", q.to_str().expect("utf-8"), "--tsv"]);
    assert!(
        stderr(&batch).contains(&format!("{}:2: {want}", q.display())),
        "batch: {}",
        stderr(&batch)
    );
    // The REPL, and a megabyte of id is never echoed whole.
    let loaded = logicrag::source::load(
        &"sim:urban_crossing".parse().expect("spec"),
        &logicrag::source::LoadOptions::default(),
        &mut |_| {},
    )
    .expect("loads");
    let engine = logicrag::engine::Engine::new(logicpad::LogicPad::builtin(), loaded.observability)
        .expect("engine");
    let pipeline = logicrag::pipeline::Pipeline::new(loaded.label, engine, loaded.windows);
    let mut s = logicrag::repl::Session::new(pipeline, None).expect("session");
    let out = s.handle(":window nope");
    assert!(out.contains(want), "repl: {out}");
    let long = "w".repeat(1 << 20);
    let out = s.handle(&format!(":window {long}"));
    assert!(out.len() < 1000, "the id is cut: {} bytes", out.len());
    // The server: 404 on every route that takes a window, the same words.
    let server = crate::common::Served::start(&["--source", "sim:urban_crossing"], &[]);
    let http = crate::common::client();
    let body = serde_json::json!({"question": "Vehicles(x)", "window": "nope"});
    let retrieve = serde_json::json!({"query": "Vehicles(x)", "window": "nope"});
    for (path, body) in [
        ("/api/ask", &body),
        ("/api/context", &body),
        ("/v1/retrieve", &retrieve),
    ] {
        let r = http.post(server.at(path)).json(body).send().expect(path);
        assert_eq!(r.status().as_u16(), 404, "{path}");
        let v: serde_json::Value = r.json().expect("a JSON error");
        let msg = v["error"]["message"].as_str().unwrap_or_default();
        assert!(msg.contains(want), "{path}: {msg}");
    }
    let r = http
        .get(server.at("/api/facts?window=nope"))
        .send()
        .expect("facts");
    let v: serde_json::Value = r.json().expect("a JSON error");
    let msg = v["error"]["message"].as_str().unwrap_or_default();
    assert!(msg.contains(want), "/api/facts: {msg}");
}

/// Issue 22 item 4: `--noise` is a source flag of `ask`, `facts` and
/// `context` (as of `eval`): it replaces a sim: scenario's noise, the seed
/// then matters, and other sources refuse it by name.
#[test]
fn noise_levels_reach_ask_facts_and_context_for_sim_sources() {
    let facts = |args: &[&str]| {
        let mut all = vec!["facts", "--frames", "0-9"];
        all.extend_from_slice(args);
        let out = logicrag(&all);
        assert!(
            out.status.success(),
            "facts {args:?}: {}",
            text(&out.stderr)
        );
        text(&out.stdout)
    };
    let clean0 = facts(&["--source", "sim:urban_crossing@0", "--noise", "none"]);
    let clean3 = facts(&["--source", "sim:urban_crossing@3", "--noise", "none"]);
    assert_eq!(clean0, clean3, "without noise the seed changes nothing");
    let high0 = facts(&["--source", "sim:urban_crossing@0", "--noise", "high"]);
    let high3 = facts(&["--source", "sim:urban_crossing@3", "--noise", "high"]);
    assert_ne!(clean0, high0, "high noise changes the facts");
    assert_ne!(high0, high3, "and each seed its own way");
    for cmd in ["ask", "context"] {
        let out = logicrag(&[
            cmd,
            "--source",
            "sim:urban_crossing@2",
            "--noise",
            "mono",
            "--frames",
            "0-9",
            "Vehicles(x)",
        ]);
        assert!(out.status.success(), "{cmd}: {}", text(&out.stderr));
        assert!(!out.stdout.is_empty(), "{cmd} printed nothing");
    }
    let kitti = logicrag(&["facts", "--source", "kitti:/nowhere", "--noise", "high"]);
    assert!(!kitti.status.success());
    assert!(
        text(&kitti.stderr).contains("--noise high applies to simulator sources"),
        "{}",
        text(&kitti.stderr)
    );
    let two = logicrag(&["ask", "--noise", "high,mono", "Vehicles(x)"]);
    assert!(!two.status.success());
    assert!(
        text(&two.stderr).contains("--noise takes one level here"),
        "{}",
        text(&two.stderr)
    );
}

/// Issue 22 item 3: answers carry a probability — 1 from a noise-free
/// source, below 1 where noisy measurements leave doubt — C2 says it, and
/// eval reports the calibration per noise level.
#[test]
fn answers_say_how_sure_they_are_and_eval_reports_their_calibration() {
    let ask = |noise: &str| {
        let out = logicrag(&[
            "ask",
            "--source",
            "sim:urban_crossing@3",
            "--noise",
            noise,
            "--json",
            "Is the red car stopped?",
        ]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        text(&out.stdout)
            .lines()
            .map(|l| serde_json::from_str::<serde_json::Value>(l).expect("a JSON line"))
            .filter(|v| v.get("window").is_some())
            .collect::<Vec<_>>()
    };
    for r in ask("none") {
        assert_eq!(r["probability"], 1.0, "{r}");
        assert!(r.get("binding_probabilities").is_none(), "{r}");
    }
    let high = ask("high");
    let probs: Vec<f64> = high
        .iter()
        .map(|r| r["probability"].as_f64().expect("a probability"))
        .collect();
    assert!(probs.iter().all(|p| (0.0..=1.0).contains(p)), "{probs:?}");
    assert!(
        probs.iter().any(|p| *p < 1.0),
        "high noise, yet certain: {probs:?}"
    );
    for r in &high {
        let bindings = r["bindings"].as_array().map_or(0, Vec::len);
        if let Some(b) = r.get("binding_probabilities") {
            assert_eq!(b.as_array().map(Vec::len), Some(bindings), "{r}");
        }
    }
    let context = |question: &str| {
        let out = logicrag(&[
            "context",
            "--source",
            "sim:urban_crossing@3",
            "--noise",
            "high",
            "--frames",
            "0-9",
            question,
        ]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        out
    };
    let ctx = context("Is the red car stopped?");
    assert!(
        text(&ctx.stdout).contains("with probability 0."),
        "C2 does not say how sure: {}",
        text(&ctx.stdout)
    );
    // A "no" says which doubtful fact it hinges on.
    let no = context("Is the red car moving?");
    assert!(
        text(&no.stdout).contains("The answer would change if Moving(car_4) held"),
        "{}",
        text(&no.stdout)
    );
    let eval = logicrag(&[
        "eval",
        "--source",
        "sim:braking",
        "--noise",
        "none,high",
        "--seeds",
        "1",
        "--json",
    ]);
    assert!(eval.status.success(), "{}", text(&eval.stderr));
    let report: serde_json::Value = serde_json::from_slice(&eval.stdout).expect("eval JSON");
    let levels = report["calibration"]
        .as_array()
        .expect("calibration per level");
    assert_eq!(levels.len(), 2, "{levels:?}");
    assert_eq!(levels[0]["noise"], "none");
    assert_eq!(
        levels[0]["brier"], 0.0,
        "noise-free answers are certain and right"
    );
    let brier = levels[1]["brier"].as_f64().expect("a Brier score");
    assert!(brier > 0.0 && brier < 0.25, "high noise Brier {brier}");
    assert!(levels[1]["ece"].as_f64().is_some());
}

/// Issue 36 item 3: `eval --json` scores the answers as forecasts of yes
/// against the base rate — overall, without U1 and per category — with a
/// reliability table, per noise level and per source; `--noise` takes a
/// scaled preset (`high*2`) and refuses a bad factor.
#[test]
fn eval_reports_skill_against_the_base_rate_and_takes_a_scaled_noise_level() {
    let eval = logicrag(&[
        "eval",
        "--source",
        "sim:braking",
        "--noise",
        "high,high*2",
        "--seeds",
        "1",
        "--json",
    ]);
    assert!(eval.status.success(), "{}", text(&eval.stderr));
    let report: serde_json::Value = serde_json::from_slice(&eval.stdout).expect("eval JSON");
    let levels = report["skill"].as_array().expect("skill per level");
    let names: Vec<&str> = levels.iter().filter_map(|l| l["noise"].as_str()).collect();
    assert_eq!(names, ["high", "high*2"]);
    for level in levels {
        for subset in ["overall", "without_u1"] {
            let f = &level[subset];
            for field in [
                "questions",
                "correct",
                "accuracy",
                "scored",
                "brier",
                "base_rate",
                "base_brier",
                "skill",
                "constant_confidence_brier",
                "confidence_skill",
                "confident_wrong",
            ] {
                assert!(f.get(field).is_some(), "{subset} lacks {field}: {f}");
            }
            let brier = f["brier"].as_f64().expect("a Brier score");
            let base = f["base_brier"].as_f64().expect("a base-rate Brier score");
            let skill = f["skill"].as_f64().expect("a skill score");
            assert!((skill - (1.0 - brier / base)).abs() < 1e-9, "{f}");
            let bins = f["reliability"].as_array().expect("reliability bins");
            let n: u64 = bins.iter().filter_map(|b| b["n"].as_u64()).sum();
            assert_eq!(
                Some(n),
                f["scored"].as_u64(),
                "the bins hold every scored answer"
            );
            for b in bins {
                for field in ["from", "to", "n", "mean_p_yes", "frequency_yes"] {
                    assert!(b.get(field).is_some(), "a bin lacks {field}: {b}");
                }
            }
        }
        let all = level["overall"]["questions"].as_u64().expect("questions");
        let rest = level["without_u1"]["questions"]
            .as_u64()
            .expect("questions");
        let u1 = level["by_category"]["U1"]["questions"]
            .as_u64()
            .expect("U1");
        assert_eq!(all, rest + u1);
    }
    // Each source carries its own, and the existing fields stay.
    let sources = report["sources"].as_array().expect("sources");
    assert_eq!(sources.len(), 2);
    assert_eq!(sources[1]["noise"], "high*2");
    assert!(sources[1]["skill"]["by_category"]["U2"]["brier"].is_number());
    assert!(sources[1]["calibration"]["brier"].is_number());
    assert!(report["calibration"].is_array() && report["noise_table"].is_array());
    // The text report shows the table and the reliability bins.
    let out = logicrag(&[
        "eval",
        "--source",
        "sim:braking",
        "--noise",
        "high*2",
        "--seeds",
        "1",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let shown = text(&out.stdout);
    for want in [
        "noise high*2: Brier against the base rate",
        "without U1",
        "reliability",
        "[0.9, 1.0]",
    ] {
        assert!(shown.contains(want), "no `{want}` in {shown}");
    }
    for (bad, says) in [
        ("high*0", "must be a positive finite number"),
        ("high*-2", "must be a positive finite number"),
        ("high*x", "must be a positive finite number"),
        ("high*inf", "must be a positive finite number"),
        ("loud*2", "unknown noise level `loud`"),
        ("none*2", "`none` has no noise to scale"),
    ] {
        let out = logicrag(&["eval", "--source", "sim:braking", "--noise", bad]);
        assert_eq!(out.status.code(), Some(2), "{bad}");
        assert!(
            text(&out.stderr).contains(says),
            "{bad}: {}",
            text(&out.stderr)
        );
    }
}

#[test]
fn ask_limit_lists_the_first_bindings_of_a_huge_query_and_says_more_exist() {
    // 65,536 bindings in this window: the first 5, at the cost of 5.
    let q = "Pedestrian(x)^Vehicles(y0)^Vehicles(y1)^Vehicles(y2)^Vehicles(y3)^Vehicles(y4)^Vehicles(y5)^Vehicles(y6)^Vehicles(y7)";
    let out = logicrag(&[
        "ask",
        "--window-id",
        "urban_crossing_000020",
        "--limit",
        "5",
        "--json",
        q,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let first: serde_json::Value =
        serde_json::from_str(text.lines().next().expect("a window line")).expect("json");
    assert_eq!(first["answer"], "yes");
    assert_eq!(first["bindings"].as_array().map(Vec::len), Some(5));
    assert_eq!(first["proofs"].as_array().map(Vec::len), Some(5));
    assert_eq!(first["truncated"]["more"], true);
    assert_eq!(first["truncated"]["total"], serde_json::Value::Null);
    // A page that reaches the end of a small answer is a slice of the
    // sorted bindings, with their total.
    // The first window's JSON object of `ask --json ARGS… Vehicles(x)`.
    let window = |extra: &[&str]| -> serde_json::Value {
        let mut args = vec![
            "ask",
            "--window-id",
            "urban_crossing_000020",
            "--json",
            "--no-proofs",
        ];
        args.extend_from_slice(extra);
        args.push("Vehicles(x)");
        let out = logicrag(&args);
        let text = String::from_utf8_lossy(&out.stdout).to_string();
        serde_json::from_str(text.lines().next().expect("a window line")).expect("json")
    };
    let all = window(&[]);
    let page = window(&["--limit", "3", "--offset", "1"]);
    assert_eq!(
        page["bindings"],
        serde_json::json!(all["bindings"].as_array().expect("list")[1..4])
    );
    assert_eq!(
        page["truncated"]["total"],
        serde_json::json!(all["bindings"].as_array().map(Vec::len))
    );
    // Text says how to get the next page; --limit 0 and --offset alone are refused.
    let out = logicrag(&[
        "ask",
        "--window-id",
        "urban_crossing_000020",
        "--limit",
        "3",
        "--no-proofs",
        q,
    ]);
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("more exist: --offset 3 for the next page")
    );
    assert_eq!(
        logicrag(&["ask", "--limit", "0", "Vehicles(x)"])
            .status
            .code(),
        Some(2)
    );
    assert_eq!(
        logicrag(&["ask", "--offset", "2", "Vehicles(x)"])
            .status
            .code(),
        Some(2)
    );
}
