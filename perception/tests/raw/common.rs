//! Helpers shared by perception's integration tests.

/// A test whose input (../shared data, the ONNX Runtime) is absent fails,
/// naming what is missing: CI provides all of them, and a silently skipped
/// test passes without checking anything. `LOGICRAG_SKIP_MISSING=1` skips
/// such tests on a machine that lacks them, saying so.
pub fn missing_input(what: &str) {
    if std::env::var_os("LOGICRAG_SKIP_MISSING").is_none() {
        panic!("{what} (set LOGICRAG_SKIP_MISSING=1 to skip tests whose inputs are absent)");
    }
    eprintln!("SKIPPED (LOGICRAG_SKIP_MISSING): {what}");
}
