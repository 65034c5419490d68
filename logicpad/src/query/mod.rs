//! Queries: the same FOL grammar as rule bodies, compiled to a kanren
//! program and answered by kanren's lazy search over a [`Model`](crate::Model)'s
//! relations, so derived predicates are queried exactly like base facts.

mod answers;
mod ask;
mod ast;
mod check;
mod compile;
mod limits;
mod parse;

pub use answers::Answers;
pub use ast::{
    AskError, CountOp, CountQuery, LiteralSpec, ParsedQuery, QueryAnswer, QueryAst, UniversalQuery,
    is_variable_name,
};
pub use check::{check_any_query, check_query};
pub use limits::{COUNT_FACTOR, DEFAULT_MAX_ANSWERS, Found, Limits, Stopped};
pub use parse::{parse_any_query, parse_query};
