//! The paper's reference LogicPad (`../shared/data/logicrag-reference/LogicPad.yaml`)
//! loads unchanged, with its real problems reported at their lines.

use logicpad::{DiagKind, Diagnostic, LogicPad, Severity};
use std::path::Path;

const REFERENCE: &str = "../../shared/data/logicrag-reference/LogicPad.yaml";

fn reference() -> Option<LogicPad> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(REFERENCE);
    if !path.exists() {
        println!(
            "NOTICE: {} is absent (no ../shared); reference LogicPad test skipped",
            path.display()
        );
        return None;
    }
    Some(LogicPad::load(&path).expect("the reference LogicPad loads (non-strict)"))
}

fn find(pad: &LogicPad, kind: DiagKind, line: usize) -> &Diagnostic {
    pad.diagnostics()
        .iter()
        .find(|d| d.kind == kind && d.line() == line)
        .unwrap_or_else(|| {
            let all: Vec<String> = pad.diagnostics().iter().map(Diagnostic::summary).collect();
            panic!("no {kind:?} at line {line}; got:\n{}", all.join("\n"))
        })
}

#[test]
fn reports_the_reference_quirks_at_their_lines() {
    let Some(pad) = reference() else { return };
    // `Appear`/`Disappear` are used, `Appears`/`Disappears` declared.
    for line in [190, 193, 265] {
        let d = find(&pad, DiagKind::UnknownPredicate, line);
        assert_eq!(d.snippet(), "Appear");
        assert_eq!(d.help.as_deref(), Some("did you mean `Appears`?"));
    }
    for line in [184, 187, 268] {
        assert_eq!(
            find(&pad, DiagKind::UnknownPredicate, line).help.as_deref(),
            Some("did you mean `Disappears`?")
        );
    }
    // `¬Move(x) ==> Stopped(x)`: unsafe under real negation, dead under `NotMove`.
    let d = find(&pad, DiagKind::UnsafeRule, 114);
    assert_eq!(d.severity, Severity::Error);
    assert!(
        d.help
            .as_deref()
            .is_some_and(|h| h.contains("dead") && h.contains("NotMove")),
        "{:?}",
        d.help
    );
    find(&pad, DiagKind::UnsafeRule, 115);
    find(&pad, DiagKind::UnsafeRule, 172);
    // Negated heads are warnings and become integrity constraints.
    for line in [134, 137] {
        assert_eq!(
            find(&pad, DiagKind::NegatedHead, line).severity,
            Severity::Warning
        );
    }
    assert_eq!(pad.program().constraints().len(), 2);
    // `Motorcycle` is not among TypeOf's values.
    let d = find(&pad, DiagKind::UndeclaredValue, 196);
    assert_eq!(d.snippet(), "Motorcycle");
    assert_eq!(d.column(), 60);
    // `TrafficSign` vs the declared `Trafficsign`.
    find(&pad, DiagKind::HeadMismatch, 261);
    // The reference's negation-as-predicate base facts.
    find(&pad, DiagKind::NegationAsPredicate, 34);
}

#[test]
fn the_rest_of_the_reference_still_loads_and_reasons() {
    let Some(pad) = reference() else { return };
    let program = pad.program();
    // Rules without errors are kept: e.g. Cross (existential y), Collide, Crash, Walk, ConstantSpeed.
    for head in [
        "Cross",
        "Collide",
        "Crash",
        "Walk",
        "ConstantSpeed",
        "IsPerson",
    ] {
        assert!(
            program
                .rules()
                .iter()
                .any(|r| program.pred_name(r.head.pred) == Some(head)),
            "no rule for {head}"
        );
    }
    // Left out: the rules with errors.
    for head in [
        "Merge",
        "Enter",
        "Diverge",
        "Exit",
        "Ride",
        "Appeared",
        "Stopped",
        "ConstantDistance",
    ] {
        assert!(
            !program
                .rules()
                .iter()
                .any(|r| program.pred_name(r.head.pred) == Some(head)),
            "rule for {head} should have been left out"
        );
    }
    let mut facts = logicpad::FactBase::new();
    facts.add("Vehicles", &["car_1"]).expect("fact");
    facts.add("SpeedUp", &["car_2"]).expect("fact");
    facts.add("Vehicles", &["car_2"]).expect("fact");
    facts.add("Pedestrian", &["pedestrian_1"]).expect("fact");
    facts.add("On", &["pedestrian_1", "road_0"]).expect("fact");
    facts.add("Road", &["road_0"]).expect("fact");
    let model = program.evaluate(facts).expect("evaluates");
    // ConstantSpeed with real negation, independent of where it sits in the file.
    assert_eq!(
        model.facts("ConstantSpeed"),
        vec![vec!["car_1".to_string()], vec!["pedestrian_1".to_string()]]
    );
    assert!(model.holds("Cross", &["pedestrian_1"]));
    // Pedestrian ⇄ Person recursion reaches its fixpoint.
    assert!(model.holds("IsPerson", &["pedestrian_1"]));
    assert!(model.holds("Person", &["pedestrian_1"]));
    // The integrity constraint `¬SpeedUp(x) ==> ¬Accelerate(x)` holds here.
    assert!(model.violations().is_empty(), "{:?}", model.violations());
}
