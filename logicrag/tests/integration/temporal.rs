//! Temporal questions over a whole video, as a user asks them
//! (`logicrag ask --source sim:braking …`): `THEN` in both orders, a
//! question asked at a window that sees only its past, and a batch line
//! that cannot answer a claim about time. The truth comes from the
//! scenario's event log (perception's simulator), never from logicrag's
//! answers.

use perception::sim::{Event, EventKind, Scenario, simulate};
use serde_json::Value;
use std::process::{Command, Output};

fn logicrag(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_logicrag"))
        .args(args)
        .output()
        .expect("the logicrag binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// `ask --json` of `query` on sim:braking: its JSON lines.
fn ask_json(query: &str, extra: &[&str]) -> Vec<Value> {
    let mut args = vec!["ask", "--source", "sim:braking", "--json"];
    args.extend_from_slice(extra);
    args.push(query);
    let out = logicrag(&args);
    assert!(out.status.success(), "{query}: {}", text(&out.stderr));
    text(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{query}: {e}: {l}")))
        .collect()
}

/// The vehicle of the braking scenario that brakes and then stands, by
/// the event log: its brake event and its first stop event after it.
fn brakes_then_stops() -> (String, Event, Event) {
    let scenario = Scenario::builtin("braking").expect("the braking scenario");
    let run = simulate(&scenario, 0).expect("simulates");
    let of = |name: &str, kind: EventKind| -> Vec<Event> {
        run.events
            .iter()
            .filter(|e| e.object == name && e.kind == kind)
            .cloned()
            .collect()
    };
    let names: std::collections::BTreeSet<&str> = run
        .events
        .iter()
        .filter(|e| e.object.starts_with("car_"))
        .map(|e| e.object.as_str())
        .collect();
    for name in names {
        for brake in of(name, EventKind::Brake) {
            if let Some(stop) = of(name, EventKind::Stop)
                .into_iter()
                .find(|s| s.first_frame >= brake.last_frame)
            {
                // Never the other way round: no braking after it stands.
                assert!(
                    of(name, EventKind::Brake)
                        .iter()
                        .all(|b| b.first_frame < stop.first_frame),
                    "{name} brakes again after standing"
                );
                return (name.to_string(), brake, stop);
            }
        }
    }
    panic!("no car brakes and then stands in the braking scenario")
}

#[test]
fn then_is_yes_in_the_order_of_the_event_log_and_no_reversed() {
    let (car, brake, stop) = brakes_then_stops();
    let forward = format!("(Decelerate({car})) THEN (Stopped({car}))");
    let lines = ask_json(&forward, &[]);
    // One result for the video, then the summary.
    assert_eq!(lines.len(), 2, "{lines:?}");
    let (result, summary) = (&lines[0], &lines[1]);
    assert_eq!(result["window"], "sim:braking");
    assert_eq!(result["first_frame"], 0);
    assert_eq!(summary["summary"]["answer"], "yes", "{summary}");
    let holds = &result["temporal"]["holds"][0]["parts"];
    let frames = |part: &Value| -> (u64, u64) {
        let w = &part["witness"];
        (
            w["first"].as_u64().unwrap_or(u64::MAX),
            w["last"].as_u64().unwrap_or(u64::MAX),
        )
    };
    let (slow, stand) = (frames(&holds[0]), frames(&holds[1]));
    // The windows named are in order, the slowing one within the braking
    // and the standing one after the braking began.
    assert!(slow.1 < stand.0, "{slow:?} then {stand:?}");
    assert!(
        slow.1 >= u64::from(brake.first_frame) && slow.0 <= u64::from(brake.last_frame),
        "slowing in {slow:?}, braking in {}–{}",
        brake.first_frame,
        brake.last_frame
    );
    assert!(
        stand.1 >= u64::from(stop.first_frame),
        "standing in {stand:?}"
    );
    let headline = summary["headline"].as_str().unwrap_or_default();
    assert!(headline.starts_with("yes — `Decelerate("), "{headline}");
    assert!(headline.contains(", then `Stopped("), "{headline}");

    let reverse = format!("(Stopped({car})) THEN (Decelerate({car}))");
    let lines = ask_json(&reverse, &[]);
    assert_eq!(lines[1]["summary"]["answer"], "no", "{lines:?}");
    // AFTER is THEN with the parts swapped.
    let after = format!("(Stopped({car})) AFTER (Decelerate({car}))");
    assert_eq!(ask_json(&after, &[])[1]["summary"]["answer"], "yes");

    // Asked at the window where the braking starts, the stop is in its
    // future: not yes.
    let first_window = brake.first_frame / 10 * 10;
    let at = format!("braking_{first_window:06}");
    let lines = ask_json(&forward, &["--window-id", &at]);
    assert_ne!(lines[1]["summary"]["answer"], "yes", "{lines:?}");
    assert_eq!(lines[0]["last_frame"], first_window + 9);

    // The text output names the frames; with a variable, the car.
    let out = logicrag(&[
        "ask",
        "--source",
        "sim:braking",
        "(Vehicles(x) ^ ColorOf(x, Red) ^ Decelerate(x)) THEN (Stopped(x))",
    ]);
    let stdout = text(&out.stdout);
    let answer = stdout
        .lines()
        .find(|l| l.starts_with("answer:"))
        .unwrap_or_default();
    assert!(
        answer.starts_with(&format!("answer:   yes — x = {car}: ")),
        "{stdout}"
    );
    assert!(
        answer.contains("in frames") && answer.contains(", then "),
        "{answer}"
    );
}

#[test]
fn a_batch_line_cannot_answer_a_claim_about_time() {
    let dir = std::env::temp_dir().join(format!("logicrag-temporal-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a scratch directory");
    let file = dir.join("queries.tsv");
    std::fs::write(
        &file,
        "braking_000000\tEVER: Stopped(x)\nbraking_000000\tVehicles(x)\n",
    )
    .expect("writes");
    let path = file.display().to_string();
    let out = logicrag(&[
        "ask",
        "--source",
        "sim:braking",
        "--json",
        "--queries",
        &path,
    ]);
    let _ = std::fs::remove_dir_all(&dir);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let lines: Vec<Value> = text(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("JSON"))
        .collect();
    assert_eq!(lines.len(), 2);
    assert_eq!(lines[0]["answer"], "invalid");
    let reason = lines[0]["reasons"][0].as_str().unwrap_or_default();
    assert!(
        reason.contains("one window alone cannot answer it"),
        "{reason}"
    );
    assert_eq!(lines[1]["answer"], "yes");
}
