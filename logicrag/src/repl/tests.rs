//! The REPL session's tests: commands, questions, paging with `more`, LogicPad reloads.

use super::*;

fn session() -> Session {
    Session::new(Pipeline::open_default("sim:urban_crossing"), None).unwrap()
}

#[test]
fn define_and_rule_add_a_checked_rule_the_next_question_uses() {
    let mut s = session();
    assert!(s.handle(":window 3").contains("urban_crossing_000030"));
    let before = s.handle("Is a pedestrian jaywalking?");
    assert!(
        before.contains("cannot translate") || before.contains("INVALID"),
        "{before}"
    );
    let added = s.handle(":define A pedestrian is jaywalking when it is on a road and moving");
    assert!(added.contains("added (line"), "{added}");
    assert!(added.contains("==> Jaywalking(x)"), "{added}");
    let after = s.handle("Is a pedestrian jaywalking?");
    assert!(
        after.contains("query: Pedestrian(x)^Jaywalking(x)"),
        "{after}"
    );
    assert!(after.contains("YES"), "{after}");
    // FOL, used at once by a query; its proof cites it.
    let added = s.handle(":rule ∀x : Pedestrian(x) ∧ Jaywalking(x) ∧ ¬Stopped(x) ==> Hurrying(x)");
    assert!(added.contains("added"), "{added}");
    let why = s.handle(":why Hurrying(pedestrian_5)");
    assert!(why.contains("==> Hurrying(x)"), "{why}");
    // Refused with the checker's words; the session keeps its rules.
    let refused = s.handle(":rule ∀x : Vehicles(x) ==> Stopped(x)");
    assert!(refused.starts_with("no rule added"), "{refused}");
    assert!(
        s.handle(":define cars are nice")
            .starts_with("no rule added")
    );
    assert!(s.handle(":rule").starts_with("usage"));
    assert!(s.handle("Is a pedestrian jaywalking?").contains("YES"));
}

#[test]
fn commands_and_questions() {
    let mut s = session();
    assert!(s.handle(":windows").contains("urban_crossing_000000"));
    assert!(s.handle(":window 3").contains("urban_crossing_000030"));
    let facts = s.handle(":facts pedestrian_5");
    assert!(facts.contains("Pedestrian(pedestrian_5)"), "{facts}");
    let ans = s.handle("Is the pedestrian on the road?");
    assert!(ans.starts_with("query: Pedestrian(x)"), "{ans}");
    assert!(ans.contains("YES"), "{ans}");
    let why = s.handle(":why Walk(pedestrian_5)");
    assert!(
        why.contains("rule") || why.contains("does not hold"),
        "{why}"
    );
    assert!(s.handle(":rules").contains("line"));
    assert!(s.handle(":nope").contains("unknown command"));
    assert!(
        s.handle("Moving(nobody_1) ^ Frobnicate(x)")
            .contains("INVALID")
    );
    assert!(s.completions().iter().any(|c| c == "ConstantSpeed"));
    assert!(s.completions().iter().any(|c| c == "pedestrian_5"));
}

#[test]
fn a_temporal_question_looks_back_from_the_window_in_focus() {
    let mut s = session();
    // The ego brakes over frames 10–40 and then stands.
    let q = "(Decelerate(ego)) THEN (Stopped(ego))";
    assert!(s.handle(":window 1").contains("urban_crossing_000010"));
    let early = s.handle(q);
    assert!(
        early.contains("(windows up to urban_crossing_000010)"),
        "{early}"
    );
    assert!(!early.starts_with("YES"), "{early}");
    let last = s.window_count() - 1;
    s.handle(&format!(":window {last}"));
    let late = s.handle(q);
    assert!(late.starts_with("YES"), "{late}");
    assert!(late.contains(", then `Stopped(ego)` in frames "), "{late}");
}

#[test]
fn a_command_without_its_colon_gets_a_hint() {
    let mut s = session();
    // Bare one-word commands run as they are (issue: `help` without the
    // colon printed only a hint).
    for bare in ["help", "Help", "windows", "rules"] {
        assert!(!s.handle(bare).contains("cannot translate"), "{bare}");
    }
    assert!(s.handle("help").contains(":windows"));
    // The hint names the command as it must be typed, arguments kept.
    let out = s.handle("why Pedestrian(pedestrian_5)");
    assert!(
        out.contains("e.g. `:why Pedestrian(pedestrian_5)`"),
        "{out}"
    );
    let out = s.handle("window 3");
    assert!(out.contains("e.g. `:window 3`"), "{out}");
    // Natural questions that start with a command's name get none.
    for q in [
        "Why is the white car moving?",
        "help me find the red car",
        "facts about car_1",
    ] {
        assert!(!s.handle(q).contains("commands start"), "{q}");
    }
    let out = s.handle("why Moving(car_1, car_2)");
    assert!(out.contains("e.g. `:why Moving(car_1, car_2)`"), "{out}");
    // A real question that fails to translate gets no such hint.
    assert!(!s.handle("flibbertigibbet").contains("commands start"));
}

#[test]
fn why_with_a_variable_is_a_query_and_facts_hide_pair_bookkeeping() {
    let mut s = session();
    // Regression: `:why Moving(x)` looked for the ground fact `Moving(x)`.
    let out = s.handle(":why Pedestrian(x)");
    assert!(out.starts_with("YES (1 answer)"), "{out}");
    assert!(out.contains("x = pedestrian_5"), "{out}");
    let out = s.handle(":facts");
    assert!(!out.contains("SharesFrames("), "{out}");
    let all = s.handle(":facts all");
    assert!(all.contains("SharesFrames("), "the window has pair facts");
    assert!(
        out.contains("facts not shown; `:facts all` lists them"),
        "{out}"
    );
}

#[test]
fn hostile_lines_and_empty_logicpads_are_refused() {
    let mut s = session();
    // Regression: `:load` of an empty file replaced the whole vocabulary.
    let dir = std::env::temp_dir().join(format!("logicrag-repl-empty-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let empty = dir.join("empty.yaml");
    std::fs::write(&empty, "~\n").expect("write");
    let out = s.handle(&format!(":load {}", empty.display()));
    assert!(
        out.contains("kept the previous LogicPad") && out.contains("declares no predicates"),
        "{out}"
    );
    assert!(s.handle("Pedestrian(x)").starts_with("YES"));
    std::fs::remove_dir_all(&dir).expect("clean");
    // Control characters are not echoed back raw.
    let out = s.handle("Is the \u{1b}[31mred car moving?");
    assert!(!out.contains('\u{1b}'), "{out:?}");
}

#[test]
fn answers_show_how_many_bindings() {
    let mut s = session();
    let out = s.handle("Pedestrian(x)");
    assert!(out.starts_with("YES (1 answer) (window "), "{out}");
}

#[test]
fn answers_come_a_page_at_a_time_and_more_gives_the_next() {
    let mut s = session();
    let bindings = |out: &str| out.lines().filter(|l| l.starts_with("  x = ")).count();
    // 4 vehicles: 16 pairs, a page of 10, then 6.
    let out = s.handle("Vehicles(x) ^ Vehicles(y)");
    assert!(out.starts_with("YES (16 answers)"), "{out}");
    assert_eq!(bindings(&out), 10, "{out}");
    assert!(out.contains("… 6 more: `more` (or `;`)"), "{out}");
    let out = s.handle("more");
    assert_eq!(bindings(&out), 6, "{out}");
    assert_eq!(s.handle(";"), "no more answers\n");
    // Past the answer limit: the answers found before it are listed,
    // page by page from that one run, each with its proof.
    let q = (0..9)
        .map(|i| format!("Vehicles(v{i})"))
        .collect::<Vec<_>>()
        .join(" ^ ");
    let out = s.handle(&q);
    assert!(
        out.starts_with("YES (at least 100000 answers)")
            && out.contains("the run stopped at its answers limit"),
        "{out}"
    );
    let first = out.lines().filter(|l| l.starts_with("  v0 = ")).count();
    assert_eq!(first, 10, "{out}");
    assert!(out.contains("[fact: "), "{out}");
    let next = s.handle(";");
    assert_eq!(
        next.lines().filter(|l| l.starts_with("  v0 = ")).count(),
        10
    );
    assert!(next.contains("… 99980 more"), "{next}");
}

#[test]
fn hot_reload_picks_up_a_changed_logicpad() {
    let dir = std::env::temp_dir().join(format!("logicrag-repl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("pad.yaml");
    std::fs::write(&path, logicpad::BUILTIN_SOURCE).unwrap();
    let mut s = session();
    assert!(
        s.handle(&format!(":load {}", path.display()))
            .contains("loaded")
    );
    assert!(s.handle("Slowpoke(x)").contains("INVALID"));
    let extra = format!(
        "{}\n  - name: Slowpoke\n    logic: \"∀x : Vehicles(x) ∧ ¬Moving(x) ==> Slowpoke(x)\"\n",
        logicpad::BUILTIN_SOURCE.trim_end()
    );
    // Make sure the modification time moves on coarse file systems.
    std::thread::sleep(std::time::Duration::from_millis(20));
    std::fs::write(&path, extra).unwrap();
    let filetime_changed = mtime(&path) != s.pad_mtime;
    let out = s.handle("Slowpoke(x)");
    if filetime_changed {
        assert!(out.contains("loaded"), "{out}");
        assert!(!out.contains("INVALID"), "{out}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
