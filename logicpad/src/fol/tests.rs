use super::*;

fn parses(s: &str) -> Formula {
    parse_formula(s).unwrap_or_else(|e| panic!("{s}: {e:?}"))
}

#[test]
fn all_operator_spellings_parse_the_same() {
    let forms = [
        "∀x,y : A(x) ∧ ¬B(x, y) ∨ C(y) ==> D(x)",
        "forall x, y: A(x) & ~B(x, y) | C(y) -> D(x)",
        "forall x,y . A(x) and not B(x, y) or C(y) implies D(x)",
        "∀x,y: A(x) ^ !B(x, y) || C(y) → D(x)",
        "∀x,y: A(x) && !B(x,y) ∨ C(y) => D(x)",
    ];
    let strip = |f: &Formula| format!("{f:?}").split("span").count();
    let first = parses(forms[0]);
    for f in &forms[1..] {
        let g = parses(f);
        // Same shape: quantifier, implication, or-of-and, negation.
        assert_eq!(strip(&first), strip(&g), "{f}");
        let Formula::Quantified { body, .. } = g else {
            panic!("{f}")
        };
        let Formula::Implies(lhs, _, _) = *body else {
            panic!("{f}")
        };
        assert!(matches!(*lhs, Formula::Or(ref v) if v.len() == 2), "{f}");
    }
}

#[test]
fn function_sugar_and_comparisons() {
    let Formula::And(parts) = parses("ColorOf(x) = White ∧ TypeOf(x) ≠ Car ∧ x != y") else {
        panic!()
    };
    let Formula::Atom(a) = &parts[0] else {
        panic!("{:?}", parts[0])
    };
    assert_eq!(a.pred, "ColorOf");
    assert_eq!(a.args.len(), 2);
    assert!(matches!(&parts[1], Formula::Not(..)));
    assert!(matches!(&parts[2], Formula::Equal { negated: true, .. }));
}

#[test]
fn names_resolve_by_scope_case_and_resolver() {
    let f = parses("∃y : On(x, y) ∧ Road(y) ∧ Near(x, car_3) ∧ Is(?v, \"big car\", Car)");
    let mut bound = Vec::new();
    bound_names(&f, &mut bound);
    let known = |n: &str| n == "car_3";
    let mut r = Resolver::new(bound, &known, true);
    let d = to_dnf(&f, &mut r).expect("dnf");
    assert_eq!(r.vars, vec!["x", "y", "v"]);
    let Literal::Pos(near) = &d[0][2] else {
        panic!()
    };
    assert_eq!(near.args[1], Arg::Const("car_3".into()));
    let Literal::Pos(is) = &d[0][3] else { panic!() };
    assert_eq!(
        is.args,
        vec![
            Arg::Var(2),
            Arg::Const("big car".into()),
            Arg::Const("Car".into())
        ]
    );
}

#[test]
fn dnf_distributes_and_pushes_negation() {
    let f = parses("(A(x) ∨ B(x)) ∧ ¬(C(x) ∨ D(x))");
    let never = |_: &str| false;
    let mut r = Resolver::new(Vec::new(), &never, true);
    let d = to_dnf(&f, &mut r).expect("dnf");
    assert_eq!(d.len(), 2);
    assert!(d.iter().all(|c| c.len() == 3
        && matches!(c[1], Literal::Neg(_))
        && matches!(c[2], Literal::Neg(_))));
    // ¬(A ∧ B) = ¬A ∨ ¬B
    let f = parses("V(x) ∧ ¬(A(x) ∧ B(x))");
    let mut r = Resolver::new(Vec::new(), &never, true);
    assert_eq!(to_dnf(&f, &mut r).expect("dnf").len(), 2);
    // ¬∃ is refused in a rule body, with a clear message.
    let f = parses("V(x) ∧ ¬∃y : On(x, y)");
    let mut r = Resolver::new(Vec::new(), &never, false);
    let e = to_dnf(&f, &mut r).expect_err("refused in a rule");
    assert!(e.message.contains("negated `∃`"), "{}", e.message);
}

#[test]
fn a_negated_exists_is_one_scoped_literal() {
    let never = |_: &str| false;
    // The local `y` is a slot of its own: the outer `y` is another.
    let f = parses("Road(y) ∧ P(x) ∧ ¬∃y: (Road(y) ∧ On(x, y)) ∧ Q(y)");
    let mut bound = Vec::new();
    bound_names(&f, &mut bound);
    let mut r = Resolver::new(bound, &never, true);
    let d = to_dnf(&f, &mut r).expect("dnf");
    assert_eq!(r.vars, vec!["y", "x", "y"]);
    assert_eq!(d.len(), 1);
    let Literal::NotExists { vars, body, .. } = &d[0][2] else {
        panic!("{:?}", d[0][2])
    };
    assert_eq!(vars, &vec![2]);
    assert_eq!(body.len(), 2);
    assert!(matches!(&body[1], Literal::Pos(a) if a.args == vec![Arg::Var(1), Arg::Var(2)]));
    // After the ∃, `y` is the outer one again.
    assert!(matches!(&d[0][3], Literal::Pos(a) if a.args == vec![Arg::Var(0)]));
    assert_eq!(d[0][2].free_vars(), vec![1]);
    // A disjunctive body is one ¬∃ per alternative; ¬¬∃ is ∃.
    let f = parses("P(x) ∧ ~∃y: (A(x, y) ∨ B(y)) ∧ not not exists z: C(z)");
    let mut bound = Vec::new();
    bound_names(&f, &mut bound);
    let mut r = Resolver::new(bound, &never, true);
    let d = to_dnf(&f, &mut r).expect("dnf");
    assert_eq!(d.len(), 1);
    assert_eq!(d[0].iter().filter(|l| l.is_not_exists()).count(), 2);
    assert!(matches!(d[0].last(), Some(Literal::Pos(a)) if a.pred == "C"));
    // Nested.
    let f = parses("P(x) ∧ ¬∃y: (On(x, y) ∧ ¬∃z: (Near(y, z)))");
    let mut bound = Vec::new();
    bound_names(&f, &mut bound);
    let mut r = Resolver::new(bound, &never, true);
    let d = to_dnf(&f, &mut r).expect("dnf");
    let Literal::NotExists { body, .. } = &d[0][1] else {
        panic!()
    };
    assert!(body[1].is_not_exists());
    assert_eq!(d[0][1].atoms().len(), 2);
}

/// Regression (fuzzer, issue 13): a negated disjunction of one
/// conjunction and thousands of atoms is two alternatives, each with
/// every negated atom, in order — built in place, not re-copied per
/// atom (which was quadratic).
#[test]
fn negated_long_disjunction_appends_in_place() {
    let atoms: Vec<String> = (0..3000).map(|i| format!("C{i}(x)")).collect();
    let f = parses(&format!("V(x) ∧ ¬((A(x) ∧ B(x)) ∨ {})", atoms.join(" ∨ ")));
    let never = |_: &str| false;
    let mut r = Resolver::new(Vec::new(), &never, true);
    let d = to_dnf(&f, &mut r).expect("dnf");
    assert_eq!(d.len(), 2);
    for (alt, first) in d.iter().zip(["A", "B"]) {
        assert_eq!(alt.len(), 1 + 1 + 3000);
        assert!(matches!(&alt[0], Literal::Pos(a) if a.pred == "V"));
        assert!(matches!(&alt[1], Literal::Neg(a) if a.pred == first));
        assert!(matches!(&alt[2], Literal::Neg(a) if a.pred == "C0"));
        assert!(matches!(&alt[3001], Literal::Neg(a) if a.pred == "C2999"));
    }
}

#[test]
fn errors_point_at_the_problem() {
    let e = parse_formula("A(x) ∧ B(x").expect_err("unclosed");
    assert_eq!(e.span.start, "A(x) ∧ B(x".len());
    let e = parse_formula("A(x) B(x)").expect_err("missing and");
    assert!(e.message.contains("missing `∧`"), "{}", e.message);
    let e = parse_formula("A(x) ∧ $").expect_err("bad char");
    assert!(e.message.contains('$'));
    assert!(parse_formula("").is_err());
    assert!(parse_formula("\"open").is_err());
    let deep = format!("{}A(x){}", "(".repeat(500), ")".repeat(500));
    assert!(
        parse_formula(&deep).is_err(),
        "deep nesting is an error, not a stack overflow"
    );
}
