//! Reading query text: existential queries ([`parse_query`]) and every
//! form, universal and counting included ([`parse_any_query`]).

use super::ast::{
    CountOp, CountQuery, ParsedQuery, PlanCache, QueryAst, UniversalQuery, is_variable_name,
};
use crate::diag::{DiagKind, Diagnostic, Severity, SourceFile, Span};
use crate::fol::{self, Formula, Quant, Resolver};
use std::sync::Arc;

fn query_syntax_error(source: &Arc<SourceFile>, e: fol::SyntaxError, help: &str) -> Diagnostic {
    Diagnostic::new(
        DiagKind::FolSyntax,
        Severity::Error,
        source,
        e.span,
        e.message,
    )
    .with_label(e.label)
    .with_help(help)
}

const QUERY_HELP: &str = "a query looks like `TypeOf(x, Car) ∧ ColorOf(x) = White ∧ ¬Moving(x)`";

/// Parses an existential query (conjunctions, `∨`, `¬`, `∃`, comparisons).
/// Names are variables or constants by their spelling alone
/// ([`is_variable_name`]). A leading `∀` is refused here, never dropped:
/// [`parse_any_query`] answers universals.
// The error is a full diagnostic (source, spans, help), returned by value
// because it is the shape every caller renders.
#[allow(clippy::result_large_err)]
pub fn parse_query(text: &str) -> Result<QueryAst, Diagnostic> {
    match parse_any_query(text)? {
        ParsedQuery::Exists(q) => Ok(std::sync::Arc::unwrap_or_clone(q)),
        ParsedQuery::Forall(u) => Err(Diagnostic::new(
            DiagKind::Unsupported,
            Severity::Error,
            &u.source,
            Span::new(0, u.source.text.len()),
            "a universal query is not an existential one",
        )
        .with_label("`∀` asks whether every object qualifies")
        .with_help("answer it with `parse_any_query`, or drop the `∀` to list the objects")),
        ParsedQuery::Count(c) => Err(Diagnostic::new(
            DiagKind::Unsupported,
            Severity::Error,
            &c.source,
            Span::new(0, c.source.text.len()),
            "a counting query is not an existential one",
        )
        .with_label("`#{…}` asks how many objects qualify")
        .with_help(
            "answer it with `parse_any_query`, or drop the `#{x: …} op N` to list the objects",
        )),
    }
}

/// Parses a query of either form. A leading `∀x: A → B` is a universal
/// query; a `∀` whose body is not an implication (`∀x: Moving(x)`) ranges
/// over everything and is refused with a diagnostic, as are `→` and `∀`
/// anywhere else: a query is never read as something weaker than written.
#[allow(clippy::result_large_err)]
pub fn parse_any_query(text: &str) -> Result<ParsedQuery, Diagnostic> {
    let source = SourceFile::new("<query>", text);
    if text.trim_start().starts_with('#') {
        return parse_count(&source).map(|c| ParsedQuery::Count(Box::new(c)));
    }
    let f = fol::parse_formula(text).map_err(|e| query_syntax_error(&source, e, QUERY_HELP))?;
    let mut forall: Vec<String> = Vec::new();
    let mut body = &f;
    let mut forall_span = None;
    while let Formula::Quantified {
        quant: Quant::Forall,
        vars,
        body: b,
        span,
    } = body
    {
        forall.extend(vars.iter().map(|(n, _)| n.clone()));
        forall_span.get_or_insert(*span);
        body = b;
    }
    let Some(forall_span) = forall_span else {
        return existential(&source, &f, None).map(|q| ParsedQuery::Exists(std::sync::Arc::new(q)));
    };
    let Formula::Implies(antecedent, consequent, _) = body else {
        let v = forall.first().cloned().unwrap_or_else(|| "x".into());
        return Err(Diagnostic::new(
            DiagKind::Unsupported,
            Severity::Error,
            &source,
            forall_span,
            format!("`∀{v}` without `→` ranges over everything, which no window can list"),
        )
        .with_label("say which objects this is about")
        .with_help(format!(
            "write `∀{v}: Vehicles({v}) → Moving({v})` to ask whether every vehicle moves, or drop the `∀` to ask which objects do"
        )));
    };
    let written = |f: &Formula| {
        let sp = f.span();
        text.get(sp.start..sp.end)
            .unwrap_or_default()
            .trim()
            .to_string()
    };
    let (antecedent_text, consequent_text) = (written(antecedent), written(consequent));
    let (a, b) = (antecedent.as_ref().clone(), consequent.as_ref().clone());
    let span = f.span();
    let and = |parts: Vec<Formula>| Formula::And(parts);
    let counter = and(vec![a.clone(), Formula::Not(Box::new(b.clone()), span)]);
    let witness = and(vec![a.clone(), b]);
    let answer = Some(forall.as_slice());
    Ok(ParsedQuery::Forall(Box::new(UniversalQuery {
        counterexamples: existential(&source, &counter, answer)?,
        domain: existential(&source, &a, answer)?,
        witnesses: existential(&source, &witness, answer)?,
        vars: forall,
        antecedent: antecedent_text,
        consequent: consequent_text,
        source,
    })))
}

const COUNT_HELP: &str = "a counting query looks like `#{x: TypeOf(x, Car)} >= 3` (ops >= > <= < =; `#{x, y: …}` counts pairs)";

/// `#{x, y: Q} op N`, the text around `Q` read here and `Q` by the FOL
/// parser, over the whole text with everything but `Q` blanked out, so
/// that every span of `Q` points into the text as written.
#[allow(clippy::result_large_err)]
fn parse_count(source: &Arc<SourceFile>) -> Result<CountQuery, Diagnostic> {
    let text = source.text.as_str();
    let err = |span: Span, message: String, label: &str| {
        Diagnostic::new(DiagKind::FolSyntax, Severity::Error, source, span, message)
            .with_label(label)
            .with_help(COUNT_HELP)
    };
    let hash = text.find('#').unwrap_or(0);
    let after = |i: usize| text.get(i..).unwrap_or("");
    let skip_ws = |i: usize| i + (after(i).len() - after(i).trim_start().len());
    let open = skip_ws(hash + 1);
    if !after(open).starts_with('{') {
        return Err(err(
            Span::new(hash, open + 1),
            "expected `{` after `#`".into(),
            "a count is written `#{x: …}`",
        ));
    }
    let Some(close) = after(open).find('}').map(|i| open + i) else {
        return Err(err(
            Span::new(open, text.len()),
            "this `{` is never closed".into(),
            "expected `}` after the counted query",
        ));
    };
    let Some(colon) = text
        .get(open + 1..close)
        .and_then(|h| h.find(':'))
        .map(|i| open + 1 + i)
    else {
        return Err(err(
            Span::new(open, close + 1),
            "expected `:` after the counted variables".into(),
            "write `#{x: Query}`",
        ));
    };
    // The counted variables: names (or `?names`) separated by commas.
    let mut vars: Vec<String> = Vec::new();
    let mut var_spans = Vec::new();
    let mut at = open + 1;
    for part in text.get(open + 1..colon).unwrap_or("").split(',') {
        let lead = part.len() - part.trim_start().len();
        let name = part.trim();
        let start = at + lead;
        let span = Span::new(start, start + name.len());
        at += part.len() + 1;
        let bare = name.strip_prefix('?').unwrap_or(name);
        let ok = !bare.is_empty()
            && bare
                .chars()
                .next()
                .is_some_and(|c| c.is_alphabetic() || c == '_')
            && bare.chars().all(|c| c.is_alphanumeric() || c == '_');
        if !ok {
            return Err(err(
                span,
                format!("expected a variable name to count, found `{name}`"),
                "expected a variable here",
            ));
        }
        if vars.iter().any(|v| v == bare) {
            return Err(err(
                span,
                format!("`{bare}` is counted twice"),
                "already counted",
            ));
        }
        vars.push(bare.to_string());
        var_spans.push(span);
    }
    // The test after `}`.
    let op_at = skip_ws(close + 1);
    let rest = after(op_at);
    let ops: [(&str, CountOp); 8] = [
        (">=", CountOp::AtLeast),
        ("≥", CountOp::AtLeast),
        ("<=", CountOp::AtMost),
        ("≤", CountOp::AtMost),
        ("==", CountOp::Exactly),
        ("=", CountOp::Exactly),
        (">", CountOp::MoreThan),
        ("<", CountOp::FewerThan),
    ];
    let Some((sym, op)) = ops.iter().find(|(sym, _)| rest.starts_with(sym)) else {
        return Err(err(
            Span::new(op_at, op_at + rest.chars().next().map_or(0, char::len_utf8)),
            "expected a comparison (`>=`, `>`, `<=`, `<` or `=`) after the count".into(),
            "expected `>=`, `>`, `<=`, `<` or `=` here",
        ));
    };
    let num_at = skip_ws(op_at + sym.len());
    let digits: &str = {
        let r = after(num_at);
        let end = r.find(|c: char| !c.is_ascii_digit()).unwrap_or(r.len());
        r.get(..end).unwrap_or("")
    };
    let end = num_at + digits.len();
    let n = match digits.parse::<usize>() {
        Ok(n) => n,
        Err(_) => {
            return Err(err(
                Span::new(num_at, (num_at + 1).min(text.len())),
                "expected a whole number after the comparison".into(),
                "expected a number here",
            ));
        }
    };
    if !after(end).trim().is_empty() {
        return Err(err(
            Span::new(skip_ws(end), text.len()),
            "unexpected text after the count's number".into(),
            "expected the query to end here",
        ));
    }
    // `Q`, parsed in place: every byte outside it becomes a space.
    let (q_start, q_end) = (colon + 1, close);
    let mut blanked = String::with_capacity(text.len());
    for (i, c) in text.char_indices() {
        if i >= q_start && i < q_end {
            blanked.push(c);
        } else {
            blanked.extend(std::iter::repeat_n(' ', c.len_utf8()));
        }
    }
    if text.get(q_start..q_end).is_none_or(|q| q.trim().is_empty()) {
        return Err(err(
            Span::new(open, close + 1),
            "the counted query is empty".into(),
            "write the query after `:`",
        ));
    }
    let f = fol::parse_formula(&blanked).map_err(|e| query_syntax_error(source, e, COUNT_HELP))?;
    if let Formula::Quantified {
        quant: Quant::Forall,
        span,
        ..
    } = &f
    {
        return Err(Diagnostic::new(
            DiagKind::Unsupported,
            Severity::Error,
            source,
            *span,
            "a counted query is existential: `∀` cannot be counted",
        )
        .with_label("not countable")
        .with_help(COUNT_HELP));
    }
    let query = existential(source, &f, Some(&vars))?;
    Ok(CountQuery {
        source: Arc::clone(source),
        inner: text.get(q_start..q_end).unwrap_or("").trim().to_string(),
        vars,
        var_spans,
        query,
        op: *op,
        n,
    })
}

/// An existential query from a formula. `answer` names the answer
/// variables (a universal's `∀` variables); `None` takes every variable not
/// bound by `∃`.
#[allow(clippy::result_large_err)]
fn existential(
    source: &Arc<SourceFile>,
    f: &Formula,
    answer: Option<&[String]>,
) -> Result<QueryAst, Diagnostic> {
    let mut exist = Vec::new();
    collect_exists(f, &mut exist);
    let mut bound = Vec::new();
    fol::bound_names(f, &mut bound);
    bound.extend(answer.into_iter().flatten().cloned());
    let is_constant = |n: &str| !is_variable_name(n);
    let mut r = Resolver::new(bound, &is_constant, true);
    let disjuncts = fol::to_dnf(f, &mut r).map_err(|e| {
        Diagnostic::new(
            DiagKind::Unsupported,
            Severity::Error,
            source,
            e.span,
            e.message,
        )
        .with_label(e.label)
    })?;
    // A `¬∃`'s own variables are never answers (they have a slot of
    // their own, which no name outside it finds).
    let answer_vars = match answer {
        None => (0..r.vars.len())
            .filter(|&v| !exist.contains(&r.vars[v]) && !r.locals.contains(&v))
            .collect(),
        Some(names) => names
            .iter()
            .filter_map(|n| (0..r.vars.len()).find(|&v| r.vars[v] == *n && !r.locals.contains(&v)))
            .collect(),
    };
    Ok(QueryAst {
        source: Arc::clone(source),
        vars: r.vars,
        answer_vars,
        disjuncts,
        plans: PlanCache::default(),
    })
}

/// The names a positive `∃` binds (projected away from the answers); a
/// negated `∃` binds variables of its own, which are never answers anyway.
fn collect_exists(f: &Formula, out: &mut Vec<String>) {
    match f {
        Formula::Quantified {
            quant, vars, body, ..
        } => {
            if *quant == Quant::Exists {
                out.extend(vars.iter().map(|(n, _)| n.clone()));
            }
            collect_exists(body, out);
        }
        Formula::Not(g, _) if matches!(**g, Formula::Quantified { .. }) => {}
        Formula::Not(g, _) => collect_exists(g, out),
        Formula::And(fs) | Formula::Or(fs) => fs.iter().for_each(|g| collect_exists(g, out)),
        Formula::Implies(a, b, _) => {
            collect_exists(a, out);
            collect_exists(b, out);
        }
        Formula::Atom(_) | Formula::Equal { .. } => {}
    }
}
