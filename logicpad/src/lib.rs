//! # logicpad — the expert rule language of logicrag
//!
//! A LogicPad is a YAML file that declares the fact vocabulary (atomic
//! predicates grouped by the perception source that produces them, and
//! functions such as `ColorOf(x, color)` with their value lists) and the rules
//! that derive new predicates (`∀x : Vehicles(x) ∧ ¬Moving(x) ==> Stopped(x)`).
//!
//! Main types:
//! - [`LogicPad`]: a loaded, checked file — [`LogicPad::load`],
//!   [`LogicPad::parse`], [`LogicPad::builtin`] (the project's default,
//!   `logicpad/LogicPad.yaml`). A rule with an error is reported and left out.
//! - [`Schema`]: predicate → arity, kind ([`PredKind`]), producer group,
//!   declared values, English phrases, and the [`Role`] (with [`Frames`])
//!   each plays in questions when the file declares it.
//! - [`Diagnostic`]: a finding with file, line, column and a caret, rendered
//!   by miette; [`lint`] / [`LintReport`] print them all.
//! - [`Program`]: the checked rules compiled and stratified into
//!   [`Component`]s; [`Program::evaluate`] runs a bottom-up, semi-naive
//!   evaluator over a [`FactBase`] of `kanren::Relation`s and returns a
//!   [`Model`].
//! - [`Model`]: base plus derived relations, one justification per derived
//!   fact ([`Model::explain`] → [`DerivationTree`]: `Base`, `Derived`,
//!   `Absent`, and `Truncated` where a proof is cut by its [`ProofLimits`] —
//!   by default 64 rule steps deep, 10 000 nodes; [`Model::explain_with`]
//!   takes others), integrity-constraint
//!   [`Violation`]s, and [`Model::ask`], which answers a [`QueryAst`]
//!   (from [`parse_query`], checked by [`check_query`]) through kanren goals
//!   with proofs; [`Model::bindings`] / [`Model::count`] give the same
//!   answers through the evaluator's own joins, faster, without proofs.
//! - [`ParsedQuery`] (from [`parse_any_query`], checked by
//!   [`check_any_query`]): an existential query — whose conjunctions may
//!   hold scoped negation `¬∃y: (…)` ([`fol::Literal::NotExists`], run as
//!   kanren's `naf` of the body's join, proved by a
//!   [`DerivationTree::NoMatch`] node) — a universal [`UniversalQuery`],
//!   or a counting [`CountQuery`] (`#{x: Q} >= N`).
//!
//! ```
//! use logicpad::{FactBase, LogicPad, RunConfig, parse_query};
//! let pad = LogicPad::builtin();
//! let mut facts = FactBase::new();
//! facts.add("Vehicles", &["car_1"]).unwrap();
//! facts.add("TypeOf", &["car_1", "Car"]).unwrap();
//! let model = pad.program().evaluate(facts).unwrap();
//! let q = parse_query("TypeOf(x) = Car ∧ ConstantSpeed(x)").unwrap();
//! let answers = model.ask(&q, RunConfig { proofs: true, ..RunConfig::default() }).unwrap();
//! assert_eq!(answers[0].bindings, vec![("x".to_string(), "car_1".to_string())]);
//! // One tree per literal: TypeOf(car_1, Car) [fact]; ConstantSpeed(car_1) [rule …]
//! // over Vehicles(car_1) [fact], ¬SpeedUp(car_1) [absent], ¬SpeedDown(car_1) [absent].
//! assert_eq!(answers[0].proof.len(), 2);
//! for tree in &answers[0].proof {
//!     println!("{tree}");
//! }
//! ```
//!
//! The language and its semantics are documented in `docs/logicpad.md`.
#![forbid(unsafe_code)]
#![warn(missing_docs, unreachable_pub)]

pub mod diag;
pub mod facts_text;
pub mod fol;
mod pad;
pub mod program;
pub mod schema;
mod yaml;

pub use diag::{DiagKind, Diagnostic, Label, Severity, SourceFile, Span};
pub use pad::{BUILTIN_SOURCE, LoadError, LogicPad};
pub use program::{CArg, CAtom, Component, PredId, Program, Rule, RuleId, RuleSource};
pub use schema::{Frames, PredInfo, PredKind, Role, Schema};
mod lint;
pub use lint::{LintReport, lint, lint_source, lint_with};
mod eval;
pub use eval::{
    CutReason, DerivationTree, EvalStats, FactBase, FactError, GroundAtom, Model, ProofLimits,
    Violation, const_term,
};
mod query;
pub use kanren::{Budget, RunConfig};
pub use query::{
    Answers, AskError, COUNT_FACTOR, CountOp, CountQuery, DEFAULT_MAX_ANSWERS, Found, Limits,
    LiteralSpec, ParsedQuery, QueryAnswer, QueryAst, Stopped, UniversalQuery, check_any_query,
    check_query, is_variable_name, parse_any_query, parse_query,
};
