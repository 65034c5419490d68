//! kanren — a fast, fair miniKanren for Rust.
//!
//! The main types:
//! - [`Term`]: a logic term — [`Var`] (a `u32` index), interned [`Sym`],
//!   `Int`, `Str`, lists (`Nil`/`Cons`, packed: a list's cells share one
//!   allocation) and compound terms (`App`). Cheap to clone; compound parts
//!   are `Arc`-shared.
//! - [`Goal`]: a relation applied to terms, built from [`eq`], [`neq`],
//!   [`conj`]/[`all`], [`disj`]/[`conde`], [`fresh`], [`conda`], [`condu`],
//!   [`onceo`], [`symbolo`], [`numbero`], [`absento`], [`project`], [`naf`],
//!   [`label`], [`fact`] and [`Tabled`] relations. Recursive relations are
//!   plain Rust functions returning goals.
//! - [`Query`] / [`Run`]: a goal over named variables, run lazily as an
//!   iterator of [`Answer`]s (reified values with `_0, _1` for unbound parts,
//!   residual constraints, optional [`Proof`]), within a [`Budget`], ending
//!   with a [`StopReason`]. `Run` is `Send`.
//! - [`Relation`]: a table of ground facts, dictionary-encoded, with an index
//!   per argument;
//!   [`fact`] queries it through the most selective bound argument.
//!
//! ```
//! use kanren::*;
//!
//! fn appendo(l: Term, s: Term, out: Term) -> Goal {
//!     conde([
//!         vec![eq(l.clone(), Term::Nil), eq(s.clone(), out.clone())],
//!         vec![fresh(move |[a, d, res]| {
//!             conj([
//!                 eq(l.clone(), Term::cons(a.clone(), d.clone())),
//!                 eq(out.clone(), Term::cons(a, res.clone())),
//!                 appendo(d, s.clone(), res),
//!             ])
//!         })],
//!     ])
//! }
//!
//! let mut q = Query::new();
//! let (x, y) = (q.var("x"), q.var("y"));
//! let answers: Vec<Answer> = q
//!     .run(appendo(x, y, Term::list([1i64, 2])), RunConfig::default())
//!     .collect::<Result<_, _>>()
//!     .unwrap();
//! assert_eq!(answers.len(), 3);
//! assert_eq!(answers[0].to_string(), "[], [1, 2]");
//! ```
//!
//! The search has µKanren's semantics — lazy, and fair between branches —
//! implemented as a queue of tasks that each run depth first for a bounded
//! turn, so every step is counted and costs what its goals cost. Variables
//! are `u32` indexes into a persistent radix-trie substitution; unification
//! commits nothing until it succeeds; constraints are re-checked only when
//! their variables are bound. [`classic`] has the textbook relations
//! (`appendo`, `membero`, `rembero`, `pluso`, the zebra puzzle). See
//! `docs/kanren.md` for the design, why it is fast, and measurements.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod classic;
mod ctx;
mod engine;
pub mod error;
pub mod facts;
pub mod goal;
pub mod join;
mod list;
pub mod proof;
pub mod run;
mod state;
pub mod subst;
pub mod tabling;
pub mod term;
mod vmap;

pub use error::{KanrenError, RunError};
pub use facts::{FactId, Probe, Relation, Tuple, TupleIter, fact, same_term};
pub use goal::{
    Goal, absento, all, conda, conde, condu, conj, delay, disj, eq, fail, fresh, label, naf, neq,
    numbero, onceo, project, project_result, stringo, succeed, symbolo,
};
pub use join::join;
pub use proof::{Proof, ProofStep};
pub use run::{Answer, Budget, Query, Run, RunConfig, StopReason};
pub use subst::{Subst, unify};
pub use tabling::{Tabled, tabled};
pub use term::{Sym, Term, Var, sym};
