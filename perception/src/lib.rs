//! perception (overview to be written with the crate).
#![forbid(unsafe_code)]
