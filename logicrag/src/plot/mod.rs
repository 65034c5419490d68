//! Pictures of a window and of an evaluation, as PNG or SVG (chosen by the
//! output file's extension): [`bev`] draws a [`SceneView`]'s tracks, the
//! camera's path, the objects' names and, for a log with a map, its
//! drivable areas, lanes and crosswalks on the bird's-eye plane;
//! [`eval_chart`] draws per-category accuracy and F1 bars for the logic
//! alone (LR) and, when present, the model under C1–C3;
//! [`reliability_chart`] the reliability diagram of the answers'
//! probabilities read as forecasts of "yes", one curve per noise level.
//!
//! Text is drawn with a font bundled in the binary (DejaVu Sans, Latin
//! subset, `assets/fonts/`) through `plotters`' `ab_glyph` backend, so a
//! plot looks the same on every machine and needs no system fonts.
//!
//! [`SceneView`]: crate::scene::SceneView

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

mod bev;
mod charts;
#[cfg(test)]
mod tests;

pub use bev::{MAX_NAMED_TRACKS, bev};
pub use charts::{NoiseLine, ReliabilityCurve, eval_chart, noise_chart, reliability_chart};

/// Errors while drawing or writing a plot.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Occurs when the output file's extension is neither `.png` nor `.svg`.
    #[error("{path}: the plot's file must end in .png or .svg")]
    Format {
        /// The output file.
        path: String,
    },
    /// Occurs when the requested size is too small to draw on or too large
    /// to hold in memory.
    #[error("a plot of {width}×{height} pixels: each side must be {MIN_SIDE} to {MAX_SIDE}")]
    Size {
        /// Width asked for.
        width: u32,
        /// Height asked for.
        height: u32,
    },
    /// Occurs when there is nothing to draw (a window without positions,
    /// an evaluation without questions).
    #[error("nothing to plot: {0}")]
    Empty(String),
    /// Occurs when the bundled font cannot be registered (a corrupt build).
    #[error("the bundled font cannot be read")]
    Font,
    /// Occurs when plotters fails to draw.
    #[error("drawing {path}: {message}")]
    Draw {
        /// The output file.
        path: String,
        /// What failed.
        message: String,
    },
    /// Occurs when the file cannot be written.
    #[error("writing {path}: {source}")]
    Io {
        /// The output file.
        path: String,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
}

/// The smallest side of a plot, in pixels: below it the labels overlap.
pub(crate) const MIN_SIDE: u32 = 200;
/// The largest side of a plot, in pixels (a PNG buffer of 8000² is 192 MB).
pub(crate) const MAX_SIDE: u32 = 8000;

/// Image formats a plot is written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// A PNG bitmap.
    Png,
    /// An SVG drawing (text stays text).
    Svg,
}

impl Format {
    /// The format a file's extension names (case-insensitive).
    pub fn of(path: &Path) -> Result<Format, PlotError> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("png") => Ok(Format::Png),
            Some("svg") => Ok(Format::Svg),
            _ => Err(PlotError::Format {
                path: path.display().to_string(),
            }),
        }
    }
}

/// The bundled font: DejaVu Sans cut to Latin (see `assets/fonts/README.md`).
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans-Latin.ttf");

/// The font family every text of a plot asks for.
const FAMILY: &str = "sans-serif";

/// Registers the bundled font once per process; plotters keeps fonts in a
/// global table, and registering again would only repeat the work.
fn register_font() -> Result<(), PlotError> {
    static DONE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        plotters::style::register_font(FAMILY, FontStyle::Normal, FONT).is_ok()
            && plotters::style::register_font(FAMILY, FontStyle::Bold, FONT).is_ok()
    });
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

/// Something that can draw itself on any plotters backend.
trait Painter {
    /// Draws on `root`; the message says what failed.
    fn paint<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String>;
}

/// Plotters' error as text (its error type differs per backend).
fn text_of<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> String {
    e.to_string()
}

/// Paints `p` on a canvas of `size` and writes it to `out` in the format
/// its extension names.
fn write_plot(out: &Path, size: (u32, u32), p: &impl Painter) -> Result<(), PlotError> {
    let format = Format::of(out)?;
    let (w, h) = size;
    if !(MIN_SIDE..=MAX_SIDE).contains(&w) || !(MIN_SIDE..=MAX_SIDE).contains(&h) {
        return Err(PlotError::Size {
            width: w,
            height: h,
        });
    }
    register_font()?;
    let path = out.display().to_string();
    let draw_err = |message: String| PlotError::Draw {
        path: path.clone(),
        message,
    };
    let bytes = match format {
        Format::Png => {
            let mut buf = vec![0u8; w as usize * h as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
                p.paint(&root).map_err(draw_err)?;
                root.present().map_err(|e| draw_err(text_of(e)))?;
            }
            let img = image::RgbImage::from_raw(w, h, buf)
                .ok_or_else(|| draw_err("the bitmap has the wrong size".into()))?;
            let mut png = std::io::Cursor::new(Vec::new());
            img.write_to(&mut png, image::ImageFormat::Png)
                .map_err(|e| draw_err(e.to_string()))?;
            png.into_inner()
        }
        Format::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
                p.paint(&root).map_err(draw_err)?;
                root.present().map_err(|e| draw_err(text_of(e)))?;
            }
            svg.into_bytes()
        }
    };
    std::fs::write(out, bytes).map_err(|source| PlotError::Io { path, source })
}
