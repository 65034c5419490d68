//! Shared helpers for the cross-crate integration tests (see `integration/`).
#![forbid(unsafe_code)]

use std::path::PathBuf;

/// The read-only shared data folder (`../shared` from the workspace root), if present.
pub fn shared_dir() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared");
    dir.is_dir().then_some(dir)
}
