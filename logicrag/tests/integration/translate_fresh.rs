//! The translator on a fresh set of questions written for this test
//! (`tests/data/fresh_questions.tsv`), across the paper's categories: U1
//! object query, U2 velocity, U3 change of velocity, U4 appear/disappear,
//! B1 relative position, B2 relative distance change, and OOV questions that
//! must be refused.
//!
//! Each question is translated and judged against its gold with the rules
//! of `../shared/tools/query_equiv.py`, mirrored here so that the test needs
//! neither `../shared` nor python:
//! - atoms are joined by `^`, `∧`, `&` or "and"; `¬`, `~`, `!` or "not "
//!   negate; `ColorOf(x) = White` is `ColorOf(x, White)`;
//! - gold may list alternatives separated by " | "; an atom prefixed with
//!   `?` is optional;
//! - predicate synonyms are folded (GoAway = DistanceIncrease, Move =
//!   Moving, Stopped = NotMoving, Accelerate = SpeedUp, `IsX` = `X`, ...);
//! - constants compare case-insensitively, Gray = Grey;
//! - `Vehicles(v)` is dropped when `TypeOf(v, T)` is present;
//! - variable names do not matter (an injective renaming of the
//!   candidate's variables into the gold's), the distance relations are
//!   symmetric;
//! - the candidate holds every required gold atom and nothing else.
//!
//! Two rules are stricter than the python judge, because this set tests
//! exactly these distinctions: `Person` (a *sitting* person in the
//! project's LogicPad) is not folded into `Pedestrian`, nor is `IsPerson`
//! (anyone: Person ∨ Pedestrian), and `Vehicles(v)` is dropped only when
//! `v`'s type is a constant (`TypeOf(x, y)` in a value question says
//! nothing about being a vehicle).

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;

use logicrag::translate::{Translator, Vocabulary};

/// One normalised atom: predicate (with a leading `¬` when negated) and
/// arguments (variables as `?name`, constants lower-cased).
type Atom = (String, Vec<String>);

/// Predicate synonyms of `query_equiv.py`, less the person entries (see
/// the module comment).
const SYNONYMS: &[(&str, &str)] = &[
    ("goaway", "distanceincrease"),
    ("distanceincreases", "distanceincrease"),
    ("comeclose", "distancedecrease"),
    ("gettingcloser", "distancedecrease"),
    ("distancedecreases", "distancedecrease"),
    ("move", "moving"),
    ("moves", "moving"),
    ("stopped", "notmoving"),
    ("stop", "notmoving"),
    ("ispedestrian", "isperson"),
    ("appears", "appear"),
    ("appeared", "appear"),
    ("disappears", "disappear"),
    ("disappeared", "disappear"),
    ("accelerate", "speedup"),
    ("increasepace", "speedup"),
    ("decelerate", "speeddown"),
    ("decreasepace", "speeddown"),
    ("fixedpace", "constantspeed"),
    ("vehicle", "vehicles"),
    ("isvehicles", "vehicles"),
    ("isvehicle", "vehicles"),
];

/// Names that keep their `Is` prefix: `IsPerson` is not `Person`.
const KEEP_IS: &[&str] = &["isperson", "isolated"];

const SYMMETRIC: &[&str] = &[
    "distanceincrease",
    "distancedecrease",
    "constantdistance",
    "notdistanceincrease",
    "notdistancedecrease",
    "tooclose",
];

fn synonym(n: &str) -> String {
    SYNONYMS
        .iter()
        .find(|(from, _)| *from == n)
        .map_or_else(|| n.to_string(), |(_, to)| (*to).to_string())
}

fn norm_pred(name: &str) -> String {
    let n = synonym(&name.to_lowercase());
    if n.starts_with("is") && n.len() > 2 && !KEEP_IS.contains(&n.as_str()) {
        return synonym(&n[2..]);
    }
    n
}

fn is_variable(a: &str) -> bool {
    let mut chars = a.chars();
    match chars.next() {
        Some('?') => a.len() > 1,
        Some(c) if c.is_ascii_lowercase() => chars.all(|d| d.is_ascii_digit()),
        _ => false,
    }
}

/// Parses one conjunction into (required, optional) atoms.
fn parse(query: &str) -> Result<(Vec<Atom>, Vec<Atom>), String> {
    let mut text = query.replace(['∧', '&'], "^");
    text = text.replace(" and ", "^");
    let mut req = Vec::new();
    let mut opt = Vec::new();
    for part in text.split('^').map(str::trim).filter(|p| !p.is_empty()) {
        let (optional, rest) = match part.strip_prefix('?') {
            Some(r) => (true, r.trim_start()),
            None => (false, part),
        };
        let (negated, rest) = if let Some(r) = rest.strip_prefix('¬') {
            (true, r)
        } else if let Some(r) = rest.strip_prefix('~').or_else(|| rest.strip_prefix('!')) {
            (true, r)
        } else if let Some(r) = rest.strip_prefix("not ") {
            (true, r)
        } else {
            (false, rest)
        };
        let rest = rest.trim();
        let (name, tail) = rest
            .split_once('(')
            .ok_or_else(|| format!("cannot read atom {part:?} in {query:?}"))?;
        let (inner, after) = tail
            .split_once(')')
            .ok_or_else(|| format!("cannot read atom {part:?} in {query:?}"))?;
        let name = name.trim();
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(format!("cannot read atom {part:?} in {query:?}"));
        }
        let mut args: Vec<String> = inner
            .split(',')
            .map(str::trim)
            .filter(|a| !a.is_empty())
            .map(str::to_string)
            .collect();
        let after = after.trim();
        if let Some(value) = after.strip_prefix('=') {
            args.push(value.trim().to_string());
        } else if !after.is_empty() {
            return Err(format!("cannot read atom {part:?} in {query:?}"));
        }
        let args = args
            .into_iter()
            .map(|a| {
                if is_variable(&a) {
                    format!("?{}", a.trim_start_matches('?'))
                } else {
                    match a.to_lowercase().as_str() {
                        "gray" => "grey".to_string(),
                        other => other.to_string(),
                    }
                }
            })
            .collect();
        let pred = format!("{}{}", if negated { "¬" } else { "" }, norm_pred(name));
        if optional {
            opt.push((pred, args));
        } else {
            req.push((pred, args));
        }
    }
    Ok((req, opt))
}

/// Drops `Vehicles(v)` when `v` has a constant type.
fn drop_implied(atoms: Vec<Atom>) -> Vec<Atom> {
    let typed: BTreeSet<String> = atoms
        .iter()
        .filter(|(p, a)| p == "typeof" && a.len() == 2 && !a[1].starts_with('?'))
        .map(|(_, a)| a[0].clone())
        .collect();
    atoms
        .into_iter()
        .filter(|(p, a)| !(p == "vehicles" && a.first().is_some_and(|v| typed.contains(v))))
        .collect()
}

fn canon((pred, args): &Atom) -> Atom {
    let mut args = args.clone();
    if args.len() == 2 && SYMMETRIC.contains(&pred.trim_start_matches('¬')) {
        args.sort();
    }
    (pred.clone(), args)
}

fn variables(atoms: &[Atom]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for (_, args) in atoms {
        for a in args {
            if a.starts_with('?') && !out.contains(a) {
                out.push(a.clone());
            }
        }
    }
    out
}

/// Every injective assignment of `k` items out of `from`, in order.
fn arrangements(from: &[String], k: usize) -> Vec<Vec<String>> {
    if k == 0 {
        return vec![Vec::new()];
    }
    let mut out = Vec::new();
    for (i, first) in from.iter().enumerate() {
        let mut rest = from.to_vec();
        rest.remove(i);
        for mut tail in arrangements(&rest, k - 1) {
            tail.insert(0, first.clone());
            out.push(tail);
        }
    }
    out
}

fn equivalent_one(gold: &str, cand: &str) -> Result<bool, String> {
    let (g_req, g_opt) = parse(gold)?;
    let (c_req, c_opt) = parse(cand)?;
    let c = drop_implied(c_req.into_iter().chain(c_opt).collect());
    let g_req = drop_implied(g_req);
    let g_all: Vec<Atom> = g_req.iter().chain(g_opt.iter()).cloned().collect();
    let (gv, cv) = (variables(&g_all), variables(&c));
    if cv.len() > gv.len() {
        return Ok(false);
    }
    let req: BTreeSet<Atom> = g_req.iter().map(canon).collect();
    let allowed: BTreeSet<Atom> = req.iter().cloned().chain(g_opt.iter().map(canon)).collect();
    for perm in arrangements(&gv, cv.len()) {
        let ren: BTreeMap<&String, &String> = cv.iter().zip(perm.iter()).collect();
        let cs: BTreeSet<Atom> = c
            .iter()
            .map(|(p, args)| {
                let args = args
                    .iter()
                    .map(|a| ren.get(a).map_or_else(|| a.clone(), |r| (*r).clone()))
                    .collect();
                canon(&(p.clone(), args))
            })
            .collect();
        if req.is_subset(&cs) && cs.is_subset(&allowed) {
            return Ok(true);
        }
    }
    Ok(false)
}

/// A gold in one of issue 31's forms (scoped negation, counting, time
/// order): compared as written, up to spaces.
fn structured(gold: &str) -> bool {
    [
        "¬∃",
        "#{",
        " THEN ",
        " BEFORE ",
        " AFTER ",
        "EVER:",
        "THROUGHOUT:",
        "STILL:",
    ]
    .iter()
    .any(|k| gold.contains(k))
}

fn squeeze(q: &str) -> String {
    q.chars().filter(|c| !c.is_whitespace()).collect()
}

/// Whether `cand` is equivalent to one of the gold's alternatives.
fn equivalent(gold: &str, cand: &str) -> Result<bool, String> {
    for g in gold.split(" | ") {
        if structured(g) {
            if squeeze(g) == squeeze(cand) {
                return Ok(true);
            }
            continue;
        }
        if structured(cand) {
            continue;
        }
        if equivalent_one(g, cand)? {
            return Ok(true);
        }
    }
    Ok(false)
}

struct Case {
    line: usize,
    category: String,
    question: String,
    gold: String,
}

fn cases() -> Vec<Case> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/fresh_questions.tsv");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: cannot read: {e}", path.display()));
    let mut out = Vec::new();
    let mut header = false;
    for (k, line) in text.lines().enumerate() {
        let line_no = k + 1;
        if line.trim().is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split('\t').collect();
        let [category, question, gold] = fields.as_slice() else {
            panic!(
                "{}:{line_no}: expected 3 tab-separated fields (category, question, gold), found {}",
                path.display(),
                fields.len()
            );
        };
        if !header {
            assert_eq!(
                fields,
                ["category", "question", "gold"],
                "{}:{line_no}: header",
                path.display()
            );
            header = true;
            continue;
        }
        if *gold != "REFUSE"
            && let Some(e) = gold
                .split(" | ")
                .filter(|g| !structured(g))
                .find_map(|g| parse(g).err())
        {
            panic!("{}:{line_no}: bad gold: {e}", path.display());
        }
        out.push(Case {
            line: line_no,
            category: category.to_string(),
            question: question.to_string(),
            gold: gold.to_string(),
        });
    }
    out
}

/// Per category: (right, total), in category order of first appearance.
struct Score {
    by_category: Vec<(String, usize, usize)>,
    right: usize,
    total: usize,
    refused_wrongly_accepted: Vec<String>,
}

fn run(translator: &Translator, tag: &str) -> Score {
    let cases = cases();
    let mut by_category: Vec<(String, usize, usize)> = Vec::new();
    let mut misses = Vec::new();
    let mut accepted = Vec::new();
    for c in &cases {
        let result = translator.translate(&c.question);
        let (ok, got) = match (&result, c.gold.as_str()) {
            (Err(e), "REFUSE") => (true, format!("refused: {e}")),
            (Ok(t), "REFUSE") => {
                accepted.push(format!("{:?} → {}", c.question, t.query));
                (false, t.query.clone())
            }
            (Err(e), _) => (false, format!("ERROR {e}")),
            (Ok(t), gold) => match equivalent(gold, &t.query) {
                Ok(same) => (same, t.query.clone()),
                Err(e) => (false, format!("{}  [{e}]", t.query)),
            },
        };
        match by_category.iter_mut().find(|(k, _, _)| *k == c.category) {
            Some(entry) => {
                entry.1 += usize::from(ok);
                entry.2 += 1;
            }
            None => by_category.push((c.category.clone(), usize::from(ok), 1)),
        }
        if !ok {
            misses.push(format!(
                "MISS [{}] line {}: {}\n      gold: {}\n      got:  {got}",
                c.category, c.line, c.question, c.gold
            ));
        }
    }
    let right: usize = by_category.iter().map(|(_, r, _)| r).sum();
    let total = cases.len();
    println!("== {tag} vocabulary: fresh questions ==");
    for m in &misses {
        println!("{m}");
    }
    for (k, r, n) in &by_category {
        println!("{k:>4}: {r}/{n} = {:.3}", *r as f64 / (*n).max(1) as f64);
    }
    println!(
        "overall: {right}/{total} = {:.3}",
        right as f64 / total.max(1) as f64
    );
    Score {
        by_category,
        right,
        total,
        refused_wrongly_accepted: accepted,
    }
}

fn assert_score(s: &Score) {
    assert!(s.total >= 70, "the fresh set holds {} questions", s.total);
    for k in ["U1", "U2", "U3", "U4", "B1", "B2", "OOV"] {
        assert!(
            s.by_category.iter().any(|(c, _, _)| c == k),
            "category {k} missing from the fresh set"
        );
    }
    assert!(
        s.refused_wrongly_accepted.is_empty(),
        "questions that must be refused were translated:\n{}",
        s.refused_wrongly_accepted.join("\n")
    );
    assert!(
        s.right * 100 >= s.total * 95,
        "overall {}/{} is below 95% (misses printed above; run with --nocapture)",
        s.right,
        s.total
    );
}

#[test]
fn fresh_questions_with_the_builtin_vocabulary() {
    assert_score(&run(&Translator::builtin(), "builtin"));
}

#[test]
fn fresh_questions_with_the_default_logicpad_vocabulary() {
    let pad = logicpad::LogicPad::builtin();
    let vocab =
        Vocabulary::from_schema(pad.schema()).expect("the default LogicPad gives a vocabulary");
    assert_score(&run(&Translator::new(vocab), "logicpad"));
}

#[test]
fn the_judge_mirrors_query_equiv() {
    let eq = |g: &str, c: &str| equivalent(g, c).unwrap_or_else(|e| panic!("{e}"));
    // Order and variable names do not matter; structure does.
    assert!(eq("P(x)^Q(x, y)", "Q(z, w)^P(z)"));
    assert!(!eq("P(x)^Q(x, y)", "P(x)^Q(y, x)"));
    assert!(!eq("P(x)^R(y)", "P(x)^R(x)"));
    // Nothing missing, nothing extra, optional atoms aside.
    assert!(!eq("P(x)", "P(x)^Q(x)"));
    assert!(!eq("P(x)^Q(x)", "P(x)"));
    assert!(eq("P(x)^?Move(x)", "P(x)"));
    assert!(eq("P(x)^?Move(x)", "P(x)^Moving(x)"));
    // Alternatives, synonyms, constants, `= value`.
    assert!(eq("A(x) | B(x)", "B(x)"));
    assert!(eq(
        "TypeOf(x, Car)^GoAway(x, y)",
        "TypeOf(x, Car)^DistanceIncrease(y, x)"
    ));
    assert!(eq("ColorOf(x) = Gray", "ColorOf(x, grey)"));
    assert!(eq("TypeOf(x, Bus)^Vehicles(x)", "TypeOf(x, Bus)"));
    // Negation counts.
    assert!(!eq("¬Move(x)^Car(x)", "Move(x)^Car(x)"));
    assert!(eq("~Move(x)^Car(x)", "¬Moving(x)^Car(x)"));
    // Stricter than the python judge: a person is not a pedestrian, a
    // variable type does not imply a vehicle.
    assert!(!eq("IsPerson(x)", "Person(x)"));
    assert!(!eq("Pedestrian(x)", "IsPerson(x)"));
    assert!(eq("IsPedestrian(x)", "IsPerson(x)"));
    assert!(!eq("Vehicles(x)^TypeOf(x, y)", "TypeOf(x, y)"));
    assert!(parse("not an atom").is_err());
    // Issue 31's forms compare as written.
    assert!(eq("#{x: TypeOf(x, Car)} > 2", "#{x:TypeOf(x, Car)} > 2"));
    assert!(!eq("#{x: TypeOf(x, Car)} > 2", "TypeOf(x, Car)"));
    assert!(!eq("TypeOf(x, Car)", "#{x: TypeOf(x, Car)} > 2"));
}
