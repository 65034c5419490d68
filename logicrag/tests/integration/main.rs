//! logicrag's integration tests, in one test binary with a module per area
//! (as ripgrep does): each file under `tests/` used to be its own binary
//! linking all of logicrag's dependencies (axum, reqwest, rustls, plotters,
//! ort …), tens of megabytes and seconds of linking each.
//!
//! Run one area with a filter on its module path, e.g.
//! `cargo test -p logicrag --test integration serve::`.
//!
//! The modules run on parallel threads of one process: a test must not
//! change process-wide state (environment variables, the working
//! directory, a panic hook, a global runtime). A test that needs to belongs
//! in a file of its own directly under `tests/`, a binary of its own, with
//! a comment at its top saying why.

mod common;

mod av2;
mod browser;
mod cli;
mod everyday;
mod hostile;
mod llm;
mod llm_real;
mod plot;
mod scoped;
mod serve;
mod serve_hardened;
mod temporal;
mod translate_cases;
mod translate_fresh;
mod translate_gold;
mod vocabulary;
