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

use crate::metrics::{ScoreColumn, Scores};
use crate::scene::SceneView;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

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
const FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans-Latin.ttf");

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

/// The colour of an object class on the bird's-eye view: the same
/// palette as the web page (`assets/app.js`), so both read alike.
fn class_color(class: &str) -> RGBColor {
    match class {
        "Vehicles" => RGBColor(31, 119, 180),
        "Pedestrian" | "Person" => RGBColor(214, 39, 40),
        "Cyclist" => RGBColor(148, 103, 189),
        "Misc" => RGBColor(140, 86, 75),
        _ => RGBColor(127, 127, 127),
    }
}

/// The grey of scenery (poles, buildings, signs) on the bird's-eye view.
const SCENERY: RGBColor = RGBColor(183, 188, 196);

/// The map's colours, as on the web page (`assets/app.js`): drivable
/// area, a lane's fill by kind and its outline, a crosswalk and its outline.
const DRIVABLE: RGBColor = RGBColor(228, 230, 234);
const LANE_OUTLINE: RGBColor = RGBColor(176, 182, 190);
const CROSSWALK: RGBColor = RGBColor(255, 226, 122);
const CROSSWALK_OUTLINE: RGBColor = RGBColor(204, 160, 32);

/// A lane's fill: general traffic grey, bus lanes orange, bike lanes green,
/// intersections a shade darker.
fn lane_color(kind: &str, is_intersection: bool) -> RGBColor {
    match (kind, is_intersection) {
        ("Bus", _) => RGBColor(250, 214, 180),
        ("Bike", _) => RGBColor(200, 232, 196),
        (_, true) => RGBColor(203, 208, 216),
        _ => RGBColor(214, 218, 225),
    }
}

/// Whether a class is a road user (drawn as a track) rather than scenery
/// (drawn as a grey square), as on the web page.
fn is_road_user(class: &str) -> bool {
    matches!(
        class,
        "Vehicles" | "Pedestrian" | "Person" | "Cyclist" | "Misc"
    )
}

/// The bird's-eye view of a window: every track as a line from where it
/// was first seen (a ring) to where it was last seen (a dot and its name),
/// and the camera's path from the origin (a black triangle), in the ego
/// frame of the window's first frame, over the map when the source has one
/// (drivable areas, lanes, crosswalks). Objects all around the ego are
/// shown, behind it too. Written as PNG or SVG by `out`'s extension.
pub fn bev(scene: &SceneView, out: &Path, size: (u32, u32)) -> Result<(), PlotError> {
    if scene.tracks.is_empty() && scene.ego.len() < 2 {
        return Err(PlotError::Empty(format!(
            "window {} has no object with a ground position",
            scene.window
        )));
    }
    write_plot(out, size, &Bev(scene))
}

struct Bev<'a>(&'a SceneView);

/// The most objects named on a bird's-eye view: a 360° log's window holds
/// a hundred, whose names would cover one another and the map.
pub const MAX_NAMED_TRACKS: usize = 30;

/// The track ids whose names are written: all of them up to
/// [`MAX_NAMED_TRACKS`], else the road users nearest the ego's start, then
/// the nearest scenery, up to that many (ties by track id).
fn labelled_tracks(scene: &SceneView) -> std::collections::BTreeSet<u32> {
    if scene.tracks.len() <= MAX_NAMED_TRACKS {
        return scene.tracks.iter().map(|t| t.track_id).collect();
    }
    let mut by_distance: Vec<(bool, f64, u32)> = scene
        .tracks
        .iter()
        .filter_map(|t| {
            let d = t
                .points
                .iter()
                .map(|p| p.x.hypot(p.z))
                .fold(f64::INFINITY, f64::min);
            d.is_finite()
                .then_some((!is_road_user(&t.class), d, t.track_id))
        })
        .collect();
    by_distance.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2)));
    by_distance
        .into_iter()
        .take(MAX_NAMED_TRACKS)
        .map(|(_, _, id)| id)
        .collect()
}

/// Metres of margin around the drawn points.
const BEV_MARGIN_M: f64 = 3.0;

impl Painter for Bev<'_> {
    fn paint<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let scene = self.0;
        root.fill(&WHITE).map_err(text_of)?;
        let points = scene
            .tracks
            .iter()
            .flat_map(|t| t.points.iter())
            .chain(&scene.ego);
        let (mut x0, mut x1, mut z0, mut z1) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for p in points {
            x0 = x0.min(p.x);
            x1 = x1.max(p.x);
            z0 = z0.min(p.z);
            z1 = z1.max(p.z);
        }
        let (x0, x1, z0, z1) = (
            x0 - BEV_MARGIN_M,
            x1 + BEV_MARGIN_M,
            z0 - BEV_MARGIN_M,
            z1 + BEV_MARGIN_M,
        );
        // One metre is as long across as ahead: widen the shorter range to
        // the plotting area's aspect, so that angles and distances read true.
        let (w, h) = root.dim_in_pixel();
        let (plot_w, plot_h) = (
            f64::from(w.saturating_sub(90).max(1)),
            f64::from(h.saturating_sub(110).max(1)),
        );
        let per_px = ((x1 - x0) / plot_w).max((z1 - z0) / plot_h);
        let (cx, cz) = ((x0 + x1) / 2.0, (z0 + z1) / 2.0);
        let (hx, hz) = (per_px * plot_w / 2.0, per_px * plot_h / 2.0);
        let title = format!(
            "{}: frames {}–{}, bird's-eye view (ego frame of frame {})",
            scene.window, scene.first_frame, scene.last_frame, scene.first_frame
        );
        let mut chart = ChartBuilder::on(root)
            .caption(title, (FAMILY, 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d((cx - hx)..(cx + hx), (cz - hz)..(cz + hz))
            .map_err(text_of)?;
        chart
            .configure_mesh()
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.0}"))
            .x_desc("x: metres to the right")
            .y_desc("z: metres ahead")
            .label_style((FAMILY, 13))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(text_of)?;
        if let Some(map) = &scene.map {
            // Cut to the drawn range: plotters does not clip an SVG's polygons.
            draw_map(&mut chart, map, [cx - hx, cz - hz, cx + hx, cz + hz])?;
        }
        let named = labelled_tracks(scene);
        let mut classes_shown = std::collections::BTreeSet::new();
        for t in scene.tracks.iter().filter(|t| !is_road_user(&t.class)) {
            // Scenery stands still: a small grey square where it is.
            let Some(p) = t.points.last() else { continue };
            let name = if named.contains(&t.track_id) {
                t.name.clone()
            } else {
                String::new()
            };
            let series = chart
                .draw_series(std::iter::once(
                    EmptyElement::at((p.x, p.z))
                        + Rectangle::new([(-3, -3), (3, 3)], SCENERY.filled())
                        + Text::new(
                            name,
                            (6, -6),
                            (FAMILY, 11).into_font().color(&RGBColor(120, 126, 135)),
                        ),
                ))
                .map_err(text_of)?;
            if classes_shown.insert("scenery") {
                series.label("scenery (static)").legend(|(x, y)| {
                    Rectangle::new([(x + 5, y - 3), (x + 11, y + 3)], SCENERY.filled())
                });
            }
        }
        for t in scene.tracks.iter().filter(|t| is_road_user(&t.class)) {
            let color = class_color(&t.class);
            let line: Vec<(f64, f64)> = t.points.iter().map(|p| (p.x, p.z)).collect();
            let series = chart
                .draw_series(LineSeries::new(line, color.stroke_width(2)))
                .map_err(text_of)?;
            if classes_shown.insert(t.class.as_str()) {
                series
                    .label(t.class.clone())
                    .legend(move |(x, y)| Circle::new((x + 8, y), 4, color.filled()));
            }
            if let Some(first) = t.points.first() {
                chart
                    .draw_series(std::iter::once(Circle::new(
                        (first.x, first.z),
                        4,
                        color.stroke_width(1),
                    )))
                    .map_err(text_of)?;
            }
            if let Some(last) = t.points.last() {
                let label = if named.contains(&t.track_id) {
                    format!("{} (#{})", t.name, t.track_id)
                } else {
                    String::new()
                };
                chart
                    .draw_series(std::iter::once(
                        EmptyElement::at((last.x, last.z))
                            + Circle::new((0, 0), 4, color.filled())
                            + Text::new(label, (6, -14), (FAMILY, 13).into_font().color(&BLACK)),
                    ))
                    .map_err(text_of)?;
            }
        }
        let ego: Vec<(f64, f64)> = scene.ego.iter().map(|p| (p.x, p.z)).collect();
        chart
            .draw_series(LineSeries::new(ego, BLACK.stroke_width(3)))
            .map_err(text_of)?
            .label("ego (camera) path")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK.stroke_width(3)));
        chart
            .draw_series(std::iter::once(
                EmptyElement::at((0.0, 0.0))
                    + Polygon::new(vec![(0, -9), (-7, 6), (7, 6)], BLACK.filled())
                    + Text::new("ego", (9, 2), (FAMILY, 13).into_font().color(&BLACK)),
            ))
            .map_err(text_of)?;
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(200, 200, 200))
            .label_font((FAMILY, 13))
            .draw()
            .map_err(text_of)?;
        Ok(())
    }
}

/// Draws the map under the tracks: drivable areas, then lanes, then
/// crosswalks, each cut to `view` (`[x_min, z_min, x_max, z_max]`), one
/// legend entry per kind present.
fn draw_map<DB: DrawingBackend>(
    chart: &mut ChartContext<
        '_,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    map: &crate::scene::MapView,
    view: [f64; 4],
) -> Result<(), String> {
    let cut = |poly: &[[f64; 2]]| -> Vec<(f64, f64)> {
        crate::scene::clip_polygon(poly, view)
            .into_iter()
            .map(|p| (p[0], p[1]))
            .collect()
    };
    let areas: Vec<Vec<(f64, f64)>> = map
        .drivable_areas
        .iter()
        .map(|a| cut(&a.polygon))
        .filter(|p| !p.is_empty())
        .collect();
    if !areas.is_empty() {
        chart
            .draw_series(
                areas
                    .into_iter()
                    .map(|p| Polygon::new(p, DRIVABLE.filled())),
            )
            .map_err(text_of)?
            .label("drivable area")
            .legend(|(x, y)| Rectangle::new([(x + 2, y - 5), (x + 14, y + 5)], DRIVABLE.filled()));
    }
    let lanes: Vec<(Vec<(f64, f64)>, RGBColor)> = map
        .lanes
        .iter()
        .map(|l| (cut(&l.polygon), lane_color(l.kind, l.is_intersection)))
        .filter(|(p, _)| !p.is_empty())
        .collect();
    if !lanes.is_empty() {
        chart
            .draw_series(
                lanes
                    .iter()
                    .map(|(p, c)| Polygon::new(p.clone(), c.filled())),
            )
            .map_err(text_of)?
            .label("lane")
            .legend(|(x, y)| {
                Rectangle::new(
                    [(x + 2, y - 5), (x + 14, y + 5)],
                    lane_color("Vehicle", false).filled(),
                )
            });
        chart
            .draw_series(lanes.into_iter().map(|(mut p, _)| {
                if let Some(&first) = p.first() {
                    p.push(first);
                }
                PathElement::new(p, LANE_OUTLINE.stroke_width(1))
            }))
            .map_err(text_of)?;
    }
    let crossings: Vec<Vec<(f64, f64)>> = map
        .crosswalks
        .iter()
        .map(|a| cut(&a.polygon))
        .filter(|p| !p.is_empty())
        .collect();
    if !crossings.is_empty() {
        chart
            .draw_series(
                crossings
                    .iter()
                    .map(|p| Polygon::new(p.clone(), CROSSWALK.filled())),
            )
            .map_err(text_of)?
            .label("crosswalk")
            .legend(|(x, y)| Rectangle::new([(x + 2, y - 5), (x + 14, y + 5)], CROSSWALK.filled()));
        chart
            .draw_series(crossings.into_iter().map(|mut p| {
                if let Some(&first) = p.first() {
                    p.push(first);
                }
                PathElement::new(p, CROSSWALK_OUTLINE.stroke_width(1))
            }))
            .map_err(text_of)?;
    }
    Ok(())
}

/// Per-category accuracy (top) and F1 (bottom) bars, one bar per column
/// in each category and a last group for all questions. Written as PNG or
/// SVG by `out`'s extension.
pub fn eval_chart(
    columns: &[ScoreColumn],
    title: &str,
    out: &Path,
    size: (u32, u32),
) -> Result<(), PlotError> {
    if columns.iter().all(|c| c.overall.n == 0) {
        return Err(PlotError::Empty("the evaluation scored no question".into()));
    }
    write_plot(out, size, &EvalChart { columns, title })
}

/// One scenario's accuracy at each noise level (the level's name, the
/// mean accuracy over its seeds), for [`noise_chart`].
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseLine {
    /// The scenario (one line of the chart).
    pub scenario: String,
    /// `(noise level, accuracy)` pairs, any order.
    pub points: Vec<(String, f64)>,
}

/// The noise levels in the order of increasing noise; other names follow
/// in the order they are first met.
const NOISE_ORDER: [&str; 5] = ["none", "low", "default", "high", "mono"];

/// Accuracy against noise level, one line per scenario: x the noise levels
/// present (none, low, default, high, mono), y the accuracy. Written as PNG
/// or SVG by `out`'s extension.
pub fn noise_chart(
    lines: &[NoiseLine],
    title: &str,
    out: &Path,
    size: (u32, u32),
) -> Result<(), PlotError> {
    let mut levels: Vec<String> = NOISE_ORDER
        .iter()
        .filter(|l| lines.iter().any(|s| s.points.iter().any(|(n, _)| n == *l)))
        .map(|l| (*l).to_string())
        .collect();
    for line in lines {
        for (n, _) in &line.points {
            if !levels.contains(n) {
                levels.push(n.clone());
            }
        }
    }
    if levels.is_empty() {
        return Err(PlotError::Empty(
            "the report has no accuracy per noise level".into(),
        ));
    }
    write_plot(
        out,
        size,
        &NoiseChart {
            lines,
            levels: &levels,
            title,
        },
    )
}

struct NoiseChart<'a> {
    lines: &'a [NoiseLine],
    levels: &'a [String],
    title: &'a str,
}

/// One colour per scenario line (Tableau 10).
const LINE_COLORS: [RGBColor; 10] = [
    RGBColor(78, 121, 167),
    RGBColor(242, 142, 43),
    RGBColor(225, 87, 89),
    RGBColor(118, 183, 178),
    RGBColor(89, 161, 79),
    RGBColor(237, 201, 72),
    RGBColor(176, 122, 161),
    RGBColor(255, 157, 167),
    RGBColor(156, 117, 95),
    RGBColor(186, 176, 172),
];

impl Painter for NoiseChart<'_> {
    fn paint<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(text_of)?;
        let n = self.levels.len();
        let lowest = self
            .lines
            .iter()
            .flat_map(|l| l.points.iter().map(|(_, a)| *a))
            .fold(1.0_f64, f64::min);
        // Room below the lowest line, in steps of 0.05.
        let y0 = ((lowest - 0.05) * 20.0).floor().max(0.0) / 20.0;
        let mut chart = ChartBuilder::on(root)
            .caption(self.title, (FAMILY, 18))
            .margin(14)
            .x_label_area_size(40)
            .y_label_area_size(56)
            .build_cartesian_2d(-0.3..(n as f64 - 0.7), y0..1.01)
            .map_err(text_of)?;
        let levels = self.levels;
        chart
            .configure_mesh()
            .x_labels(n)
            .x_label_formatter(&|v| {
                let i = v.round();
                if (v - i).abs() < 1e-6 && i >= 0.0 {
                    levels.get(i as usize).cloned().unwrap_or_default()
                } else {
                    String::new()
                }
            })
            .y_label_formatter(&|v| format!("{v:.2}"))
            .x_desc("noise level")
            .y_desc("accuracy (mean over seeds)")
            .label_style((FAMILY, 13))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(text_of)?;
        for (i, line) in self.lines.iter().enumerate() {
            let color = LINE_COLORS[i % LINE_COLORS.len()];
            let mut pts: Vec<(f64, f64)> = line
                .points
                .iter()
                .filter_map(|(l, a)| levels.iter().position(|x| x == l).map(|x| (x as f64, *a)))
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            labelled_line(&mut chart, &pts, color, &line.scenario)?;
        }
        legend(&mut chart, SeriesLabelPosition::LowerLeft)?;
        Ok(())
    }
}

/// One curve of a reliability diagram: a label (a noise level, a question
/// subset) and its reliability table.
#[derive(Debug, Clone, PartialEq)]
pub struct ReliabilityCurve {
    /// What the curve is of, shown in the legend.
    pub label: String,
    /// The non-empty bins, in order of P(yes).
    pub bins: Vec<crate::eval::ReliabilityBin>,
}

/// The reliability diagram: above, each curve's observed frequency of yes
/// against its mean forecast P(yes) per bin, with the diagonal of perfect
/// calibration; below, the answers per bin on a log scale (most answers
/// sit in the end bins). Written as PNG or SVG by `out`'s extension.
pub fn reliability_chart(
    curves: &[ReliabilityCurve],
    title: &str,
    out: &Path,
    size: (u32, u32),
) -> Result<(), PlotError> {
    if curves.iter().all(|c| c.bins.iter().all(|b| b.n == 0)) {
        return Err(PlotError::Empty("no answer states a probability".into()));
    }
    write_plot(out, size, &ReliabilityChart { curves, title })
}

struct ReliabilityChart<'a> {
    curves: &'a [ReliabilityCurve],
    title: &'a str,
}

impl Painter for ReliabilityChart<'_> {
    fn paint<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(text_of)?;
        let (_, h) = root.dim_in_pixel();
        let (top, bottom) = root.split_vertically(h * 68 / 100);
        let mut chart = ChartBuilder::on(&top)
            .caption(self.title, (FAMILY, 18))
            .margin(14)
            .x_label_area_size(40)
            .y_label_area_size(56)
            .build_cartesian_2d(0.0..1.0, 0.0..1.0)
            .map_err(text_of)?;
        chart
            .configure_mesh()
            .x_desc("forecast P(yes), mean per bin")
            .y_desc("observed frequency of yes")
            .x_label_formatter(&|v| format!("{v:.1}"))
            .y_label_formatter(&|v| format!("{v:.1}"))
            .label_style((FAMILY, 13))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(text_of)?;
        chart
            .draw_series(LineSeries::new(
                [(0.0, 0.0), (1.0, 1.0)],
                RGBColor(150, 150, 150).stroke_width(1),
            ))
            .map_err(text_of)?
            .label("perfectly calibrated")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], RGBColor(150, 150, 150)));
        for (i, curve) in self.curves.iter().enumerate() {
            let color = LINE_COLORS[i % LINE_COLORS.len()];
            let pts: Vec<(f64, f64)> = curve
                .bins
                .iter()
                .filter(|b| b.n > 0)
                .map(|b| (b.mean_p_yes, b.frequency_yes))
                .collect();
            labelled_line(&mut chart, &pts, color, &curve.label)?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
        // Answers per bin: bars side by side, one per curve, from 0.5 so
        // that a bin of one answer still shows.
        let most = self
            .curves
            .iter()
            .flat_map(|c| c.bins.iter().map(|b| b.n))
            .max()
            .unwrap_or(1) as f64;
        let mut counts = ChartBuilder::on(&bottom)
            .margin(14)
            .margin_top(4)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d(0.0..1.0, (0.5..most * 2.0).log_scale())
            .map_err(text_of)?;
        counts
            .configure_mesh()
            .x_desc("forecast P(yes), bin")
            .y_desc("answers")
            .x_label_formatter(&|v| format!("{v:.1}"))
            .y_label_formatter(&|v| format!("{v:.0}"))
            .label_style((FAMILY, 13))
            .light_line_style(WHITE)
            .draw()
            .map_err(text_of)?;
        let k = self.curves.len().max(1) as f64;
        for (i, curve) in self.curves.iter().enumerate() {
            let color = LINE_COLORS[i % LINE_COLORS.len()];
            counts
                .draw_series(curve.bins.iter().filter(|b| b.n > 0).map(|b| {
                    let w = (b.to - b.from) * 0.8 / k;
                    let left = b.from + (b.to - b.from) * 0.1 + w * i as f64;
                    Rectangle::new([(left, 0.5), (left + w * 0.92, b.n as f64)], color.filled())
                }))
                .map_err(text_of)?;
        }
        Ok(())
    }
}

/// Reads one score (accuracy, F1) of a category.
type Metric = fn(&Scores) -> f64;

struct EvalChart<'a> {
    columns: &'a [ScoreColumn],
    title: &'a str,
}

/// The colour of a column: the logic dark, the model's conditions lighter.
fn column_color(name: &str, i: usize) -> RGBColor {
    match name {
        "LR" => RGBColor(31, 78, 121),
        "C1" => RGBColor(160, 160, 160),
        "C2" => RGBColor(242, 142, 43),
        "C3" => RGBColor(89, 161, 79),
        _ => [RGBColor(118, 183, 178), RGBColor(237, 201, 72)][i % 2],
    }
}

impl Painter for EvalChart<'_> {
    fn paint<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(text_of)?;
        let (head, body) = root.split_vertically(48);
        let (w, _) = head.dim_in_pixel();
        let centered =
            TextStyle::from((FAMILY, 20).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
        head.draw(&Text::new(self.title, (w as i32 / 2, 16), centered))
            .map_err(text_of)?;
        // One legend for both panels, in the head: inside a panel it would
        // cover the bars, which reach the top for a perfect score.
        let mut x = w as i32 - 12;
        for (i, col) in self.columns.iter().enumerate().rev() {
            let color = column_color(&col.name, i);
            let text_w = 9 * col.name.chars().count() as i32;
            x -= text_w;
            head.draw(&Text::new(
                col.name.clone(),
                (x, 38),
                TextStyle::from((FAMILY, 14).into_font()).pos(Pos::new(HPos::Left, VPos::Center)),
            ))
            .map_err(text_of)?;
            x -= 20;
            head.draw(&Rectangle::new([(x, 32), (x + 14, 44)], color.filled()))
                .map_err(text_of)?;
            x -= 14;
        }
        let mut cats: Vec<String> = self
            .columns
            .iter()
            .flat_map(|c| c.by_category.keys().cloned())
            .collect();
        cats.sort();
        cats.dedup();
        // Questions without a category are filed under "": name them.
        let groups: Vec<(String, Vec<Option<&Scores>>)> = cats
            .iter()
            .map(|k| {
                let label = if k.is_empty() { "(none)" } else { k.as_str() };
                (
                    label.to_string(),
                    self.columns.iter().map(|c| c.by_category.get(k)).collect(),
                )
            })
            .chain(std::iter::once((
                "all".to_string(),
                self.columns.iter().map(|c| Some(&c.overall)).collect(),
            )))
            .collect();
        let panels = body.split_evenly((2, 1));
        let metrics: [(&str, Metric); 2] = [("accuracy", |s| s.accuracy), ("F1", |s| s.f1)];
        for (panel, (metric, value)) in panels.iter().zip(metrics) {
            self.bars(root, panel, metric, value, &groups)?;
        }
        Ok(())
    }
}

impl EvalChart<'_> {
    /// One panel: a group of bars per category, one bar per column, the
    /// value written above each bar and the category's name (with its
    /// number of questions) under the group.
    fn bars<DB: DrawingBackend>(
        &self,
        canvas: &DrawingArea<DB, Shift>,
        area: &DrawingArea<DB, Shift>,
        metric: &str,
        value: Metric,
        groups: &[(String, Vec<Option<&Scores>>)],
    ) -> Result<(), String> {
        let n = groups.len() as f64;
        let mut chart = ChartBuilder::on(area)
            .margin(10)
            .margin_bottom(6)
            .x_label_area_size(30)
            .y_label_area_size(48)
            .build_cartesian_2d(0.0..n, 0.0..1.12)
            .map_err(text_of)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .disable_x_axis()
            .x_labels(0)
            .y_labels(6)
            .y_desc(metric)
            .y_label_formatter(&|v| format!("{v:.1}"))
            .label_style((FAMILY, 13))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(text_of)?;
        let k = self.columns.len().max(1) as f64;
        // Bars fill 80% of a group's width; the rest separates groups.
        let bar = 0.8 / k;
        for (g, (_, scores)) in groups.iter().enumerate() {
            for (i, (col, s)) in self.columns.iter().zip(scores).enumerate() {
                let Some(s) = s.filter(|s| s.n > 0) else {
                    continue;
                };
                let v = value(s);
                let left = g as f64 + 0.1 + bar * i as f64;
                let color = column_color(&col.name, i);
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(left, 0.0), (left + bar * 0.92, v)],
                        color.filled(),
                    )))
                    .map_err(text_of)?;
                chart
                    .draw_series(std::iter::once(Text::new(
                        format!("{v:.2}"),
                        (left + bar * 0.08, v + 0.05),
                        (FAMILY, 11).into_font().color(&BLACK),
                    )))
                    .map_err(text_of)?;
            }
        }
        // Category names go under the plotting area, where a chart's own
        // series would be clipped: placed on the whole canvas, whose
        // pixels are the backend's (a panel's are offset).
        let style = TextStyle::from((FAMILY, 13).into_font())
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Top));
        for (g, (label, scores)) in groups.iter().enumerate() {
            let n = scores.iter().flatten().map(|s| s.n).max().unwrap_or(0);
            let (px, py) = chart.backend_coord(&(g as f64 + 0.5, 0.0));
            canvas
                .draw(&Text::new(
                    format!("{label} (n={n})"),
                    (px, py + 6),
                    style.clone(),
                ))
                .map_err(text_of)?;
        }
        Ok(())
    }
}

/// A chart over two `f64` axes (the noise and reliability plots).
type LineChart<'a, DB> = ChartContext<
    'a,
    DB,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// One labelled curve: a line through `pts` with a dot at each, and its
/// legend entry.
fn labelled_line<'a, DB: DrawingBackend + 'a>(
    chart: &mut LineChart<'a, DB>,
    pts: &[(f64, f64)],
    color: RGBColor,
    label: &str,
) -> Result<(), String> {
    chart
        .draw_series(LineSeries::new(pts.to_vec(), color.stroke_width(2)))
        .map_err(text_of)?
        .label(label.to_string())
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2)));
    chart
        .draw_series(pts.iter().map(|p| Circle::new(*p, 4, color.filled())))
        .map_err(text_of)?;
    Ok(())
}

/// The legend of a chart's labelled curves, at `position`.
fn legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut LineChart<'a, DB>,
    position: SeriesLabelPosition,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(200, 200, 200))
        .label_font((FAMILY, 13))
        .draw()
        .map_err(text_of)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_png_and_svg_are_written() {
        assert_eq!(Format::of(Path::new("a/b.PNG")).ok(), Some(Format::Png));
        assert_eq!(Format::of(Path::new("b.svg")).ok(), Some(Format::Svg));
        assert!(matches!(
            Format::of(Path::new("b.jpg")),
            Err(PlotError::Format { .. })
        ));
        assert!(matches!(
            Format::of(Path::new("noext")),
            Err(PlotError::Format { .. })
        ));
    }

    #[test]
    fn accuracy_against_noise_renders_one_line_per_scenario() {
        let dir = std::env::temp_dir().join(format!("logicrag-noise-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let line = |name: &str, acc: [f64; 3]| NoiseLine {
            scenario: name.into(),
            // Out of order on purpose: the chart orders the levels.
            points: vec![
                ("high".into(), acc[2]),
                ("none".into(), acc[0]),
                ("default".into(), acc[1]),
            ],
        };
        let lines = [
            line("braking", [1.0, 0.977, 0.958]),
            line("pickup", [1.0, 1.0, 0.992]),
        ];
        let svg = dir.join("noise.svg");
        noise_chart(&lines, "accuracy against noise", &svg, (800, 500)).expect("svg");
        let text = std::fs::read_to_string(&svg).expect("svg text");
        for word in [
            "braking",
            "pickup",
            "none",
            "default",
            "high",
            "noise level",
        ] {
            assert!(text.contains(word), "the SVG lacks {word}");
        }
        let png = dir.join("noise.png");
        noise_chart(&lines, "accuracy against noise", &png, (640, 400)).expect("png");
        let img = image::open(&png).expect("png reads").to_rgb8();
        assert_eq!((img.width(), img.height()), (640, 400));
        assert!(img.pixels().filter(|p| p.0 != [255, 255, 255]).count() > 2000);
        assert!(matches!(
            noise_chart(&[], "t", &png, (640, 400)),
            Err(PlotError::Empty(_))
        ));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_bundled_font_registers() {
        assert!(register_font().is_ok());
    }

    #[test]
    fn a_reliability_diagram_names_its_curves() {
        let dir = std::env::temp_dir().join(format!("logicrag-rel-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let bin = |from: f64, n: usize, p: f64, f: f64| crate::eval::ReliabilityBin {
            from,
            to: from + 0.1,
            n,
            mean_p_yes: p,
            frequency_yes: f,
        };
        let curves = [ReliabilityCurve {
            label: "high".into(),
            bins: vec![
                bin(0.0, 400, 0.01, 0.02),
                bin(0.5, 3, 0.55, 0.33),
                bin(0.9, 380, 0.99, 0.97),
            ],
        }];
        let svg = dir.join("rel.svg");
        reliability_chart(&curves, "reliability", &svg, (700, 700)).expect("svg");
        let text = std::fs::read_to_string(&svg).expect("svg text");
        for word in [
            "high",
            "perfectly calibrated",
            "observed frequency of yes",
            "answers",
        ] {
            assert!(text.contains(word), "the SVG lacks {word}");
        }
        let empty = [ReliabilityCurve {
            label: "x".into(),
            bins: vec![],
        }];
        assert!(matches!(
            reliability_chart(&empty, "t", &svg, (700, 700)),
            Err(PlotError::Empty(_))
        ));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
