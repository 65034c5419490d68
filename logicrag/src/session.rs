//! What every front end says the same way: what the command line's source
//! flags mean ([`SourceOptions`]), the answer flags ([`ask_options`]), and
//! the errors and messages of opening and asking ([`SessionError`],
//! [`message`]); [`crate::pipeline::Pipeline::open`] opens a source with
//! them.
//!
//! Why here and not in the binary: the Python package (`logicrag-py`)
//! must give the same answers, the same JSON and the same error messages
//! as the CLI; with one implementation in the library neither can drift.

use crate::ask::AskOptions;
use crate::engine::{EngineError, PrepareError};
use crate::kb::KbError;
use crate::source::{LoadOptions, SourceError, SourceSpec};
use logicpad::LogicPad;
/// The simulator's noise levels (`--noise`: a preset, or one with its
/// sigmas scaled as `high*2`), for front ends that read one.
pub use perception::sim::{NoiseLevel, NoisePreset};
use perception::{FactConfig, PerceptionError, WindowSpec};
use std::path::{Path, PathBuf};

/// Errors of opening a source and asking it, each worded as the command
/// line reports it (the CLI prints `error: ` and this message).
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    /// Occurs when the source string is not understood, or the source
    /// cannot be loaded (a missing file, a malformed label file).
    #[error(transparent)]
    Source(#[from] SourceError),
    /// Occurs when the `--config` file or the `--frames` range is not valid.
    #[error(transparent)]
    Perception(#[from] PerceptionError),
    /// Occurs when a source option is out of range or does not apply to
    /// the source's kind (`--window 0`, `--frames` on a `facts:` source).
    #[error("{0}")]
    Option(String),
    /// Occurs when the LogicPad file cannot be read or is not YAML.
    #[error(transparent)]
    LogicPad(#[from] logicpad::LoadError),
    /// Occurs when the LogicPad's vocabulary cannot drive the translator.
    #[error(transparent)]
    Engine(#[from] EngineError),
    /// Occurs when a window id is not one of the source's: every front
    /// end says it in these words.
    #[error(transparent)]
    UnknownWindow(#[from] crate::kb::NoWindow),
    /// Occurs when the translator cannot turn an English question into a
    /// query (the grammar cannot read it, or the LLM fails).
    #[error(transparent)]
    Prepare(#[from] PrepareError),
    /// Occurs when a window's facts cannot be stored in its KB.
    #[error(transparent)]
    Kb(#[from] KbError),
    /// Occurs when an answer cannot be rendered as JSON.
    #[error("rendering JSON: {0}")]
    Json(#[from] serde_json::Error),
}

impl SessionError {
    /// True when the error comes from reading a file (the OS said no):
    /// the Python package raises `OSError` for these, `ValueError` for
    /// the rest.
    pub fn is_io(&self) -> bool {
        io_cause(self)
    }
}

/// True when `e` or one of its causes is an I/O error.
pub(crate) fn io_cause(e: &(dyn std::error::Error + 'static)) -> bool {
    let mut next = Some(e);
    while let Some(err) = next {
        if err.is::<std::io::Error>() {
            return true;
        }
        next = err.source();
    }
    false
}

/// An error and its causes on one line, each cause once: our errors
/// already end their message with their cause (`{path}: {source}`), so
/// printing every cause again would say "No such file … : No such file …".
/// The CLI prints this after `error: `; the Python package raises it.
pub fn message(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut next = e.source();
    while let Some(cause) = next {
        let c = cause.to_string();
        // Only a whole trailing cause (`…: cause`) counts as already said.
        if text != c && !text.ends_with(&format!(": {c}")) {
            text.push_str(": ");
            text.push_str(&c);
        }
        next = cause.source();
    }
    text
}

/// A source's options, as the command line's flags give them (`--sequence`,
/// `--window`, …); `None` is a flag not given.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SourceOptions {
    /// KITTI (or multi-sequence JSON) sequence, e.g. `0000`.
    pub sequence: Option<String>,
    /// Frames per window (default: 10, the paper's).
    pub window: Option<u32>,
    /// Frames between window starts (default: the window size).
    pub stride: Option<u32>,
    /// One inclusive frame range instead of sliding windows, e.g. `0-9`.
    pub frames: Option<String>,
    /// Perception thresholds (YAML or JSON `FactConfig`).
    pub config: Option<PathBuf>,
    /// Model set YAML for `frames:DIR` sources.
    pub models: Option<PathBuf>,
    /// Camera calibration for `frames:DIR` sources.
    pub camera: Option<PathBuf>,
    /// Frame rate of `frames:DIR` frames, per second.
    pub fps: Option<f64>,
    /// Simulator noise level replacing a `sim:` scenario's own (`--noise`).
    pub noise: Option<NoiseLevel>,
}

impl SourceOptions {
    /// The source with the options of its kind; an option its kind would
    /// ignore is an error naming the flag, never silently dropped.
    pub fn spec(&self, source: SourceSpec) -> Result<SourceSpec, SessionError> {
        if let Some(level) = self.noise
            && !matches!(source, SourceSpec::Sim { .. })
        {
            return Err(SessionError::Option(format!(
                "--noise {level} applies to simulator sources (sim:SCENARIO[@SEED]), not {source}"
            )));
        }
        let spec = source
            .with_sequence(self.sequence.clone())?
            .with_frames_options(self.models.clone(), self.camera.clone(), self.fps)?;
        // A facts source's windows are its files: frame ranges and window
        // sizes have nothing to cut.
        if matches!(spec, SourceSpec::Facts { .. }) {
            for (flag, given) in [
                ("--frames", self.frames.is_some()),
                ("--window", self.window.is_some()),
                ("--stride", self.stride.is_some()),
                ("--config", self.config.is_some()),
            ] {
                if given {
                    return Err(SessionError::Option(format!(
                        "{flag} does not apply to facts:PATH sources (each file is one window)"
                    )));
                }
            }
        }
        Ok(spec)
    }

    /// How the source's frames are cut into windows, and the thresholds.
    pub(crate) fn load_options(&self) -> Result<LoadOptions, SessionError> {
        // The CLI's parser refuses the pair before this; other callers
        // (Python keywords) reach it.
        if self.frames.is_some() && (self.window.is_some() || self.stride.is_some()) {
            return Err(SessionError::Option(
                "--frames (one range) does not combine with --window or --stride (sliding windows)"
                    .into(),
            ));
        }
        let config = match &self.config {
            None => FactConfig::default(),
            Some(p) => FactConfig::load(p)?,
        };
        let frames = match &self.frames {
            Some(f) => Some(perception::source::parse_frame_range(f)?),
            None => None,
        };
        let size = self.window.unwrap_or(WindowSpec::PAPER.size);
        if size == 0 {
            return Err(SessionError::Option(
                "--window must be at least 1 frame".into(),
            ));
        }
        let stride = self.stride.unwrap_or(size);
        if stride == 0 {
            return Err(SessionError::Option(
                "--stride must be at least 1 frame".into(),
            ));
        }
        Ok(LoadOptions {
            windows: WindowSpec { size, stride },
            frames,
            config,
            noise: self.noise,
        })
    }
}

/// What to tell the user about a loaded source's accuracy: a `frames:`
/// source without `--camera` has only roughly metric 3D positions.
pub(crate) fn camera_note(spec: &SourceSpec) -> Option<String> {
    matches!(spec, SourceSpec::Frames { camera: None, .. }).then(|| {
        format!(
            "no --camera calibration; assumed fx = fy = image width, principal point \
             at the centre and a camera {} m above the road, so 3D positions are only roughly metric",
            perception::raw::frames::DEFAULT_CAMERA_HEIGHT_M
        )
    })
}

/// The warning for a LogicPad read from `path` some of whose rules had to
/// be left out, or `None` when every rule loaded.
pub(crate) fn pad_warning(pad: &LogicPad, path: &Path) -> Option<String> {
    let errors = pad.diagnostics().iter().filter(|d| d.is_error()).count();
    (errors > 0).then(|| {
        format!(
            "{} has {errors} error(s); the rules concerned are left out (see `logicrag lint {}`)",
            path.display(),
            path.display()
        )
    })
}

/// The answer options of `ask`'s flags: `base` (all, bindings only, or
/// counts) with `--max-answers` (at least 1) and `--proof-depth` (capped
/// at [`logicpad::ProofLimits::MAX_DEPTH_CEILING`]).
pub fn ask_options(
    base: AskOptions,
    max_answers: usize,
    proof_depth: usize,
) -> Result<AskOptions, SessionError> {
    if max_answers == 0 {
        return Err(SessionError::Option(
            "--max-answers must be at least 1".into(),
        ));
    }
    Ok(AskOptions {
        limits: logicpad::Limits {
            answers: max_answers,
            proof_depth: proof_depth.min(logicpad::ProofLimits::MAX_DEPTH_CEILING),
            ..base.limits
        },
        ..base
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_another_kind_would_ignore_are_refused_with_the_flag() {
        let facts: SourceSpec = "facts:/nowhere".parse().expect("spec");
        let framed = SourceOptions {
            frames: Some("0-9".into()),
            ..SourceOptions::default()
        };
        let err = framed.spec(facts).expect_err("refused");
        assert_eq!(
            err.to_string(),
            "--frames does not apply to facts:PATH sources (each file is one window)"
        );
        let sim: SourceSpec = "sim:braking".parse().expect("spec");
        let seq = SourceOptions {
            sequence: Some("0000".into()),
            ..SourceOptions::default()
        };
        assert!(
            seq.spec(sim)
                .expect_err("refused")
                .to_string()
                .contains("--sequence")
        );
        for (opts, says) in [
            (
                SourceOptions {
                    window: Some(0),
                    ..SourceOptions::default()
                },
                "--window must be at least 1 frame",
            ),
            (
                SourceOptions {
                    stride: Some(0),
                    ..SourceOptions::default()
                },
                "--stride must be at least 1 frame",
            ),
            (
                SourceOptions {
                    frames: Some("0-9".into()),
                    window: Some(5),
                    ..SourceOptions::default()
                },
                "--frames (one range) does not combine",
            ),
        ] {
            let err = opts.load_options().expect_err("refused");
            assert!(err.to_string().starts_with(says), "{err}");
        }
        assert!(ask_options(AskOptions::default(), 0, 3).is_err());
        let capped = ask_options(AskOptions::BINDINGS, 7, usize::MAX).expect("fine");
        assert_eq!(capped.limits.answers, 7);
        assert!(!capped.proofs);
        assert_eq!(
            capped.limits.proof_depth,
            logicpad::ProofLimits::MAX_DEPTH_CEILING
        );
    }

    #[test]
    fn a_missing_file_is_an_io_error_said_once() {
        let options = crate::pipeline::OpenOptions {
            logicpad: crate::pipeline::PadChoice::File("/nonexistent/pad.yaml".into()),
            ..Default::default()
        };
        let err = crate::pipeline::Pipeline::sourceless(&options).expect_err("missing");
        assert!(err.is_io());
        let text = message(&err);
        assert!(
            text.starts_with("cannot read LogicPad file `/nonexistent/pad.yaml`: "),
            "{text}"
        );
        assert_eq!(text.matches("No such file").count(), 1, "{text}");
        let bad: Result<SourceSpec, _> = "nope:x".parse();
        let err = SessionError::from(bad.expect_err("unknown kind"));
        assert!(!err.is_io());
        assert!(message(&err).contains("unknown source kind `nope`"));
    }
}
