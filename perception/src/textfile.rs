//! Reading an input file safely: only a regular file (a FIFO or a device
//! would block or never end), and no larger than a stated limit.

use std::io::{Error, ErrorKind};
use std::path::Path;

/// The largest text input read, in bytes (labels, tracks, scenarios,
/// configurations, calibrations).
pub const MAX_TEXT_BYTES: u64 = 256 * 1024 * 1024;

/// The metadata of `path` when it is a regular file; a FIFO, a device or a
/// directory is an error before anything is opened, since opening a FIFO
/// blocks until a writer comes and a device may never end.
pub fn regular_file(path: &Path) -> std::io::Result<std::fs::Metadata> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            "not a regular file (a directory, FIFO or device is not read)",
        ));
    }
    Ok(meta)
}

/// Opens a regular file for reading (see [`regular_file`]): images and
/// binary headers go through here so no input can block the process.
pub fn open_regular(path: &Path) -> std::io::Result<std::fs::File> {
    regular_file(path)?;
    std::fs::File::open(path)
}

/// Reads a UTF-8 text file that must be a regular file of at most
/// [`MAX_TEXT_BYTES`]; a FIFO, a device or a directory is an error before
/// anything is opened, so it cannot hang.
pub fn read_text_file(path: &Path) -> std::io::Result<String> {
    let meta = regular_file(path)?;
    if meta.len() > MAX_TEXT_BYTES {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!(
                "{} bytes is more than the {MAX_TEXT_BYTES} bytes read",
                meta.len()
            ),
        ));
    }
    let mut text = std::fs::read_to_string(path)?;
    // A UTF-8 byte order mark says nothing about the content: YAML readers
    // skipped it while the line formats reported it as a bad first line.
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// Reads a configuration-like file and parses it as JSON when its
/// extension is `.json`, YAML otherwise; `origin` in errors is the path.
pub fn load_yaml_or_json<T>(
    path: &Path,
    from_json: impl FnOnce(&str, &str) -> Result<T, crate::PerceptionError>,
    from_yaml: impl FnOnce(&str, &str) -> Result<T, crate::PerceptionError>,
) -> Result<T, crate::PerceptionError> {
    let text = read_text_file(path).map_err(|e| crate::PerceptionError::io(path, e))?;
    let origin = path.display().to_string();
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
    {
        from_json(&text, &origin)
    } else {
        from_yaml(&text, &origin)
    }
}
