//! The FOL text grammar shared by LogicPad rules and queries.
//!
//! ```text
//! formula  := quant | implies
//! quant    := ('∀' | 'forall' | '∃' | 'exists') name (',' name)* (':' | '.')? formula
//! implies  := or (('==>' | '=>' | '->' | '→' | '⇒' | 'implies') implies)?
//! or       := and (('∨' | '|' | '||' | 'or') and)*
//! and      := unary (('∧' | '&' | '&&' | '^' | 'and') unary)*
//! unary    := ('¬' | '~' | '!' | 'not') (nquant | unary) | '(' formula ')' | quant | atom
//! nquant   := ('∃' | 'exists' | '∀' | 'forall') name (',' name)* (':' | '.')? ('(' formula ')' | formula)
//! atom     := Name '(' term (',' term)* ')' (('=' | '≠' | '!=') term)?
//!           | term ('=' | '≠' | '!=') term
//! term     := Name | '?' Name | '"' text '"'
//! ```
//! `F(x) = c` is sugar for `F(x, c)` and `F(x) ≠ c` for `¬F(x, c)`.
//! Spans are byte offsets into the formula text; the caller shifts them into
//! its file.

use crate::diag::Span;
use std::fmt;

/// A lexical token.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Tok {
    Name(String),
    QVar(String),
    Quoted(String),
    LParen,
    RParen,
    Comma,
    Colon,
    Dot,
    Forall,
    Exists,
    Not,
    And,
    Or,
    Implies,
    Eq,
    Neq,
    Eof,
}

impl Tok {
    fn describe(&self) -> String {
        match self {
            Tok::Name(n) => format!("`{n}`"),
            Tok::QVar(n) => format!("`?{n}`"),
            Tok::Quoted(s) => format!("\"{s}\""),
            Tok::LParen => "`(`".into(),
            Tok::RParen => "`)`".into(),
            Tok::Comma => "`,`".into(),
            Tok::Colon => "`:`".into(),
            Tok::Dot => "`.`".into(),
            Tok::Forall => "`∀`".into(),
            Tok::Exists => "`∃`".into(),
            Tok::Not => "`¬`".into(),
            Tok::And => "`∧`".into(),
            Tok::Or => "`∨`".into(),
            Tok::Implies => "`==>`".into(),
            Tok::Eq => "`=`".into(),
            Tok::Neq => "`≠`".into(),
            Tok::Eof => "the end of the formula".into(),
        }
    }
}

/// A syntax error in a formula.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SyntaxError {
    /// Where (within the formula text).
    pub span: Span,
    /// What went wrong.
    pub message: String,
    /// What the caret says.
    pub label: String,
}

fn is_name_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_' || c == '\'' || c == '-'
}

fn lex(text: &str) -> Result<Vec<(Tok, Span)>, SyntaxError> {
    let mut toks = Vec::with_capacity(text.len() / 3 + 2);
    let mut it = text.char_indices().peekable();
    while let Some(&(i, c)) = it.peek() {
        let single = |t: Tok| (t, Span::new(i, i + c.len_utf8()));
        if c.is_whitespace() {
            it.next();
            continue;
        }
        let rest = text.get(i..).unwrap_or("");
        let multi: &[(&str, Tok)] = &[
            ("==>", Tok::Implies),
            ("=>", Tok::Implies),
            ("->", Tok::Implies),
            ("!=", Tok::Neq),
            ("/=", Tok::Neq),
            ("&&", Tok::And),
            ("||", Tok::Or),
        ];
        if let Some((s, t)) = multi.iter().find(|(s, _)| rest.starts_with(s)) {
            toks.push((t.clone(), Span::new(i, i + s.len())));
            for _ in 0..s.chars().count() {
                it.next();
            }
            continue;
        }
        let tok = match c {
            '(' => Some(Tok::LParen),
            ')' => Some(Tok::RParen),
            ',' => Some(Tok::Comma),
            ':' => Some(Tok::Colon),
            '.' => Some(Tok::Dot),
            '∀' => Some(Tok::Forall),
            '∃' => Some(Tok::Exists),
            '¬' | '~' | '!' => Some(Tok::Not),
            '∧' | '&' | '^' => Some(Tok::And),
            '∨' | '|' => Some(Tok::Or),
            '→' | '⇒' | '⟹' | '⊃' => Some(Tok::Implies),
            '=' => Some(Tok::Eq),
            '≠' => Some(Tok::Neq),
            _ => None,
        };
        if let Some(t) = tok {
            toks.push(single(t));
            it.next();
            continue;
        }
        if c == '"' {
            it.next();
            let mut value = String::new();
            let mut end = None;
            while let Some((j, d)) = it.next() {
                if d == '"' {
                    end = Some(j + 1);
                    break;
                }
                if d == '\\' {
                    if let Some((_, e)) = it.next() {
                        value.push(e);
                    }
                    continue;
                }
                value.push(d);
            }
            let Some(end) = end else {
                return Err(SyntaxError {
                    span: Span::new(i, text.len()),
                    message: "unterminated quoted constant".into(),
                    label: "this `\"` is never closed".into(),
                });
            };
            toks.push((Tok::Quoted(value), Span::new(i, end)));
            continue;
        }
        if c == '?' {
            it.next();
            let start = i + 1;
            let mut end = start;
            while let Some(&(j, d)) = it.peek() {
                if is_name_char(d) {
                    end = j + d.len_utf8();
                    it.next();
                } else {
                    break;
                }
            }
            if end == start {
                return Err(SyntaxError {
                    span: Span::new(i, i + 1),
                    message: "`?` must be followed by a variable name".into(),
                    label: "expected a name after `?`".into(),
                });
            }
            toks.push((
                Tok::QVar(text.get(start..end).unwrap_or("").to_string()),
                Span::new(i, end),
            ));
            continue;
        }
        if is_name_char(c) && c != '\'' && c != '-' {
            let mut end = i;
            while let Some(&(j, d)) = it.peek() {
                // `->` is an arrow, not part of a name.
                if d == '-' && text.get(j..).is_some_and(|r| r.starts_with("->")) {
                    break;
                }
                if is_name_char(d) {
                    end = j + d.len_utf8();
                    it.next();
                } else {
                    break;
                }
            }
            let word = text.get(i..end).unwrap_or("");
            let t = match word {
                "forall" => Tok::Forall,
                "exists" => Tok::Exists,
                "not" => Tok::Not,
                "and" => Tok::And,
                "or" => Tok::Or,
                "implies" => Tok::Implies,
                _ => Tok::Name(word.to_string()),
            };
            toks.push((t, Span::new(i, end)));
            continue;
        }
        return Err(SyntaxError {
            span: Span::new(i, i + c.len_utf8()),
            message: format!("unexpected character `{c}`"),
            label: "not part of the FOL syntax".into(),
        });
    }
    toks.push((Tok::Eof, Span::new(text.len(), text.len())));
    Ok(toks)
}

/// A term as written, before names are resolved into variables and constants.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum TermAst {
    /// A bare identifier (`x`, `Car`, `car_3`).
    Name(String, Span),
    /// `?x`: always a variable.
    QVar(String, Span),
    /// `"..."`: always a constant.
    Quoted(String, Span),
}

impl TermAst {
    /// Where it was written.
    pub fn span(&self) -> Span {
        match self {
            TermAst::Name(_, s) | TermAst::QVar(_, s) | TermAst::Quoted(_, s) => *s,
        }
    }
    /// The name or constant text.
    pub fn text(&self) -> &str {
        match self {
            TermAst::Name(n, _) | TermAst::QVar(n, _) | TermAst::Quoted(n, _) => n,
        }
    }
}

/// `P(t1, …, tn)` as written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AtomAst {
    /// Predicate name.
    pub pred: String,
    /// Span of the predicate name.
    pub pred_span: Span,
    /// Arguments (for `F(x) = c`, `c` is the last one).
    pub args: Vec<TermAst>,
    /// Span of the whole atom.
    pub span: Span,
}

/// Quantifier kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quant {
    /// `∀`
    Forall,
    /// `∃`
    Exists,
}

/// A parsed formula.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Formula {
    /// An atom.
    Atom(AtomAst),
    /// `a = b` (`negated`: `a ≠ b`) between two terms.
    Equal {
        /// The left term.
        left: TermAst,
        /// The right term.
        right: TermAst,
        /// True for `≠`.
        negated: bool,
        /// Where it is written.
        span: Span,
    },
    /// `¬f`
    Not(Box<Formula>, Span),
    /// `f1 ∧ f2 ∧ …`
    And(Vec<Formula>),
    /// `f1 ∨ f2 ∨ …`
    Or(Vec<Formula>),
    /// `body ==> head`
    Implies(Box<Formula>, Box<Formula>, Span),
    /// `∀x,y : f` / `∃x : f`
    Quantified {
        /// `∀` or `∃`.
        quant: Quant,
        /// The variables it binds, each where it is written.
        vars: Vec<(String, Span)>,
        /// The formula it quantifies.
        body: Box<Formula>,
        /// Where it is written.
        span: Span,
    },
}

impl Formula {
    /// The span the formula covers.
    pub fn span(&self) -> Span {
        match self {
            Formula::Atom(a) => a.span,
            Formula::Equal { span, .. } | Formula::Not(_, span) | Formula::Implies(_, _, span) => {
                *span
            }
            Formula::Quantified { span, .. } => *span,
            Formula::And(fs) | Formula::Or(fs) => fs
                .iter()
                .map(Formula::span)
                .reduce(Span::join)
                .unwrap_or_default(),
        }
    }
}

struct Parser {
    toks: Vec<(Tok, Span)>,
    pos: usize,
    depth: usize,
}

const MAX_DEPTH: usize = 200;

impl Parser {
    fn peek(&self) -> &Tok {
        self.toks.get(self.pos).map_or(&Tok::Eof, |(t, _)| t)
    }
    fn span(&self) -> Span {
        self.toks
            .get(self.pos)
            .or(self.toks.last())
            .map_or(Span::default(), |(_, s)| *s)
    }
    fn prev_end(&self) -> usize {
        self.pos
            .checked_sub(1)
            .and_then(|p| self.toks.get(p))
            .map_or(0, |(_, s)| s.end)
    }
    /// Takes the current token out (tokens are never revisited, so names
    /// move into the AST instead of being copied).
    fn bump(&mut self) -> (Tok, Span) {
        match self.toks.get_mut(self.pos) {
            Some((tok, span)) => {
                let span = *span;
                let tok = if matches!(tok, Tok::Eof) {
                    Tok::Eof
                } else {
                    std::mem::replace(tok, Tok::Eof)
                };
                self.pos += 1;
                (tok, span)
            }
            None => (
                Tok::Eof,
                self.toks.last().map_or(Span::default(), |(_, s)| *s),
            ),
        }
    }
    fn err<T>(
        &self,
        message: impl Into<String>,
        label: impl Into<String>,
    ) -> Result<T, SyntaxError> {
        Err(SyntaxError {
            span: self.span(),
            message: message.into(),
            label: label.into(),
        })
    }
    fn expect(&mut self, want: Tok, what: &str) -> Result<Span, SyntaxError> {
        if *self.peek() == want {
            Ok(self.bump().1)
        } else {
            let found = self.peek().describe();
            self.err(
                format!("expected {what}, found {found}"),
                format!("expected {what} here"),
            )
        }
    }

    fn formula(&mut self) -> Result<Formula, SyntaxError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return self.err(
                format!("formula nested more than {MAX_DEPTH} levels deep"),
                "nesting limit reached here",
            );
        }
        let f = match self.peek() {
            Tok::Forall | Tok::Exists => self.quantified(),
            _ => self.implies(),
        };
        self.depth -= 1;
        f
    }

    fn quantified(&mut self) -> Result<Formula, SyntaxError> {
        self.quantified_body(false)
    }

    /// A quantifier; `negated`: it follows a `¬`, and a body in
    /// parentheses is then the whole body, so that `¬∃y: (On(x, y)) ∧
    /// Walk(x)` negates only the group (a negated `∃` is one literal of
    /// its conjunction). Otherwise the body extends as far as it can.
    fn quantified_body(&mut self, negated: bool) -> Result<Formula, SyntaxError> {
        let (q, qspan) = self.bump();
        let quant = if q == Tok::Forall {
            Quant::Forall
        } else {
            Quant::Exists
        };
        let mut vars = Vec::new();
        loop {
            match self.bump() {
                (Tok::Name(n), s) | (Tok::QVar(n), s) => vars.push((n, s)),
                (t, s) => {
                    return Err(SyntaxError {
                        span: s,
                        message: format!(
                            "expected a variable name after the quantifier, found {}",
                            t.describe()
                        ),
                        label: "expected a variable here".into(),
                    });
                }
            }
            if *self.peek() == Tok::Comma {
                self.bump();
            } else {
                break;
            }
        }
        if matches!(self.peek(), Tok::Colon | Tok::Dot) {
            self.bump();
        }
        let body = if negated && *self.peek() == Tok::LParen {
            self.unary()?
        } else {
            self.formula()?
        };
        let span = qspan.join(body.span());
        Ok(Formula::Quantified {
            quant,
            vars,
            body: Box::new(body),
            span,
        })
    }

    fn implies(&mut self) -> Result<Formula, SyntaxError> {
        let lhs = self.or()?;
        if *self.peek() == Tok::Implies {
            self.bump();
            // `==>` is right associative: each one nests a level (10,000
            // chained arrows overflowed the stack).
            self.depth += 1;
            if self.depth > MAX_DEPTH {
                return self.err(
                    format!("formula nested more than {MAX_DEPTH} levels deep"),
                    "nesting limit reached here",
                );
            }
            let rhs = match self.peek() {
                Tok::Forall | Tok::Exists => self.quantified(),
                _ => self.implies(),
            };
            self.depth -= 1;
            let rhs = rhs?;
            let span = lhs.span().join(rhs.span());
            return Ok(Formula::Implies(Box::new(lhs), Box::new(rhs), span));
        }
        Ok(lhs)
    }

    fn or(&mut self) -> Result<Formula, SyntaxError> {
        let mut parts = vec![self.and()?];
        while *self.peek() == Tok::Or {
            self.bump();
            parts.push(self.and()?);
        }
        Ok(if parts.len() == 1 {
            parts.remove(0)
        } else {
            Formula::Or(parts)
        })
    }

    fn and(&mut self) -> Result<Formula, SyntaxError> {
        let mut parts = vec![self.unary()?];
        while *self.peek() == Tok::And {
            self.bump();
            parts.push(self.unary()?);
        }
        Ok(if parts.len() == 1 {
            parts.remove(0)
        } else {
            Formula::And(parts)
        })
    }

    fn unary(&mut self) -> Result<Formula, SyntaxError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return self.err(
                format!("formula nested more than {MAX_DEPTH} levels deep"),
                "nesting limit reached here",
            );
        }
        let r = match self.peek() {
            Tok::Not => {
                let (_, s) = self.bump();
                let inner = if matches!(self.peek(), Tok::Exists | Tok::Forall) {
                    self.quantified_body(true)?
                } else {
                    self.unary()?
                };
                let span = s.join(inner.span());
                Ok(Formula::Not(Box::new(inner), span))
            }
            Tok::LParen => {
                self.bump();
                let f = self.formula()?;
                self.expect(Tok::RParen, "`)`")?;
                Ok(f)
            }
            Tok::Forall | Tok::Exists => self.quantified(),
            _ => self.atom(),
        };
        self.depth -= 1;
        r
    }

    fn term(&mut self) -> Result<TermAst, SyntaxError> {
        if !matches!(self.peek(), Tok::Name(_) | Tok::QVar(_) | Tok::Quoted(_)) {
            let found = self.peek().describe();
            return self.err(
                format!("expected a term, found {found}"),
                "expected a variable or a constant",
            );
        }
        match self.bump() {
            (Tok::Name(n), s) => Ok(TermAst::Name(n, s)),
            (Tok::QVar(n), s) => Ok(TermAst::QVar(n, s)),
            (Tok::Quoted(v), s) => Ok(TermAst::Quoted(v, s)),
            (t, s) => Err(SyntaxError {
                span: s,
                message: format!("expected a term, found {}", t.describe()),
                label: "expected a variable or a constant".into(),
            }),
        }
    }

    fn atom(&mut self) -> Result<Formula, SyntaxError> {
        let first = self.term()?;
        if *self.peek() == Tok::LParen {
            let TermAst::Name(pred, pred_span) = first else {
                return Err(SyntaxError {
                    span: first.span(),
                    message: "a predicate name must be a plain identifier".into(),
                    label: "not a predicate name".into(),
                });
            };
            self.bump();
            let mut args = Vec::new();
            if *self.peek() != Tok::RParen {
                loop {
                    args.push(self.term()?);
                    match self.peek() {
                        Tok::Comma => {
                            self.bump();
                        }
                        Tok::RParen => break,
                        t => {
                            let found = t.describe();
                            return self.err(
                                format!("expected `,` or `)` in the arguments of `{pred}`, found {found}"),
                                "expected `,` or `)`",
                            );
                        }
                    }
                }
            }
            let close = self.expect(Tok::RParen, "`)`")?;
            let mut atom = AtomAst {
                pred,
                pred_span,
                args,
                span: pred_span.join(close),
            };
            return match self.peek() {
                Tok::Eq | Tok::Neq => {
                    let (op, _) = self.bump();
                    let value = self.term()?;
                    atom.span = atom.span.join(value.span());
                    atom.args.push(value);
                    let span = atom.span;
                    let f = Formula::Atom(atom);
                    Ok(if op == Tok::Neq {
                        Formula::Not(Box::new(f), span)
                    } else {
                        f
                    })
                }
                _ => Ok(Formula::Atom(atom)),
            };
        }
        match self.peek() {
            Tok::Eq | Tok::Neq => {
                let (op, _) = self.bump();
                let right = self.term()?;
                let span = first.span().join(right.span());
                Ok(Formula::Equal {
                    left: first,
                    right,
                    negated: op == Tok::Neq,
                    span,
                })
            }
            _ => {
                let name = first.text().to_string();
                Err(SyntaxError {
                    span: first.span(),
                    message: format!("expected `(` after `{name}`: an atom needs its arguments"),
                    label: "expected `(` after this name".into(),
                })
            }
        }
    }
}

/// Parses one formula (a rule `body ==> head`, or a query).
pub fn parse_formula(text: &str) -> Result<Formula, SyntaxError> {
    let toks = lex(text)?;
    let mut p = Parser {
        toks,
        pos: 0,
        depth: 0,
    };
    if *p.peek() == Tok::Eof {
        return p.err("empty formula", "expected a formula");
    }
    let f = p.formula()?;
    if *p.peek() != Tok::Eof {
        let found = p.peek().describe();
        let hint = if matches!(p.peek(), Tok::Name(_)) && p.prev_end() > 0 {
            " (missing `∧` between atoms?)"
        } else {
            ""
        };
        return p.err(
            format!("unexpected {found} after a complete formula{hint}"),
            "expected the formula to end here",
        );
    }
    Ok(f)
}

/// A resolved term: a variable (index into the owner's variable list) or a constant.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Arg {
    /// Variable number `i` (see the owner's `vars`).
    Var(usize),
    /// A constant.
    Const(String),
}

/// A resolved atom.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Atom {
    /// Predicate name.
    pub pred: String,
    /// Arguments.
    pub args: Vec<Arg>,
    /// Span of the whole atom.
    pub span: Span,
    /// Span of the predicate name.
    pub pred_span: Span,
    /// Span of each argument.
    pub arg_spans: Vec<Span>,
}

/// A body literal.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Literal {
    /// `P(..)`
    Pos(Atom),
    /// `¬P(..)`
    Neg(Atom),
    /// `a = b` / `a ≠ b` (`negated`).
    Cmp {
        /// The left argument.
        left: Arg,
        /// The right argument.
        right: Arg,
        /// True for `≠`.
        negated: bool,
        /// Where it is written.
        span: Span,
    },
    /// `¬∃vars: (body)`: no binding of the local variables `vars` makes
    /// the conjunction `body` hold (queries only; a rule body refuses it).
    ///
    /// Invariant: the local variables are slots of their own (a name
    /// bound by this `∃` never shares a slot with the same name outside
    /// it), so they occur only in `body`; every other variable of `body`
    /// is bound outside, by a positive atom of the enclosing conjunction
    /// (the query's safety check).
    NotExists {
        /// The local variables (`∃`'s), as slots of the owner's `vars`.
        vars: Vec<usize>,
        /// The conjunction that must have no match: atoms, negated atoms,
        /// comparisons and nested `¬∃`.
        body: Vec<Literal>,
        /// Where it is written (from `¬` or `∃` to the end of the body).
        span: Span,
    },
}

impl Literal {
    /// The atom of a positive literal.
    pub fn positive(&self) -> Option<&Atom> {
        match self {
            Literal::Pos(a) => Some(a),
            _ => None,
        }
    }

    /// Where the literal was written.
    pub fn span(&self) -> Span {
        match self {
            Literal::Pos(a) | Literal::Neg(a) => a.span,
            Literal::Cmp { span, .. } | Literal::NotExists { span, .. } => *span,
        }
    }

    /// Every atom of the literal with whether it is negated, including
    /// the atoms inside a `¬∃` body (read as negated: the literal holds
    /// when they are absent), depth first in written order. For scans
    /// that must see each predicate a query uses (checks, observability).
    pub fn atoms(&self) -> Vec<(&Atom, bool)> {
        let mut out = Vec::new();
        let mut todo = vec![(self, false)];
        while let Some((l, under)) = todo.pop() {
            match l {
                Literal::Pos(a) => out.push((a, under)),
                Literal::Neg(a) => out.push((a, true)),
                Literal::Cmp { .. } => {}
                Literal::NotExists { body, .. } => {
                    todo.extend(body.iter().rev().map(|b| (b, true)));
                }
            }
        }
        out
    }

    /// The variables the literal reads from outside: its arguments, and
    /// for a `¬∃` the variables of its body that are not its own (nor a
    /// nested `¬∃`'s), in written order, possibly repeated.
    pub fn free_vars(&self) -> Vec<usize> {
        fn walk(l: &Literal, local: &mut Vec<usize>, out: &mut Vec<usize>) {
            let mut arg = |a: &Arg, local: &Vec<usize>| {
                if let Arg::Var(v) = a
                    && !local.contains(v)
                {
                    out.push(*v);
                }
            };
            match l {
                Literal::Pos(a) | Literal::Neg(a) => a.args.iter().for_each(|x| arg(x, local)),
                Literal::Cmp { left, right, .. } => {
                    arg(left, local);
                    arg(right, local);
                }
                Literal::NotExists { vars, body, .. } => {
                    let mark = local.len();
                    local.extend(vars.iter().copied());
                    for b in body {
                        walk(b, local, out);
                    }
                    local.truncate(mark);
                }
            }
        }
        let mut out = Vec::new();
        walk(self, &mut Vec::new(), &mut out);
        out
    }

    /// True for a `¬∃` literal.
    pub fn is_not_exists(&self) -> bool {
        matches!(self, Literal::NotExists { .. })
    }
}

/// The variables a literal binds for itself: a `¬∃`'s own variables and
/// those of the `¬∃`s nested in its body (none for other literals).
pub fn local_vars(l: &Literal) -> Vec<usize> {
    let mut out = Vec::new();
    let mut todo = vec![l];
    while let Some(l) = todo.pop() {
        if let Literal::NotExists { vars, body, .. } = l {
            out.extend(vars.iter().copied());
            todo.extend(body.iter());
        }
    }
    out
}

/// A literal written out in the query syntax, each variable as `name`
/// says (its name, or the value an answer gives it): `On(ped_1, y)`,
/// `¬Moving(x)`, `x ≠ y`, `¬∃y: (Road(y) ∧ On(ped_1, y))`.
pub fn literal_text(l: &Literal, name: &dyn Fn(usize) -> String) -> String {
    let arg = |a: &Arg| match a {
        Arg::Var(v) => name(*v),
        Arg::Const(c) => c.clone(),
    };
    let atom = |a: &Atom| {
        let args: Vec<String> = a.args.iter().map(arg).collect();
        format!("{}({})", a.pred, args.join(", "))
    };
    match l {
        Literal::Pos(a) => atom(a),
        Literal::Neg(a) => format!("¬{}", atom(a)),
        Literal::Cmp {
            left,
            right,
            negated,
            ..
        } => format!(
            "{} {} {}",
            arg(left),
            if *negated { "≠" } else { "=" },
            arg(right)
        ),
        Literal::NotExists { vars, body, .. } => {
            let names: Vec<String> = vars.iter().map(|v| name(*v)).collect();
            let parts: Vec<String> = body.iter().map(|b| literal_text(b, name)).collect();
            format!("¬∃{}: ({})", names.join(", "), parts.join(" ∧ "))
        }
    }
}

/// How names are resolved: which bare lower-case names are constants.
///
/// `scope` holds the names a `¬∃` binds while its body is resolved, each
/// with its own slot (searched last first, so an inner `∃` hides an
/// outer name); `not_exists` says whether a `¬∃` is allowed at all
/// (queries) or refused (rule bodies).
pub(crate) struct Resolver<'a> {
    pub bound: Vec<String>,
    pub is_constant: &'a dyn Fn(&str) -> bool,
    pub vars: Vec<String>,
    pub var_spans: Vec<Span>,
    pub scope: Vec<(String, usize)>,
    pub locals: Vec<usize>,
    pub not_exists: bool,
}

impl<'a> Resolver<'a> {
    /// A resolver with no variables yet. `bound`: the names quantifiers
    /// bind; `not_exists`: whether `¬∃` is allowed (queries).
    pub(crate) fn new(
        bound: Vec<String>,
        is_constant: &'a dyn Fn(&str) -> bool,
        not_exists: bool,
    ) -> Resolver<'a> {
        Resolver {
            bound,
            is_constant,
            vars: Vec::new(),
            var_spans: Vec::new(),
            scope: Vec::new(),
            locals: Vec::new(),
            not_exists,
        }
    }

    pub(crate) fn arg(&mut self, t: &TermAst) -> Arg {
        match t {
            TermAst::Quoted(v, _) => Arg::Const(v.clone()),
            TermAst::QVar(n, s) => Arg::Var(self.var(n, *s)),
            TermAst::Name(n, s) => {
                let bound = self.bound.iter().any(|b| b == n);
                let upper = n
                    .chars()
                    .next()
                    .is_some_and(|c| c.is_uppercase() || c.is_ascii_digit());
                if bound || (!upper && !(self.is_constant)(n)) {
                    Arg::Var(self.var(n, *s))
                } else {
                    Arg::Const(n.clone())
                }
            }
        }
    }
    fn var(&mut self, n: &str, s: Span) -> usize {
        if let Some(&(_, i)) = self.scope.iter().rev().find(|(m, _)| m == n) {
            return i;
        }
        // A slot of a `¬∃` that has been left is never reused by name.
        let local = |i: usize| self.locals.contains(&i);
        if let Some(i) = self
            .vars
            .iter()
            .enumerate()
            .position(|(i, v)| v == n && !local(i))
        {
            i
        } else {
            self.vars.push(n.to_string());
            self.var_spans.push(s);
            self.vars.len() - 1
        }
    }
    pub(crate) fn atom(&mut self, a: &AtomAst) -> Atom {
        Atom {
            pred: a.pred.clone(),
            args: a.args.iter().map(|t| self.arg(t)).collect(),
            span: a.span,
            pred_span: a.pred_span,
            arg_spans: a.args.iter().map(TermAst::span).collect(),
        }
    }
}

/// Limit on the number of conjunctions a body may expand to.
pub const MAX_DISJUNCTS: usize = 64;

/// Collects every quantifier-bound name in `f` (LogicPad has no shadowing:
/// one name is one variable per rule).
pub(crate) fn bound_names(f: &Formula, out: &mut Vec<String>) {
    match f {
        Formula::Atom(_) | Formula::Equal { .. } => {}
        Formula::Not(g, _) => bound_names(g, out),
        Formula::And(fs) | Formula::Or(fs) => fs.iter().for_each(|g| bound_names(g, out)),
        Formula::Implies(a, b, _) => {
            bound_names(a, out);
            bound_names(b, out);
        }
        Formula::Quantified { vars, body, .. } => {
            out.extend(vars.iter().map(|(n, _)| n.clone()));
            bound_names(body, out);
        }
    }
}

/// Converts a body formula into disjunctive normal form: a list of
/// conjunctions of literals. Errors name the unsupported construct.
pub(crate) fn to_dnf(f: &Formula, r: &mut Resolver<'_>) -> Result<Vec<Vec<Literal>>, SyntaxError> {
    dnf(f, false, r)
}

/// An atom, a comparison, or a negated atom: one literal in DNF.
fn is_literal(f: &Formula) -> bool {
    match f {
        Formula::Atom(_) | Formula::Equal { .. } => true,
        Formula::Not(g, _) => matches!(**g, Formula::Atom(_) | Formula::Equal { .. }),
        _ => false,
    }
}

fn unsupported(span: Span, message: &str, label: &str) -> SyntaxError {
    SyntaxError {
        span,
        message: message.into(),
        label: label.into(),
    }
}

fn dnf(f: &Formula, neg: bool, r: &mut Resolver<'_>) -> Result<Vec<Vec<Literal>>, SyntaxError> {
    match f {
        Formula::Atom(a) => {
            let atom = r.atom(a);
            Ok(vec![vec![if neg {
                Literal::Neg(atom)
            } else {
                Literal::Pos(atom)
            }]])
        }
        Formula::Equal {
            left,
            right,
            negated,
            span,
        } => {
            let (l, rr) = (r.arg(left), r.arg(right));
            Ok(vec![vec![Literal::Cmp {
                left: l,
                right: rr,
                negated: *negated != neg,
                span: *span,
            }]])
        }
        Formula::Not(g, _) => dnf(g, !neg, r),
        Formula::And(fs) | Formula::Or(fs) => {
            let conj = matches!(f, Formula::And(_)) != neg;
            // Fast path for the common query shape, a conjunction of literals.
            if conj && fs.iter().all(is_literal) {
                let mut lits = Vec::with_capacity(fs.len());
                for g in fs {
                    lits.extend(dnf(g, neg, r)?.into_iter().flatten());
                }
                return Ok(vec![lits]);
            }
            let parts = fs
                .iter()
                .map(|g| dnf(g, neg, r))
                .collect::<Result<Vec<_>, _>>()?;
            if conj {
                let mut acc: Vec<Vec<Literal>> = vec![Vec::new()];
                for p in parts {
                    // One alternative: append it to every alternative so far,
                    // in place (moved when there is one). Building a fresh
                    // product here copied every alternative once per part,
                    // quadratic in the parts: the fuzzer's
                    // `∀x: V(x) → (A ∧ B) ∨ C1 ∨ … ∨ C3800` took minutes.
                    if p.len() == 1 {
                        if let Some(b) = p.into_iter().next() {
                            match acc.as_mut_slice() {
                                [a] => a.extend(b),
                                all => all.iter_mut().for_each(|a| a.extend(b.iter().cloned())),
                            }
                        }
                        continue;
                    }
                    let mut next = Vec::new();
                    for a in &acc {
                        for b in &p {
                            let mut c = a.clone();
                            c.extend(b.iter().cloned());
                            next.push(c);
                        }
                    }
                    if next.len() > MAX_DISJUNCTS {
                        return Err(unsupported(
                            f.span(),
                            "formula expands to too many alternatives",
                            "split this rule into several rules",
                        ));
                    }
                    acc = next;
                }
                Ok(acc)
            } else {
                let out: Vec<_> = parts.into_iter().flatten().collect();
                if out.len() > MAX_DISJUNCTS {
                    return Err(unsupported(
                        f.span(),
                        "formula expands to too many alternatives",
                        "split this rule",
                    ));
                }
                Ok(out)
            }
        }
        Formula::Implies(_, _, span) => Err(unsupported(
            *span,
            "`==>` inside a rule body or query is not supported",
            "only one `==>`, at the top, is allowed",
        )),
        Formula::Quantified {
            quant,
            vars,
            body,
            span,
        } => match (quant, neg) {
            (Quant::Exists, false) => dnf(body, neg, r),
            (Quant::Exists, true) if r.not_exists => not_exists(vars, body, *span, r),
            (Quant::Exists, true) => Err(unsupported(
                *span,
                "a negated `∃` inside a rule body cannot be evaluated",
                "define a helper predicate for this part and negate that",
            )),
            _ => Err(unsupported(
                *span,
                "a universal quantifier inside a body cannot be evaluated",
                "define a helper predicate for this part and negate that",
            )),
        },
    }
}

/// `¬∃vars: body` as literals of one conjunction: the body in DNF with the
/// names `vars` bound to slots of their own while it is resolved, one
/// [`Literal::NotExists`] per alternative (`¬∃y: (A ∨ B)` is `¬∃y: A ∧
/// ¬∃y: B`).
fn not_exists(
    vars: &[(String, Span)],
    body: &Formula,
    span: Span,
    r: &mut Resolver<'_>,
) -> Result<Vec<Vec<Literal>>, SyntaxError> {
    let mark = r.scope.len();
    let mut slots = Vec::with_capacity(vars.len());
    for (name, at) in vars {
        let slot = r.vars.len();
        r.vars.push(name.clone());
        r.var_spans.push(*at);
        r.locals.push(slot);
        r.scope.push((name.clone(), slot));
        slots.push(slot);
    }
    let alts = dnf(body, false, r);
    r.scope.truncate(mark);
    let lits = alts?
        .into_iter()
        .map(|alt| Literal::NotExists {
            vars: slots.clone(),
            body: alt,
            span,
        })
        .collect();
    Ok(vec![lits])
}

impl fmt::Display for Arg {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Arg::Var(i) => write!(f, "_{i}"),
            Arg::Const(c) => write!(f, "{c}"),
        }
    }
}

#[cfg(test)]
mod tests {
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
        let Formula::And(parts) = parses("ColorOf(x) = White ∧ TypeOf(x) ≠ Car ∧ x != y")
        else {
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
}
