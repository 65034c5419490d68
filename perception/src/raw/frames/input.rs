//! The frames of a directory, in order, within the frame-count limit.

use std::path::{Path, PathBuf};

use crate::model::{MAX_FRAMES, check_frame_count};
use crate::raw::RawError;

/// The largest image decoded, in pixels (width × height).
///
/// A compressed image can claim any size: a 389 KB 20000×20000 PNG took
/// 1.6 GB to decode. 40 megapixels hold 8K video frames (33 MP) and KITTI's
/// 1242×375 frames many times over, and decode in at most 160 MB (RGBA8).
pub const MAX_IMAGE_PIXELS: u64 = 40_000_000;

/// Decodes an image after checking the dimensions in its header against
/// [`MAX_IMAGE_PIXELS`], so that an oversized image is an error naming the
/// file before any pixel buffer is allocated.
pub fn open_image(path: &Path) -> Result<image::DynamicImage, RawError> {
    let err = |e: image::ImageError| RawError::Image {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let reader = || -> Result<_, RawError> {
        let file = crate::textfile::open_regular(path).map_err(|e| RawError::io(path, e))?;
        image::ImageReader::new(std::io::BufReader::new(file))
            .with_guessed_format()
            .map_err(|e| RawError::io(path, e))
    };
    let (width, height) = reader()?.into_dimensions().map_err(err)?;
    if u64::from(width) * u64::from(height) > MAX_IMAGE_PIXELS {
        return Err(RawError::ImageTooLarge {
            path: path.to_path_buf(),
            width,
            height,
            limit: MAX_IMAGE_PIXELS,
        });
    }
    reader()?.decode().map_err(err)
}

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

    /// CRC-32 of PNG chunks (ISO 3309), so a test can forge a header.
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = 0xffff_ffff_u32;
        for b in bytes {
            c ^= u32::from(*b);
            for _ in 0..8 {
                c = if c & 1 == 1 {
                    0xedb8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }

    #[test]
    fn an_image_beyond_max_image_pixels_is_refused_from_its_header() {
        // Regression: a 389 KB 20000×20000 PNG under `frames:DIR` took
        // 1.6 GB to decode. A 2×2 PNG whose IHDR is rewritten to claim
        // 20000×20000 must fail before any pixel is decoded.
        let dir = std::env::temp_dir().join(format!("perception-big-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let small = dir.join("small.png");
        image::RgbImage::new(2, 2).save(&small).unwrap();
        let mut bytes = std::fs::read(&small).unwrap();
        open_image(&small).unwrap();
        // IHDR: length at 8, type at 12, width 16..20, height 20..24, CRC 29..33.
        bytes[16..20].copy_from_slice(&20_000u32.to_be_bytes());
        bytes[20..24].copy_from_slice(&20_000u32.to_be_bytes());
        let crc = crc32(&bytes[12..29]);
        bytes[29..33].copy_from_slice(&crc.to_be_bytes());
        let big = dir.join("000000.png");
        std::fs::write(&big, &bytes).unwrap();
        let e = open_image(&big).unwrap_err();
        let _ = std::fs::remove_dir_all(&dir);
        let m = e.to_string();
        assert!(
            matches!(
                e,
                RawError::ImageTooLarge {
                    width: 20_000,
                    height: 20_000,
                    ..
                }
            ) && m.contains("000000.png")
                && m.contains("20000×20000")
                && m.contains(&format!("limit of {MAX_IMAGE_PIXELS} pixels")),
            "{m}"
        );
    }

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
