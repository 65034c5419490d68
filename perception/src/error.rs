//! The crate's one error type.

use std::path::PathBuf;

/// Everything that can go wrong in perception. Every variant names the input
/// it came from so a user can find and fix it.
#[derive(Debug, thiserror::Error)]
pub enum PerceptionError {
    /// Occurs when a file or directory cannot be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file or directory involved.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// Occurs when a line of a text input (KITTI label or calib file) does not
    /// have the expected shape.
    #[error("{path}:{line}: {message}")]
    Parse {
        /// The file being parsed.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What was expected and what was found.
        message: String,
    },
    /// Occurs when a file parses line by line but is inconsistent as a whole
    /// (a missing `P2:` line, a track twice in one frame, labels outside
    /// the image).
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: PathBuf,
        /// What is inconsistent, naming frames and tracks where it can.
        message: String,
    },
    /// Occurs when a JSON document (track file, fact config) does not match
    /// its documented schema.
    #[error("{origin}: {message}")]
    Json {
        /// File path or other description of where the JSON came from.
        origin: String,
        /// The serde error, with line and column.
        message: String,
    },
    /// Occurs when a YAML scenario or config does not match its schema.
    #[error("{origin}: {message}")]
    Yaml {
        /// File path or scenario name.
        origin: String,
        /// The serde-saphyr error, with line and column.
        message: String,
    },
    /// Occurs when a sequence breaks a documented invariant (unsorted or
    /// duplicate observations, frame out of range, non-finite numbers,
    /// inverted boxes).
    #[error("sequence {sequence}: {message}")]
    InvalidSequence {
        /// The sequence name.
        sequence: String,
        /// Which invariant was broken and where.
        message: String,
    },
    /// Occurs when a window specification or frame range is unusable
    /// (zero size or stride, range outside the sequence).
    #[error("invalid window: {0}")]
    InvalidWindow(String),
    /// Occurs when a configuration value is out of its documented range.
    #[error("invalid configuration field `{field}`: {message}")]
    InvalidConfig {
        /// The configuration field name.
        field: String,
        /// Why the value is rejected.
        message: String,
    },
    /// Occurs when a source specification (`kitti:DIR`, `sim:NAME`,
    /// `json:FILE`) cannot be understood or names something that is absent.
    #[error("source `{spec}`: {message}")]
    Source {
        /// The specification as given.
        spec: String,
        /// What was expected.
        message: String,
    },
    /// Occurs when a simulator scenario is inconsistent (unknown object
    /// referenced by an event, non-positive durations, bad speeds).
    #[error("scenario `{scenario}`: {message}")]
    Scenario {
        /// The scenario name.
        scenario: String,
        /// What is wrong.
        message: String,
    },
    /// Occurs when a perception back-end (for example the raw-frames
    /// detector and tracker) fails; the back-end's own error is kept.
    #[error("{stage}: {source}")]
    Backend {
        /// The pipeline stage that failed.
        stage: String,
        /// The back-end's error.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

impl PerceptionError {
    /// Builds an [`PerceptionError::Io`] for `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        PerceptionError::Io {
            path: path.into(),
            source,
        }
    }

    /// Builds an [`PerceptionError::InvalidSequence`].
    pub fn invalid_sequence(sequence: &str, message: impl Into<String>) -> Self {
        PerceptionError::InvalidSequence {
            sequence: sequence.to_string(),
            message: message.into(),
        }
    }
}

/// A `serde_saphyr` error as this crate reports it: the caller already
/// prefixes the file name, so the parser's own leading `error: ` goes, and
/// its snippet header names the file instead of `<input>`.
pub(crate) fn yaml_message(err: &impl std::fmt::Display, origin: &str) -> String {
    let text = err.to_string();
    let text = text.strip_prefix("error: ").unwrap_or(&text);
    text.replace("--> <input>:", &format!("--> {origin}:"))
}

#[cfg(test)]
mod yaml_message_tests {
    #[test]
    fn names_the_file_once_and_says_error_once() {
        let err = serde_saphyr::from_str::<std::collections::BTreeMap<String, u32>>("a: [")
            .expect_err("not YAML");
        let m = super::yaml_message(&err, "cfg.yaml");
        assert!(!m.starts_with("error:"), "{m}");
        assert!(!m.contains("<input>"), "{m}");
        // The snippet header names the file the caller's prefix names.
        assert!(m.contains("--> cfg.yaml:"), "{m}");
    }
}
