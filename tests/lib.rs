//! Shared helpers for the cross-crate integration tests (see `integration/`).
#![forbid(unsafe_code)]

use std::path::PathBuf;

/// The read-only shared data folder (`../shared` from the workspace root), if present.
pub fn shared_dir() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared");
    dir.is_dir().then_some(dir)
}

/// A test whose input (../shared data, python3) is absent fails, naming
/// what is missing: CI provides all of them, and a silently skipped test
/// passes without checking anything. `LOGICRAG_SKIP_MISSING=1` skips such
/// tests on a machine that lacks them, saying so.
pub fn missing_input(what: &str) {
    if std::env::var_os("LOGICRAG_SKIP_MISSING").is_none() {
        panic!("{what} (set LOGICRAG_SKIP_MISSING=1 to skip tests whose inputs are absent)");
    }
    eprintln!("SKIPPED (LOGICRAG_SKIP_MISSING): {what}");
}
