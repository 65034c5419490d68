//! Finding and loading the ONNX Runtime shared library, and running models.
//!
//! `ort` is built with `load-dynamic`: nothing is linked at build time, the
//! library is opened at run time. Plain `ort::init()` panics when the library
//! is missing, so we always resolve a path first ([`find_library`]) and load it
//! with `ort::init_from`, turning every failure into a [`RawError`] that says
//! how to install the runtime.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Mutex, OnceLock};

use ndarray::ArrayViewD;
use ort::session::Session;
use ort::value::TensorRef;

use super::RawError;

/// Environment variable that names the library explicitly (the same one `ort`
/// itself honours).
pub const DYLIB_ENV: &str = "ORT_DYLIB_PATH";

/// A loaded ONNX Runtime: the library path and the process-wide `ort`
/// environment sessions are created under.
///
/// Invariant: at most one library is loaded per process (ONNX Runtime's API
/// table is global); every `Runtime` value refers to that one library.
#[derive(Clone)]
pub struct Runtime {
    library: PathBuf,
    env: ort::environment::Environment,
}

impl std::fmt::Debug for Runtime {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Runtime")
            .field("library", &self.library)
            .finish_non_exhaustive()
    }
}

static LOADED: OnceLock<Runtime> = OnceLock::new();
static LOAD_LOCK: Mutex<()> = Mutex::new(());

impl Runtime {
    /// Finds the library ([`find_library`]) and loads it; returns the already
    /// loaded runtime on later calls.
    pub fn discover() -> Result<Runtime, RawError> {
        if let Some(rt) = LOADED.get() {
            return Ok(rt.clone());
        }
        let path = find_library()?;
        Runtime::load(&path)
    }

    /// Loads the library at `path` with `ort::init_from`. Loading the same
    /// library twice returns the same runtime; a different one is a
    /// [`RawError::RuntimeConflict`].
    pub fn load(path: &Path) -> Result<Runtime, RawError> {
        // Serialise loading so two threads cannot race two different libraries.
        let _guard = LOAD_LOCK
            .lock()
            .unwrap_or_else(|poison| poison.into_inner());
        if let Some(rt) = LOADED.get() {
            return if same_file(&rt.library, path) {
                Ok(rt.clone())
            } else {
                Err(RawError::RuntimeConflict {
                    loaded: rt.library.clone(),
                    requested: path.to_path_buf(),
                })
            };
        }
        if !path.is_file() {
            return Err(RawError::RuntimeNotFound {
                searched: format!("{} does not exist or is not a file", path.display()),
            });
        }
        let builder = ort::init_from(path).map_err(|e| RawError::RuntimeLoad {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let env = builder
            .with_name("logicrag-perception")
            .build()
            .map_err(|e| RawError::RuntimeLoad {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?;
        let rt = Runtime {
            library: path.to_path_buf(),
            env,
        };
        Ok(LOADED.get_or_init(|| rt).clone())
    }

    /// The loaded library file.
    pub fn library(&self) -> &Path {
        &self.library
    }
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

/// Resolves the ONNX Runtime library without hand setup: `ORT_DYLIB_PATH` when
/// set and non-empty, otherwise the `capi/` folder of the `onnxruntime` Python
/// package as reported by `python3`.
pub fn find_library() -> Result<PathBuf, RawError> {
    find_library_from(std::env::var_os(DYLIB_ENV).as_deref(), "python3")
}

/// [`find_library`] with the environment value and the Python interpreter
/// given explicitly (what the tests vary).
pub fn find_library_from(
    dylib_env: Option<&std::ffi::OsStr>,
    python: &str,
) -> Result<PathBuf, RawError> {
    if let Some(value) = dylib_env.filter(|v| !v.is_empty()) {
        let path = PathBuf::from(value);
        return if path.is_file() {
            Ok(path)
        } else {
            Err(RawError::RuntimeNotFound {
                searched: format!("{DYLIB_ENV}={} is not a file", path.display()),
            })
        };
    }
    let dir = python_package_dir(python)?;
    library_in_package(&dir)
}

/// Asks `python` where the `onnxruntime` package lives.
pub fn python_package_dir(python: &str) -> Result<PathBuf, RawError> {
    let output = Command::new(python)
        .args([
            "-c",
            "import os, onnxruntime; print(os.path.dirname(onnxruntime.__file__))",
        ])
        .output()
        .map_err(|e| RawError::RuntimeNotFound {
            searched: format!("{DYLIB_ENV} unset; cannot run `{python}`: {e}"),
        })?;
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        let last = stderr.lines().last().unwrap_or("").trim().to_string();
        return Err(RawError::RuntimeNotFound {
            searched: format!("{DYLIB_ENV} unset; `{python}` cannot import onnxruntime: {last}"),
        });
    }
    let dir = String::from_utf8_lossy(&output.stdout).trim().to_string();
    Ok(PathBuf::from(dir))
}

/// Picks the shared library inside an installed `onnxruntime` package
/// directory (`<dir>/capi/libonnxruntime.so.<version>` on Linux). The
/// versioned name sorts last, and the highest version wins, so the result is
/// deterministic when several are present.
pub fn library_in_package(package_dir: &Path) -> Result<PathBuf, RawError> {
    let capi = package_dir.join("capi");
    let entries = std::fs::read_dir(&capi).map_err(|e| RawError::RuntimeNotFound {
        searched: format!("cannot list {}: {e}", capi.display()),
    })?;
    let mut candidates: Vec<PathBuf> = entries
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(is_library_name)
        })
        .collect();
    candidates.sort();
    candidates.pop().ok_or_else(|| RawError::RuntimeNotFound {
        searched: format!("no libonnxruntime shared library in {}", capi.display()),
    })
}

fn is_library_name(name: &str) -> bool {
    name.starts_with("libonnxruntime.so")
        || (name.starts_with("libonnxruntime") && name.ends_with(".dylib"))
        || name == "onnxruntime.dll"
}

/// One output tensor of a model run, copied out of the runtime.
///
/// Invariant: `data.len()` is the product of `shape`, non-zero, and every
/// element is finite (checked by [`ModelRunner::run`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ModelOutput {
    /// The output's name in the graph.
    pub name: String,
    /// The output's shape.
    pub shape: Vec<usize>,
    /// Row-major elements.
    pub data: Vec<f32>,
}

/// A model output borrowed from the runtime for the duration of
/// [`ModelRunner::run_with`] (no copy).
///
/// Invariant: as [`ModelOutput`]'s, checked before the caller sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutputRef<'a> {
    /// The output's name in the graph.
    pub name: &'a str,
    /// The output's shape.
    pub shape: &'a [usize],
    /// Row-major elements.
    pub data: &'a [f32],
}

/// Read access to a model output, owned ([`ModelOutput`]) or borrowed
/// ([`OutputRef`]), so decoders work on either.
pub trait OutputTensor {
    /// The output's name in the graph.
    fn name(&self) -> &str;
    /// The output's shape.
    fn shape(&self) -> &[usize];
    /// Row-major elements.
    fn data(&self) -> &[f32];
}

impl OutputTensor for ModelOutput {
    fn name(&self) -> &str {
        &self.name
    }
    fn shape(&self) -> &[usize] {
        &self.shape
    }
    fn data(&self) -> &[f32] {
        &self.data
    }
}

impl OutputTensor for OutputRef<'_> {
    fn name(&self) -> &str {
        self.name
    }
    fn shape(&self) -> &[usize] {
        self.shape
    }
    fn data(&self) -> &[f32] {
        self.data
    }
}

/// An ONNX model opened for inference with one `f32` input.
///
/// Invariant: the model has exactly one input, of element type `f32`; the
/// declared shape is kept (`-1` for dynamic dimensions) and every run is
/// checked against it before ONNX Runtime sees the tensor.
#[derive(Debug)]
pub struct ModelRunner {
    session: Session,
    path: PathBuf,
    input_name: String,
    input_shape: Vec<i64>,
    output_names: Vec<String>,
    /// Wall time of the last `Session::run` alone (not the output copy and
    /// checks), so callers can report the model's own time honestly.
    last_session: std::time::Duration,
}

impl ModelRunner {
    /// Opens `path` under `runtime`, using `threads` intra-op threads (0 lets
    /// ONNX Runtime choose).
    pub fn open(runtime: &Runtime, path: &Path, threads: usize) -> Result<ModelRunner, RawError> {
        if !path.is_file() {
            return Err(RawError::ModelNotFound {
                path: path.to_path_buf(),
                config: None,
            });
        }
        let context = || format!("opening model {}", path.display());
        let mut builder =
            Session::builder(&runtime.env).map_err(|e| RawError::ort(context(), e))?;
        // Idle ONNX Runtime workers spin by default and take the CPU from our
        // own pre- and post-processing between runs.
        builder = builder
            .with_intra_op_spinning(false)
            .map_err(|e| RawError::ort(context(), e))?
            .with_inter_op_spinning(false)
            .map_err(|e| RawError::ort(context(), e))?;
        if threads > 0 {
            builder = builder
                .with_intra_threads(threads)
                .map_err(|e| RawError::ort(context(), e))?;
        }
        let session = builder
            .commit_from_file(path)
            .map_err(|e| RawError::ort(context(), e))?;
        let inputs = session.inputs();
        let [input] = inputs else {
            return Err(RawError::OutputShape {
                model: path.to_path_buf(),
                message: format!("expected exactly one input, the model has {}", inputs.len()),
            });
        };
        let dtype = input.dtype();
        let input_shape: Vec<i64> = match (dtype.tensor_type(), dtype.tensor_shape()) {
            (Some(ort::value::TensorElementType::Float32), Some(shape)) => shape.to_vec(),
            _ => {
                return Err(RawError::OutputShape {
                    model: path.to_path_buf(),
                    message: format!(
                        "input `{}` must be a float32 tensor, found {dtype}",
                        input.name()
                    ),
                });
            }
        };
        let input_name = input.name().to_string();
        let output_names = session
            .outputs()
            .iter()
            .map(|o| o.name().to_string())
            .collect();
        Ok(ModelRunner {
            session,
            path: path.to_path_buf(),
            input_name,
            input_shape,
            output_names,
            last_session: std::time::Duration::ZERO,
        })
    }

    /// Wall time of the last run inside ONNX Runtime alone (`Session::run`),
    /// without copying and checking the outputs.
    pub fn last_session_time(&self) -> std::time::Duration {
        self.last_session
    }

    /// The model file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The declared input shape, `-1` for dynamic dimensions.
    pub fn input_shape(&self) -> &[i64] {
        &self.input_shape
    }

    /// The output names in graph order.
    pub fn output_names(&self) -> &[String] {
        &self.output_names
    }

    /// Checks a shape against the declared input shape.
    pub fn check_input_shape(&self, shape: &[usize]) -> Result<(), RawError> {
        let fits = shape.len() == self.input_shape.len()
            && shape
                .iter()
                .zip(&self.input_shape)
                .all(|(&got, &want)| want < 0 || i64::try_from(got).is_ok_and(|g| g == want));
        if fits {
            Ok(())
        } else {
            Err(RawError::InputShape {
                model: self.path.clone(),
                input: self.input_name.clone(),
                expected: self.input_shape.clone(),
                got: shape.to_vec(),
            })
        }
    }

    /// Runs the model on one input tensor and returns every output, in graph
    /// order, after checking that each is non-empty and finite.
    pub fn run(&mut self, input: ArrayViewD<'_, f32>) -> Result<Vec<ModelOutput>, RawError> {
        self.run_with(input, |outs| {
            Ok(outs
                .iter()
                .map(|o| ModelOutput {
                    name: o.name.to_string(),
                    shape: o.shape.to_vec(),
                    data: o.data.to_vec(),
                })
                .collect())
        })
    }

    /// Runs the model and hands `f` every output, in graph order, borrowed
    /// from the runtime (no copy: a detector running three tiles per frame
    /// would otherwise copy megabytes per frame), after checking that each
    /// is non-empty and finite.
    pub fn run_with<R>(
        &mut self,
        input: ArrayViewD<'_, f32>,
        f: impl FnOnce(&[OutputRef<'_>]) -> Result<R, RawError>,
    ) -> Result<R, RawError> {
        self.check_input_shape(input.shape())?;
        let context = || format!("running model {}", self.path.display());
        let tensor =
            TensorRef::from_array_view(input.view()).map_err(|e| RawError::ort(context(), e))?;
        let start = std::time::Instant::now();
        let outputs = self.session.run(ort::inputs![tensor]);
        self.last_session = start.elapsed();
        let outputs = outputs
            .map_err(|e| RawError::ort(format!("running model {}", self.path.display()), e))?;
        let mut parts: Vec<(&str, Vec<usize>, &[f32])> = Vec::with_capacity(outputs.len());
        for name in outputs.keys() {
            // `get` borrows from `outputs` (the iterators' values are
            // temporaries the data could not outlive).
            let Some(value) = outputs.get(name) else {
                continue;
            };
            let (shape, data) = value.try_extract_tensor::<f32>().map_err(|e| {
                RawError::ort(
                    format!("reading output `{name}` of {}", self.path.display()),
                    e,
                )
            })?;
            parts.push((
                name,
                shape
                    .iter()
                    .map(|&d| usize::try_from(d).unwrap_or(0))
                    .collect(),
                data,
            ));
        }
        let views: Vec<OutputRef<'_>> = parts
            .iter()
            .map(|(name, shape, data)| OutputRef { name, shape, data })
            .collect();
        if views.is_empty() {
            return Err(RawError::OutputEmpty {
                model: self.path.clone(),
                output: "<none>".to_string(),
                shape: Vec::new(),
            });
        }
        for out in &views {
            check_output(&self.path, out)?;
        }
        f(&views)
    }
}

/// Rejects empty outputs and outputs holding NaN or infinity, naming the first
/// offending element: a model that silently emits NaN would otherwise produce
/// no detections and look like an empty scene.
pub fn check_output(model: &Path, out: &impl OutputTensor) -> Result<(), RawError> {
    let data = out.data();
    if data.is_empty() {
        return Err(RawError::OutputEmpty {
            model: model.to_path_buf(),
            output: out.name().to_string(),
            shape: out.shape().to_vec(),
        });
    }
    // A branch-free pass per block (vectorisable); the element is located
    // only when one is bad.
    let all_finite = data
        .chunks(4096)
        .all(|block| block.iter().fold(true, |ok, v| ok & v.is_finite()));
    if all_finite {
        return Ok(());
    }
    if let Some((index, &value)) = data.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(RawError::OutputNotFinite {
            model: model.to_path_buf(),
            output: out.name().to_string(),
            index,
            value,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn library_names_are_recognised() {
        assert!(is_library_name("libonnxruntime.so.1.31.1"));
        assert!(is_library_name("libonnxruntime.so"));
        assert!(is_library_name("libonnxruntime.1.31.1.dylib"));
        assert!(!is_library_name("libonnxruntime_providers_shared.so"));
        assert!(!is_library_name("onnxruntime_pybind11_state.so"));
    }

    #[test]
    fn package_without_library_is_a_clear_error() {
        let dir = std::env::temp_dir().join(format!("pframes-nolib-{}", std::process::id()));
        let capi = dir.join("capi");
        std::fs::create_dir_all(&capi).unwrap();
        std::fs::write(capi.join("libonnxruntime_providers_shared.so"), b"x").unwrap();
        let err = library_in_package(&dir).unwrap_err().to_string();
        assert!(err.contains("no libonnxruntime shared library"), "{err}");
        assert!(err.contains("pip install onnxruntime==1.31.1"), "{err}");
        std::fs::write(capi.join("libonnxruntime.so.1.31.1"), b"x").unwrap();
        assert_eq!(
            library_in_package(&dir).unwrap(),
            capi.join("libonnxruntime.so.1.31.1")
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn missing_python_is_a_clear_error() {
        let err = python_package_dir("python3-that-does-not-exist")
            .unwrap_err()
            .to_string();
        assert!(err.contains("cannot run"), "{err}");
        assert!(err.contains("pip install onnxruntime"), "{err}");
    }

    #[test]
    fn nan_and_empty_outputs_are_rejected() {
        let model = Path::new("m.onnx");
        let nan = ModelOutput {
            name: "y".into(),
            shape: vec![2],
            data: vec![1.0, f32::NAN],
        };
        let err = check_output(model, &nan).unwrap_err().to_string();
        assert!(
            err.contains("non-finite") && err.contains("index 1"),
            "{err}"
        );
        let empty = ModelOutput {
            name: "y".into(),
            shape: vec![0, 4],
            data: vec![],
        };
        assert!(
            check_output(model, &empty)
                .unwrap_err()
                .to_string()
                .contains("empty")
        );
        let ok = ModelOutput {
            name: "y".into(),
            shape: vec![1],
            data: vec![0.5],
        };
        assert!(check_output(model, &ok).is_ok());
    }
}
