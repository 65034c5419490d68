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
//! - [`pipeline::Pipeline`], opened by [`pipeline::Pipeline::open`] with
//!   [`pipeline::OpenOptions`] (the source's options, the LogicPad, the
//!   translator): the one front door. It holds a source's windows, their
//!   KBs (reasoned once), the engine for the source and the translator;
//!   prepares questions and answers them (ask, pages, context) on one
//!   window or all, with one error for an unknown window. Every front end
//!   — each CLI subcommand, batches, the LMM evaluation, the REPL,
//!   `serve`, the Python package — opens one and only renders.
//! - [`ask::AskResult`]: outcome, bindings, proofs, why-not, reasons,
//!   how sure the answer is ([`belief`]: from the probabilities perception
//!   gives its facts and doubts; docs/probability.md), and the limit its
//!   run stopped at, if any ([`ask::AskOptions::limits`]: one
//!   `logicpad::Limits` for every run behind an answer).
//! - [`kb::WindowKb`]: one window's facts, provenance and reasoned model.
//! - [`kb::Observability`]: which predicates a source cannot see, so that
//!   "no" is never said where the truth is unknowable.
//! - [`metrics::Evaluation`]: accuracy, balanced accuracy, F1 per category.
//! - [`temporal`]: `(Q1) THEN (Q2)`, `EVER: Q`, `THROUGHOUT: Q`,
//!   `STILL: Q` — claims about a video's windows over time, answered once
//!   per video with the frames where each part holds.
//! - [`session`]: what the command line's source flags mean, and the
//!   errors and messages of opening and asking, shared with Python.
//! - The edges, which render what the core answers: [`json`] (the objects
//!   `ask --json` prints), [`render`] (terminal text), `arrow` (feature
//!   `arrow`: facts and answers as Arrow tables and Parquet files, one
//!   schema, docs/formats.md), [`scene`], `plot`, [`repl`], `serve`. The
//!   core never imports them (docs/architecture.md, checked by a test).
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
