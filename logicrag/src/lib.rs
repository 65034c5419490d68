//! logicrag library (overview written with the crate).
#![forbid(unsafe_code)]

pub mod translate;
