//! The formula as written ([`Formula`], [`AtomAst`], [`TermAst`]) and the
//! recursive-descent parser that builds it ([`parse_formula`]).

use super::lex::{SyntaxError, Tok, lex};
use crate::diag::Span;

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
