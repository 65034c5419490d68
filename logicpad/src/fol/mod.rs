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

mod dnf;
mod lex;
mod literal;
mod parse;
#[cfg(test)]
mod tests;

pub use dnf::MAX_DISJUNCTS;
pub(crate) use dnf::{Resolver, bound_names, to_dnf};
pub use lex::SyntaxError;
pub use literal::{Arg, Atom, Literal, literal_text, local_vars};
pub use parse::{AtomAst, Formula, Quant, TermAst, parse_formula};
