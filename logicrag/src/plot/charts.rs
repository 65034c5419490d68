//! The charts of an evaluation: per-category accuracy and F1 bars
//! ([`eval_chart`]), accuracy against noise ([`noise_chart`]) and the
//! reliability diagram ([`reliability_chart`]).

use super::{FAMILY, Painter, PlotError, text_of, write_plot};
use crate::metrics::{ScoreColumn, Scores};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

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
