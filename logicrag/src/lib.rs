//! # logicrag — ask questions about driving video, get proved answers
//!
//! Data flows one way: a source (simulator, KITTI labels, JSON tracks, raw
//! frames, or a text KB) becomes window facts with provenance; each window's
//! facts plus the LogicPad rules become a [`kb::WindowKb`]; a question is
//! translated ([`engine::Translate`]: the grammar, an LLM, or the grammar
//! then the LLM) into a query; [`ask::ask`] answers it with one of four
//! [`ask::Outcome`]s and a proof per binding; [`context`] renders that as
//! retrieval context for a multimodal model. [`pipeline::Pipeline`] is that
//! whole path in one value, and every front end goes through it.
//!
//! Main types:
//! - [`pipeline::Pipeline`]: a source's windows, their KBs (reasoned once),
//!   the engine for the source and the translator; prepares questions and
//!   answers them (ask, context, retrieve) on one window or all, with one
//!   error for an unknown window. The CLI (`ask`, `context`, `demo`,
//!   `eval`), batches, the LMM evaluation, the REPL, `serve` and the Python
//!   package all ask through it.
//! - [`source::Loaded`]: a source's windows and what it can observe.
//! - [`kb::WindowKb`]: one window's facts, provenance and reasoned model.
//! - [`kb::Observability`]: which predicates a source cannot see, so that
//!   "no" is never said where the truth is unknowable.
//! - [`ask::AskResult`]: outcome, bindings, proofs, why-not, reasons, and
//!   how sure the answer is ([`belief`]: from the probabilities perception
//!   gives its facts and doubts; docs/probability.md).
//! - [`metrics::Evaluation`]: accuracy, balanced accuracy, F1 per category.
//! - [`temporal`]: `(Q1) THEN (Q2)`, `EVER: Q`, `THROUGHOUT: Q`,
//!   `STILL: Q` — claims about a video's windows over time, answered once
//!   per video with the frames where each part holds.
//! - [`session`]: what the command line's source flags mean, and the
//!   errors and messages of opening and asking, shared with Python.
//! - `arrow` (feature `arrow`): facts and answers as Arrow tables and
//!   Parquet files, one schema (docs/formats.md).
#![forbid(unsafe_code)]
#![warn(missing_docs, unreachable_pub)]

#[cfg(feature = "arrow")]
pub mod arrow;
pub mod ask;
pub mod batch;
pub mod belief;
pub mod compose;
pub mod context;
pub mod engine;
pub mod eval;
pub mod facts_text;
pub mod images;
pub mod json;
pub mod kb;
pub mod llm;
pub mod metrics;
pub mod pipeline;
#[cfg(feature = "plot")]
pub mod plot;
pub mod proof;
pub mod questions;
pub mod render;
pub mod repl;
pub mod scene;
#[cfg(feature = "serve")]
pub mod serve;
pub mod session;
pub mod source;
pub mod temporal;
pub mod translate;
pub mod whynot;
