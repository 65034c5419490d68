//! logicrag library.
#![forbid(unsafe_code)]
