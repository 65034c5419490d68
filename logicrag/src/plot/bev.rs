//! The bird's-eye view of a window ([`bev`]): tracks, scenery, the camera's
//! path and, for a log with a map, its drivable areas, lanes and crosswalks.

use super::{FAMILY, Painter, PlotError, text_of, write_plot};
use crate::scene::SceneView;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

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
