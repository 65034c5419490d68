//! A source's frames as pictures for a multimodal model: which picture
//! shows which frame ([`FrameImages`]: an image file, or a simulated frame
//! rendered on demand), N frames sampled evenly over a window, each
//! downscaled to a bounded size and encoded as PNG.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use perception::SceneState;

/// Errors reading a frame image.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// Occurs when an image file cannot be read or decoded.
    #[error("{path}: {message}")]
    Read {
        /// The file.
        path: String,
        /// What failed.
        message: String,
    },
    /// Occurs when an image is larger than `MAX_DECODE_PIXELS`.
    #[error("{path}: {width}×{height} pixels is more than this reads ({MAX_DECODE_PIXELS} pixels)")]
    TooLarge {
        /// The file.
        path: String,
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
    /// Occurs when a rendered simulator frame cannot be encoded as PNG.
    #[error("rendered frame {frame}: {message}")]
    Render {
        /// The frame number.
        frame: u32,
        /// What failed.
        message: String,
    },
}

/// The largest image decoded (a 20000×20000 PNG would take 1.6 GB).
pub(crate) const MAX_DECODE_PIXELS: u64 = 40_000_000;

/// The longest side of an image sent to a model, in pixels.
pub const DEFAULT_MAX_SIDE: u32 = 768;

/// One frame's picture.
#[derive(Debug, Clone)]
pub enum FramePicture {
    /// An image file (PNG or JPEG).
    File(PathBuf),
    /// A simulated frame, rendered from its scene state with the state's
    /// camera when asked for.
    Rendered(Arc<SceneState>),
}

impl FramePicture {
    /// The picture as PNG with its longer side at most `max_side` pixels
    /// (a file is scaled down, never up; a simulated frame is rendered at
    /// that size).
    pub fn png(&self, max_side: u32) -> Result<Vec<u8>, ImageError> {
        match self {
            FramePicture::File(path) => png_for_model(path, max_side),
            FramePicture::Rendered(state) => rendered_png(state, max_side),
        }
    }
}

/// Pictures by frame number.
///
/// Invariant: every file path names an existing PNG or JPEG file (when
/// built); every rendered frame is keyed by its state's frame number.
#[derive(Debug, Clone, Default)]
pub struct FrameImages {
    by_frame: BTreeMap<u32, FramePicture>,
}

impl FrameImages {
    /// Images of a `frames:DIR` source: frame `i` is the `i`-th file in
    /// name order.
    pub(crate) fn in_order(files: Vec<PathBuf>) -> FrameImages {
        FrameImages {
            by_frame: files
                .into_iter()
                .enumerate()
                .filter_map(|(i, p)| u32::try_from(i).ok().map(|i| (i, FramePicture::File(p))))
                .collect(),
        }
    }

    /// Images named by their frame number (`000010.png` is frame 10), as in
    /// KITTI's `image_02/NNNN/`; other files are skipped. `None` when the
    /// directory does not exist or holds none.
    pub fn numbered(dir: &Path) -> Option<FrameImages> {
        let rd = std::fs::read_dir(dir).ok()?;
        let mut by_frame = BTreeMap::new();
        for entry in rd.flatten() {
            let p = entry.path();
            let ext = p
                .extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase);
            if !matches!(ext.as_deref(), Some("png" | "jpg" | "jpeg")) {
                continue;
            }
            if let Some(n) = p
                .file_stem()
                .and_then(|s| s.to_str())
                .and_then(|s| s.parse::<u32>().ok())
            {
                by_frame.insert(n, FramePicture::File(p));
            }
        }
        (!by_frame.is_empty()).then_some(FrameImages { by_frame })
    }

    /// Images already on disk by frame number.
    pub fn from_map(by_frame: BTreeMap<u32, PathBuf>) -> FrameImages {
        FrameImages {
            by_frame: by_frame
                .into_iter()
                .map(|(f, p)| (f, FramePicture::File(p)))
                .collect(),
        }
    }

    /// The camera views of a simulation, one per scene state, rendered
    /// only when a frame is sampled (a run has many frames and a question
    /// looks at a few).
    pub fn rendered(states: &[SceneState]) -> FrameImages {
        FrameImages {
            by_frame: states
                .iter()
                .map(|s| (s.frame, FramePicture::Rendered(Arc::new(s.clone()))))
                .collect(),
        }
    }

    /// The picture of one frame, when the source has it.
    pub fn get(&self, frame: u32) -> Option<&FramePicture> {
        self.by_frame.get(&frame)
    }

    /// Number of frames with an image.
    pub fn len(&self) -> usize {
        self.by_frame.len()
    }

    /// True when no frame has an image.
    pub fn is_empty(&self) -> bool {
        self.by_frame.is_empty()
    }

    /// Up to `n` images evenly spread over frames `first..=last` (the
    /// first and the last of them included when `n` ≥ 2), in frame order.
    pub fn sample(&self, first: u32, last: u32, n: usize) -> Vec<(u32, &FramePicture)> {
        let inside: Vec<(u32, &FramePicture)> = self
            .by_frame
            .range(first..=last)
            .map(|(f, p)| (*f, p))
            .collect();
        if n == 0 || inside.is_empty() {
            return Vec::new();
        }
        if inside.len() <= n {
            return inside;
        }
        if n == 1 {
            return inside.get(inside.len() / 2).copied().into_iter().collect();
        }
        let step = (inside.len() - 1) as f64 / (n - 1) as f64;
        let mut picked: Vec<usize> = (0..n).map(|i| (i as f64 * step).round() as usize).collect();
        picked.dedup();
        picked
            .into_iter()
            .filter_map(|i| inside.get(i).copied())
            .collect()
    }

    /// The [`sample`](FrameImages::sample) of `n` frames over
    /// `first..=last` as PNGs at most `max_side` pixels on the longer side,
    /// in frame order.
    pub fn pngs(
        &self,
        first: u32,
        last: u32,
        n: usize,
        max_side: u32,
    ) -> Result<Vec<Vec<u8>>, ImageError> {
        self.sample(first, last, n)
            .into_iter()
            .map(|(_, p)| p.png(max_side))
            .collect()
    }
}

/// A simulated frame rendered straight at the size a model gets (cheaper
/// than rendering at full size and scaling down) and encoded as PNG.
fn rendered_png(state: &SceneState, max_side: u32) -> Result<Vec<u8>, ImageError> {
    use perception::raw::view::{camera_within, render_view};
    let img = render_view(state, &camera_within(&state.camera, max_side));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(|e| ImageError::Render {
            frame: state.frame,
            message: e.to_string(),
        })?;
    Ok(out.into_inner())
}

/// Reads an image, scales it down so that its longer side is at most
/// `max_side` pixels (never up), and encodes it as PNG.
pub(crate) fn png_for_model(path: &Path, max_side: u32) -> Result<Vec<u8>, ImageError> {
    let err = |message: String| ImageError::Read {
        path: path.display().to_string(),
        message,
    };
    // A FIFO or device named as a frame would block the read forever.
    let reader = || {
        let file = perception::textfile::open_regular(path).map_err(|e| err(e.to_string()))?;
        image::ImageReader::new(std::io::BufReader::new(file))
            .with_guessed_format()
            .map_err(|e| err(e.to_string()))
    };
    let (w, h) = reader()?
        .into_dimensions()
        .map_err(|e| err(e.to_string()))?;
    if u64::from(w) * u64::from(h) > MAX_DECODE_PIXELS {
        return Err(ImageError::TooLarge {
            path: path.display().to_string(),
            width: w,
            height: h,
        });
    }
    let img = reader()?.decode().map_err(|e| err(e.to_string()))?;
    let img = if w.max(h) > max_side {
        img.resize(max_side, max_side, image::imageops::FilterType::Triangle)
    } else {
        img
    };
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(|e| err(e.to_string()))?;
    Ok(out.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn images(frames: &[u32]) -> FrameImages {
        FrameImages::from_map(
            frames
                .iter()
                .map(|f| (*f, PathBuf::from(format!("{f}.png"))))
                .collect(),
        )
    }

    #[test]
    fn samples_are_spread_evenly_and_keep_the_ends() {
        let all = images(&(0..100).collect::<Vec<_>>());
        let s: Vec<u32> = all.sample(10, 19, 5).iter().map(|(f, _)| *f).collect();
        assert_eq!(s, [10, 12, 15, 17, 19]);
        let s: Vec<u32> = all.sample(10, 19, 1).iter().map(|(f, _)| *f).collect();
        assert_eq!(s, [15]);
        let sparse = images(&[10, 15, 20]);
        let s: Vec<u32> = sparse.sample(10, 19, 5).iter().map(|(f, _)| *f).collect();
        assert_eq!(s, [10, 15]);
        assert!(sparse.sample(30, 39, 5).is_empty());
    }

    #[test]
    fn a_frame_is_downscaled_to_a_bounded_png() {
        let dir = std::env::temp_dir().join(format!("logicrag-img-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let p = dir.join("000003.png");
        image::RgbImage::from_pixel(1242, 375, image::Rgb([10, 20, 30]))
            .save(&p)
            .expect("save");
        let png = png_for_model(&p, 600).expect("png");
        let back = image::load_from_memory(&png).expect("decodes");
        assert_eq!((back.width(), back.height()), (600, 181));
        let found = FrameImages::numbered(&dir).expect("numbered");
        assert_eq!(found.sample(0, 9, 5).first().map(|(f, _)| *f), Some(3));
        assert_eq!(found.pngs(0, 9, 5, 600).expect("pngs"), vec![png]);
        std::fs::remove_dir_all(&dir).expect("clean");
    }

    #[test]
    fn simulated_frames_are_rendered_at_the_model_size() {
        let scenario = perception::sim::Scenario::builtin("urban_crossing").expect("scenario");
        let run = perception::sim::simulate(&scenario, 0).expect("simulates");
        let images = FrameImages::rendered(&run.states);
        assert_eq!(images.len(), run.states.len());
        let frames: Vec<u32> = images.sample(20, 29, 5).iter().map(|(f, _)| *f).collect();
        assert_eq!(frames, [20, 22, 25, 27, 29]);
        let pngs = images.pngs(20, 29, 5, 400).expect("renders");
        assert_eq!(pngs.len(), 5);
        let k = run.states[20].camera.intrinsics;
        for png in &pngs {
            let back = image::load_from_memory(png).expect("decodes");
            assert_eq!(back.width().max(back.height()), 400);
            let aspect = f64::from(back.width()) / f64::from(back.height());
            let expected = f64::from(k.image_width) / f64::from(k.image_height);
            assert!((aspect - expected).abs() < 0.02, "{aspect} vs {expected}");
        }
        // The same frame renders to the same bytes (a cache key depends on it).
        assert_eq!(images.pngs(20, 20, 1, 400).expect("renders")[0], pngs[0]);
        assert_ne!(
            pngs[0], pngs[4],
            "the pedestrian moves between frames 20 and 29"
        );
    }
}
