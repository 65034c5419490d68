//! The raw-frames error type. Every variant names the file, model or output it
//! came from, and the runtime variants say how to fix the installation.

use std::path::PathBuf;

/// The command that installs the ONNX Runtime library this crate loads.
pub const INSTALL_HINT: &str = "install it with `python3 -m pip install onnxruntime==1.31.1` \
(the library is onnxruntime/capi/libonnxruntime.so.1.31.1 inside the wheel) \
or point ORT_DYLIB_PATH at a libonnxruntime shared library";

/// Everything that can go wrong between a frame on disk and a tracked,
/// 3D-lifted observation.
#[derive(Debug, thiserror::Error)]
pub enum RawError {
    /// Occurs when no ONNX Runtime shared library can be found: neither
    /// `ORT_DYLIB_PATH` nor a `python3` with the `onnxruntime` package gives one.
    #[error("ONNX Runtime library not found ({searched}); {hint}", hint = INSTALL_HINT)]
    RuntimeNotFound {
        /// Where we looked and what each place said.
        searched: String,
    },
    /// Occurs when the library file exists but cannot be loaded (not a shared
    /// library, wrong architecture, too old a version).
    #[error("cannot load ONNX Runtime from {path}: {message}; {hint}", hint = INSTALL_HINT)]
    RuntimeLoad {
        /// The library file.
        path: PathBuf,
        /// The loader's message.
        message: String,
    },
    /// Occurs when a second, different library is requested after one was
    /// loaded: the runtime is process-global and cannot be swapped.
    #[error(
        "ONNX Runtime already loaded from {loaded}; cannot also load {requested} in the same process"
    )]
    RuntimeConflict {
        /// The library in use.
        loaded: PathBuf,
        /// The library asked for.
        requested: PathBuf,
    },
    /// Occurs when ONNX Runtime itself reports an error (session creation,
    /// invalid model file, inference failure).
    #[error("{context}: {message}")]
    Ort {
        /// What we were doing, naming the model.
        context: String,
        /// ONNX Runtime's message.
        message: String,
    },
    /// Occurs when the model file named by a config (or `--model`) is
    /// absent, or is not a regular file (a directory, FIFO or device).
    #[error("model file {path} {}{}", if path.exists() { "is not a regular file" } else { "not found" }, config.as_ref().map(|c| format!(" (named by {})", c.display())).unwrap_or_default())]
    ModelNotFound {
        /// The resolved model path.
        path: PathBuf,
        /// The config file that named it, when there is one.
        config: Option<PathBuf>,
    },
    /// Occurs when the tensor given to a model (or the size a config promises)
    /// does not match the model's declared input shape.
    #[error(
        "model {model}: input `{input}` expects shape {} (? = any) but got {}",
        shape_text(expected),
        shape_text(got)
    )]
    InputShape {
        /// The model file.
        model: PathBuf,
        /// The input's name.
        input: String,
        /// The declared shape, -1 for dynamic dimensions.
        expected: Vec<i64>,
        /// The shape supplied.
        got: Vec<usize>,
    },
    /// Occurs when a model output contains NaN or infinity.
    #[error(
        "model {model}: output `{output}` contains a non-finite value ({value}) at flat index {index}"
    )]
    OutputNotFinite {
        /// The model file.
        model: PathBuf,
        /// The output's name.
        output: String,
        /// Flat index of the first bad element.
        index: usize,
        /// The bad value.
        value: f32,
    },
    /// Occurs when a model produces no outputs, or an output with zero elements.
    #[error(
        "model {model}: output `{output}` is empty (shape {})",
        shape_text(shape)
    )]
    OutputEmpty {
        /// The model file.
        model: PathBuf,
        /// The output's name (`<none>` when the model returned no outputs).
        output: String,
        /// The output's shape.
        shape: Vec<usize>,
    },
    /// Occurs when a decoder finds outputs whose number or shapes do not fit
    /// what the config says the model produces.
    #[error("model {model}: {message}")]
    OutputShape {
        /// The model file.
        model: PathBuf,
        /// What was expected and what was found.
        message: String,
    },
    /// Occurs when a model config file is not valid YAML or does not match the
    /// schema (the message carries line and column).
    #[error("{path}: {message}")]
    ConfigSyntax {
        /// The config file.
        path: PathBuf,
        /// The parser's message with line and column.
        message: String,
    },
    /// Occurs when a model config parses but a field is out of range or
    /// inconsistent (zero size, wrong mean length, unknown class name).
    #[error("{path}: field `{field}`: {message}")]
    ConfigInvalid {
        /// The config file.
        path: PathBuf,
        /// The offending field, dotted (`output.strides`).
        field: String,
        /// Why it is rejected.
        message: String,
    },
    /// Occurs when an image or map file cannot be decoded.
    #[error("{path}: cannot decode image: {message}")]
    Image {
        /// The image file.
        path: PathBuf,
        /// The decoder's message.
        message: String,
    },
    /// Occurs when an image's header announces more pixels than
    /// [`crate::raw::frames::MAX_IMAGE_PIXELS`]; checked before decoding, so
    /// a small file claiming a huge image cannot exhaust memory.
    #[error(
        "{path}: the image is {width}×{height} pixels, more than the limit of {limit} pixels (perception::raw::frames::MAX_IMAGE_PIXELS)"
    )]
    ImageTooLarge {
        /// The image file.
        path: PathBuf,
        /// Width from the header.
        width: u32,
        /// Height from the header.
        height: u32,
        /// The limit in pixels.
        limit: u64,
    },
    /// Occurs when a file or directory cannot be read.
    #[error("{path}: {source}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// Occurs when a frames directory or a set of dense maps is unusable (no
    /// frames, mixed sizes, unexpected file names, maps of different sizes).
    #[error("{path}: {message}")]
    Frames {
        /// The directory or file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Occurs when the shared perception code (sequence validation, window
    /// facts) rejects what this path produced.
    #[error(transparent)]
    Perception(#[from] crate::PerceptionError),
}

impl RawError {
    /// Builds an [`RawError::Io`].
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        RawError::Io {
            path: path.into(),
            source,
        }
    }

    /// Wraps an `ort` error with what we were doing.
    pub fn ort(context: impl Into<String>, err: impl std::fmt::Display) -> Self {
        RawError::Ort {
            context: context.into(),
            message: err.to_string(),
        }
    }
}

impl From<RawError> for crate::PerceptionError {
    fn from(err: RawError) -> Self {
        match err {
            RawError::Perception(inner) => inner,
            other => crate::PerceptionError::Backend {
                stage: "raw frames".to_string(),
                source: Box::new(other),
            },
        }
    }
}

/// A tensor shape as people write it, `1×3×416×416`, with `?` for a
/// dynamic (negative) dimension.
pub(crate) fn shape_text<T: Copy + std::fmt::Display + PartialOrd + Default>(
    shape: &[T],
) -> String {
    if shape.is_empty() {
        return "a scalar".to_string();
    }
    shape
        .iter()
        .map(|&d| {
            if d < T::default() {
                "?".to_string()
            } else {
                d.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("×")
}
