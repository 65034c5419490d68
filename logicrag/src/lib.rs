//! logicrag library (overview written with the crate).
#![forbid(unsafe_code)]

pub mod facts_text;
pub mod metrics;
pub mod translate;
