//! Golden (insta) snapshots of every diagnostic kind, rendered the way
//! `lint` prints them (miette graphical, no colour).

use logicpad::{
    DiagKind, Diagnostic, LogicPad, Schema, check_query, lint_source, lint_with, parse_query,
};

const DECLS: &str = "atomic_predicates:
  tracker:
    - Vehicles(x)
    - Pedestrian(x)
    - Moving(x)
    - SpeedUp(x)
    - Appears(x)
    - DistanceDecrease(x, y)
functions:
  TypeOf:
    predicate: TypeOf(x, type)
    values: [Car, Van]
";

fn with_rules(rules: &[&str]) -> String {
    let mut s = DECLS.to_string();
    s.push_str("derived_predicates:\n");
    for r in rules {
        // The entry is named after the rule's head, as LogicPad files do.
        let head = r
            .rsplit("==>")
            .next()
            .unwrap_or("")
            .trim()
            .trim_start_matches('¬');
        let name = head.split('(').next().unwrap_or("R");
        s.push_str(&format!("  - name: {name}\n    logic: \"{r}\"\n"));
    }
    s
}

fn render(diags: &[Diagnostic]) -> String {
    diags
        .iter()
        .map(|d| d.render_plain(100))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Loads `src`, asserts a diagnostic of `kind` is among the results, and
/// returns every rendered diagnostic of that kind.
fn only(src: &str, kind: DiagKind) -> String {
    let report = lint_source(src, "case.yaml", false);
    let of_kind: Vec<Diagnostic> = report
        .diagnostics
        .iter()
        .filter(|d| d.kind == kind)
        .cloned()
        .collect();
    assert!(
        !of_kind.is_empty(),
        "no {kind:?} in: {}",
        render(&report.diagnostics)
    );
    render(&of_kind)
}

#[test]
fn yaml_syntax() {
    insta::assert_snapshot!(only(
        "atomic_predicates:\n  tracker: [Moving(x)\n",
        DiagKind::YamlSyntax
    ));
}

#[test]
fn structure() {
    insta::assert_snapshot!(only(
        "atomic_predicate:\n  tracker: [Moving(x)]\nfunctions: 3\n",
        DiagKind::Structure
    ));
}

#[test]
fn fol_syntax() {
    insta::assert_snapshot!(only(
        &with_rules(&["∀x : Vehicles(x) ∧ ==> Stopped(x)"]),
        DiagKind::FolSyntax
    ));
}

#[test]
fn unsupported() {
    insta::assert_snapshot!(only(
        &with_rules(&["∀x : Vehicles(x) ==> Stopped(x) ∨ Moving(x)"]),
        DiagKind::Unsupported
    ));
}

#[test]
fn unknown_predicate() {
    insta::assert_snapshot!(only(
        &with_rules(&["∀x : Appear(x) ==> Appeared(x)"]),
        DiagKind::UnknownPredicate
    ));
}

#[test]
fn arity_mismatch() {
    insta::assert_snapshot!(only(
        &with_rules(&["∀x : DistanceDecrease(x) ==> Near(x)"]),
        DiagKind::ArityMismatch
    ));
}

#[test]
fn undeclared_value() {
    insta::assert_snapshot!(only(
        &with_rules(&["∀x : TypeOf(x, Motorcycle) ==> IsMotorcycle(x)"]),
        DiagKind::UndeclaredValue
    ));
}

#[test]
fn unsafe_rule() {
    insta::assert_snapshot!(only(
        &with_rules(&["∀x : ¬Moving(x) ==> Stopped(x)"]),
        DiagKind::UnsafeRule
    ));
}

#[test]
fn negation_cycle() {
    insta::assert_snapshot!(only(
        &with_rules(&["∀x : Vehicles(x) ∧ ¬Q(x) ==> P(x)", "∀x : P(x) ==> Q(x)"]),
        DiagKind::NegationCycle
    ));
}

#[test]
fn dead_rule() {
    insta::assert_snapshot!(only(
        &with_rules(&[
            "∀x : ¬Moving(x) ==> Stopped(x)",
            "∀x : Stopped(x) ∧ Vehicles(x) ==> Parked(x)"
        ]),
        DiagKind::DeadRule
    ));
}

#[test]
fn duplicate_rule() {
    insta::assert_snapshot!(only(
        &with_rules(&[
            "∀x : Vehicles(x) ∧ Moving(x) ==> Move(x)",
            "∀x : Moving(x) ∧ Vehicles(x) ==> Move(x)"
        ]),
        DiagKind::DuplicateRule
    ));
}

#[test]
fn negated_head() {
    insta::assert_snapshot!(only(
        &with_rules(&[
            "∀x : Vehicles(x) ∧ ¬SpeedUp(x) ==> ¬Accelerate(x)",
            "∀x : Vehicles(x) ∧ SpeedUp(x) ==> Accelerate(x)"
        ]),
        DiagKind::NegatedHead
    ));
}

#[test]
fn duplicate_declaration() {
    let src = DECLS.replace("    - Appears(x)\n", "    - Appears(x)\n    - Moving(y)\n");
    insta::assert_snapshot!(only(&src, DiagKind::DuplicateDeclaration));
}

#[test]
fn head_mismatch() {
    let src = format!(
        "{DECLS}derived_predicates:\n  - name: Appeared\n    logic: \"∀x : Appears(x) ==> Appear(x)\"\n"
    );
    insta::assert_snapshot!(only(&src, DiagKind::HeadMismatch));
}

#[test]
fn negation_as_predicate() {
    let src = DECLS.replace(
        "    - Appears(x)\n",
        "    - Appears(x)\n    - NotMoving(x)\n",
    );
    insta::assert_snapshot!(only(&src, DiagKind::NegationAsPredicate));
}

#[test]
fn bad_role() {
    let src = DECLS.replace(
        "    - Moving(x)\n",
        "    - predicate: Moving(x)\n      role: verb\n    - predicate: SpeedUp2(x, y)\n      role: class\n",
    );
    insta::assert_snapshot!(only(&src, DiagKind::BadRole));
}

#[test]
fn io() {
    let report = lint_with("definitely/not/here.yaml", false);
    assert_eq!(report.exit_code(), 2);
    assert_eq!(report.diagnostics[0].kind, DiagKind::Io);
    assert!(
        report.diagnostics[0]
            .message
            .contains("definitely/not/here.yaml")
    );
    insta::assert_snapshot!(render(&report.diagnostics));
}

#[test]
fn query_diagnostics() {
    let pad = LogicPad::parse(
        &with_rules(&["∀x : Vehicles(x) ∧ Moving(x) ==> Move(x)"]),
        "case.yaml",
        false,
    )
    .expect("loads");
    let schema: &Schema = pad.schema();
    let q = parse_query("TypeOf(x) = Truck ∧ Appear(x) ∧ DistanceDecrease(x) ∧ ¬Moving(y)")
        .expect("parses");
    insta::assert_snapshot!(render(&check_query(schema, &q)));
    let bad = parse_query("TypeOf(x, Car) ∧ ∧ Moving(x)").expect_err("syntax error");
    insta::assert_snapshot!("query_syntax", bad.render_plain(100));
}

#[test]
fn lint_exit_codes() {
    assert_eq!(
        lint_source(
            &with_rules(&["∀x : Vehicles(x) ∧ Moving(x) ==> Move(x)"]),
            "a.yaml",
            false
        )
        .exit_code(),
        0
    );
    assert_eq!(
        lint_source(
            &with_rules(&["∀x : Vehicles(x) ==> ¬Moving(x)"]),
            "a.yaml",
            false
        )
        .exit_code(),
        1
    );
    assert_eq!(
        lint_source(&with_rules(&["∀x : Moving(x ==> Move(x)"]), "a.yaml", false).exit_code(),
        2
    );
    let text = lint_source(&with_rules(&["∀x : Moving(x ==> Move(x)"]), "a.yaml", false)
        .render_with(false, 100);
    assert!(text.contains("a.yaml: 1 error(s), 0 warning(s)"), "{text}");
}

#[test]
fn strict_mode_rejects_errors_and_keeps_diagnostics() {
    let src = with_rules(&[
        "∀x : Appear(x) ==> Appeared(x)",
        "∀x : Vehicles(x) ∧ Moving(x) ==> Move(x)",
    ]);
    let lenient = LogicPad::parse(&src, "case.yaml", false).expect("lenient load");
    assert_eq!(
        lenient.program().rules().len(),
        1,
        "the rule with an error is left out, the other kept"
    );
    let err = LogicPad::parse(&src, "case.yaml", true).expect_err("strict load fails");
    assert!(
        err.diagnostics()
            .iter()
            .any(|d| d.kind == DiagKind::UnknownPredicate)
    );
    assert!(err.to_string().contains("case.yaml:"), "{err}");
}

/// Regression: `logic: []` linted clean, and a query on the name then
/// failed as "not declared anywhere".
#[test]
fn an_empty_logic_list_is_a_warning() {
    let src = format!("{DECLS}derived_predicates:\n  - name: Fast\n    logic: []\n");
    let report = lint_source(&src, "case.yaml", false);
    let warning = report
        .diagnostics
        .iter()
        .find(|d| d.kind == DiagKind::Structure)
        .expect("a structure diagnostic");
    assert!(!warning.is_error());
    let text = render(std::slice::from_ref(warning));
    assert!(
        text.contains("derived predicate `Fast` has an empty `logic:` list"),
        "{text}"
    );
    assert!(text.contains("case.yaml:"), "{text}");
}

#[test]
fn a_value_no_query_can_spell_is_refused_by_lint() {
    // Regression: `Truc$k` linted clean and then failed in every query.
    let yaml = "functions:\n  app:\n    ColorOf:\n      predicate: ColorOf(x, color)\n      values: [White, Truc$k]\n";
    let pad = LogicPad::parse(yaml, "truck.yaml", false).expect("loads");
    let d = pad
        .diagnostics()
        .iter()
        .find(|d| d.is_error())
        .expect("an error");
    assert!(
        d.message.contains("`Truc$k` cannot be written in a query"),
        "{}",
        d.message
    );
    assert_eq!((d.line(), d.column()), (5, 23));
    let values = pad
        .schema()
        .predicates()
        .find(|p| p.name == "ColorOf")
        .and_then(|p| p.values.clone());
    assert_eq!(values, Some(vec!["White".to_string()]));
}
