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
        return Err(too_large(meta.len()));
    }
    let mut text = std::fs::read_to_string(path)?;
    // A UTF-8 byte order mark says nothing about the content: YAML readers
    // skipped it while the line formats reported it as a bad first line.
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// The error [`read_text_file`] gives for a file over [`MAX_TEXT_BYTES`].
fn too_large(len: u64) -> Error {
    Error::new(
        ErrorKind::InvalidInput,
        format!("{len} bytes is more than the {MAX_TEXT_BYTES} bytes read"),
    )
}

/// Reads a text file under the rules of [`read_text_file`] (a regular file
/// of at most [`MAX_TEXT_BYTES`], UTF-8, a byte order mark skipped) but
/// hands it to `f` in pieces of whole lines of about `chunk` bytes (a line
/// longer than that comes whole; the last piece may lack its newline), so
/// a large file is never held whole: a 95 MB text KB read at once spent
/// more time having the kernel zero its pages than parsing them. `f`'s
/// error stops the reading and is returned; `io` turns a read error into
/// `f`'s error type.
pub fn read_text_chunks<E>(
    path: &Path,
    chunk: usize,
    io: impl Fn(Error) -> E,
    mut f: impl FnMut(&str) -> Result<(), E>,
) -> Result<(), E> {
    use std::io::Read;
    let meta = regular_file(path).map_err(&io)?;
    if meta.len() > MAX_TEXT_BYTES {
        return Err(io(too_large(meta.len())));
    }
    let mut file = std::fs::File::open(path).map_err(&io)?;
    let chunk = chunk.max(1);
    let mut buf: Vec<u8> = Vec::with_capacity(chunk.saturating_mul(2));
    let mut total: u64 = 0;
    let mut first = true;
    loop {
        let n = file
            .by_ref()
            .take(chunk as u64)
            .read_to_end(&mut buf)
            .map_err(&io)?;
        total = total.saturating_add(n as u64);
        // The file may have grown since its size was checked.
        if total > MAX_TEXT_BYTES {
            return Err(io(too_large(total)));
        }
        let eof = n < chunk;
        if first {
            let bom = "\u{feff}".as_bytes();
            if buf.len() < bom.len() && !eof && bom.starts_with(&buf) {
                continue; // too few bytes yet to tell
            }
            if buf.starts_with(bom) {
                buf.drain(..bom.len());
            }
            first = false;
        }
        // Whole lines only: `\n` never occurs inside a multi-byte
        // character, so the cut is also a character boundary.
        let cut = if eof {
            buf.len()
        } else {
            match buf.iter().rposition(|&b| b == b'\n') {
                Some(i) => i + 1,
                None => continue, // one long line: read on
            }
        };
        let text = std::str::from_utf8(buf.get(..cut).unwrap_or_default()).map_err(|_| {
            io(Error::new(
                ErrorKind::InvalidData,
                "stream did not contain valid UTF-8",
            ))
        })?;
        if !text.is_empty() {
            f(text)?;
        }
        buf.drain(..cut);
        if eof {
            return Ok(());
        }
    }
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
