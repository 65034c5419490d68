//! The frames of a directory, in order, within the frame-count limit.

use std::path::{Path, PathBuf};

use crate::model::{MAX_FRAMES, check_frame_count};
use crate::raw::RawError;

/// The image files of a frames directory (`.png`, `.jpg`, `.jpeg`), sorted by
/// name; frame `i` is the `i`-th file.
pub fn list_frames(dir: &Path) -> Result<Vec<PathBuf>, RawError> {
    let rd = std::fs::read_dir(dir).map_err(|e| RawError::io(dir, e))?;
    let mut out = Vec::new();
    for entry in rd {
        let path = entry.map_err(|e| RawError::io(dir, e))?.path();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if matches!(ext.as_deref(), Some("png" | "jpg" | "jpeg")) {
            out.push(path);
        }
    }
    out.sort();
    // Before any model runs: a directory beyond the limit would otherwise
    // fail only after a full run, in `Sequence::validate`.
    checked_frame_count(dir, out.len())?;
    if out.is_empty() {
        return Err(RawError::Frames {
            path: dir.to_path_buf(),
            message: "no .png/.jpg frames in this directory".into(),
        });
    }
    Ok(out)
}

/// `n` frames of `dir` as a frame count, or an error naming the directory
/// and [`MAX_FRAMES`] when there are more.
pub(super) fn checked_frame_count(dir: &Path, n: usize) -> Result<u32, RawError> {
    let message = match u32::try_from(n) {
        Ok(count) => match check_frame_count("frames", count) {
            Ok(()) => return Ok(count),
            Err(m) => m,
        },
        Err(_) => format!(
            "`frames` {n} exceeds the limit of {MAX_FRAMES} frames (perception::MAX_FRAMES)"
        ),
    };
    Err(RawError::Frames {
        path: dir.to_path_buf(),
        message,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_count_beyond_max_frames_is_refused_naming_the_directory() {
        let dir = Path::new("/data/frames");
        assert_eq!(checked_frame_count(dir, 3).ok(), Some(3));
        let max = MAX_FRAMES as usize;
        assert_eq!(checked_frame_count(dir, max).ok(), Some(MAX_FRAMES));
        for n in [max + 1, usize::MAX] {
            let err = checked_frame_count(dir, n)
                .map_or_else(|e| e.to_string(), |c| format!("accepted {c}"));
            assert!(
                err.starts_with("/data/frames: ")
                    && err.contains(&format!("`frames` {n} exceeds the limit of 1000000")),
                "{err}"
            );
        }
    }
}
