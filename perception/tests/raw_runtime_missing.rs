//! Runtime loading failures, in their own test binary: ONNX Runtime's API
//! table is process-global, so these must run where no library was loaded.
//! Nothing here may panic: each failure is an error that says how to install
//! the runtime.

use std::ffi::OsStr;
use std::path::Path;

use perception::raw::RawError;
use perception::raw::runtime::{Runtime, find_library_from};

#[test]
fn missing_library_file_says_how_to_install() {
    let err = Runtime::load(Path::new("/nonexistent/libonnxruntime.so.1.31.1")).unwrap_err();
    assert!(matches!(err, RawError::RuntimeNotFound { .. }), "{err}");
    let msg = err.to_string();
    assert!(
        msg.contains("/nonexistent/libonnxruntime.so.1.31.1"),
        "{msg}"
    );
    assert!(msg.contains("pip install onnxruntime==1.31.1"), "{msg}");
    assert!(msg.contains("ORT_DYLIB_PATH"), "{msg}");
}

#[test]
fn a_file_that_is_not_a_library_is_a_load_error() {
    let dir = std::env::temp_dir().join(format!("pframes-notlib-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fake = dir.join("libonnxruntime.so.1.31.1");
    std::fs::write(&fake, b"not an ELF file").unwrap();
    let err = Runtime::load(&fake).unwrap_err();
    assert!(matches!(err, RawError::RuntimeLoad { .. }), "{err}");
    assert!(
        err.to_string().contains("pip install onnxruntime==1.31.1"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn discovery_reports_each_missing_piece() {
    // ORT_DYLIB_PATH set to a missing file.
    let err =
        find_library_from(Some(OsStr::new("/nope/libonnxruntime.so")), "python3").unwrap_err();
    assert!(
        err.to_string()
            .contains("ORT_DYLIB_PATH=/nope/libonnxruntime.so is not a file"),
        "{err}"
    );
    // No Python to ask.
    let err = find_library_from(None, "/nonexistent/python3").unwrap_err();
    assert!(
        err.to_string()
            .contains("cannot run `/nonexistent/python3`"),
        "{err}"
    );
    // A Python without the package: `false` exits non-zero like a failed import.
    let err = find_library_from(None, "false").unwrap_err();
    assert!(
        err.to_string().contains("cannot import onnxruntime"),
        "{err}"
    );
    assert!(
        err.to_string().contains("pip install onnxruntime==1.31.1"),
        "{err}"
    );
    // An empty ORT_DYLIB_PATH counts as unset (then Python is asked).
    let err = find_library_from(Some(OsStr::new("")), "/nonexistent/python3").unwrap_err();
    assert!(err.to_string().contains("cannot run"), "{err}");
}
