//! Argoverse 2 sensor logs (`av2:DIR`). TEMPORARY placeholder: the reader
//! lands with issue 32.

use std::path::Path;

use crate::error::PerceptionError;
use crate::model::Sequence;

/// The log's name (its directory name).
pub fn log_name(dir: &Path) -> Result<String, PerceptionError> {
    dir.file_name()
        .and_then(|n| n.to_str())
        .map(str::to_string)
        .ok_or_else(|| PerceptionError::Source {
            spec: format!("av2:{}", dir.display()),
            message: "expected a log directory".into(),
        })
}

/// Loads a log.
pub fn load(dir: &Path) -> Result<Sequence, PerceptionError> {
    Err(PerceptionError::Source {
        spec: format!("av2:{}", dir.display()),
        message: "the Argoverse 2 reader is not built yet".into(),
    })
}
