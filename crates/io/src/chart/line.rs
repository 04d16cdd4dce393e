//! Line charts: curves over linear or logarithmic axes, each in its style (colour,
//! marker, dash), with failed runs marked; and figures of several such panels.

use std::path::Path;

use plotters::prelude::*;

use plotters::coord::Shift;

use super::legend::{self, Entry, Key};
use super::style::{Style, draw_marker};
use super::{Axis, LEGEND_WIDTH, SIZE, Series, svg_string, write_svg};
use crate::error::Result;

/// A line chart.
#[derive(Debug, Clone, PartialEq)]
pub struct LineChart {
    /// Title above the plot.
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// The curves, coloured in order.
    pub series: Vec<Series>,
}

impl LineChart {
    /// The chart as an SVG document.
    pub fn to_svg(&self) -> Result<String> {
        svg_string(SIZE, |backend| self.draw(backend))
    }

    /// Writes the chart to `path` as SVG.
    pub fn write_svg(&self, path: &Path) -> Result<()> {
        write_svg(path, self.to_svg())
    }

    /// The points of a series that the axes can show.
    fn drawable<'a>(&self, series: &'a Series) -> impl Iterator<Item = (f64, f64)> + 'a {
        let (log_x, log_y) = (self.x.log, self.y.log);
        series.points.iter().copied().filter(move |&(x, y)| {
            x.is_finite() && y.is_finite() && (!log_x || x > 0.0) && (!log_y || y > 0.0)
        })
    }

    /// Data range of one coordinate, padded by 5 % (a factor on log axes); the
    /// horizontal one includes the failed runs' positions.
    fn range(&self, pick: fn(&(f64, f64)) -> f64, log: bool, with_failed: bool) -> (f64, f64) {
        let failed = self
            .series
            .iter()
            .filter(|_| with_failed)
            .flat_map(|s| s.failed.iter().copied())
            .filter(|&x| x.is_finite() && (!log || x > 0.0));
        let (lo, hi) = self
            .series
            .iter()
            .flat_map(|s| self.drawable(s))
            .map(|p| pick(&p))
            .chain(failed)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        if lo > hi {
            return if log { (0.1, 10.0) } else { (0.0, 1.0) };
        }
        if log {
            let (lo, hi) = if lo == hi {
                (lo / 2.0, hi * 2.0)
            } else {
                (lo, hi)
            };
            (lo / (hi / lo).powf(0.05), hi * (hi / lo).powf(0.05))
        } else {
            let span = if hi > lo { hi - lo } else { lo.abs().max(1.0) };
            (lo - 0.05 * span, hi + 0.05 * span)
        }
    }

    fn draw<DB: DrawingBackend>(&self, backend: DB) -> std::result::Result<(), String> {
        let root = backend.into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        self.draw_on(&root, 24)?;
        root.present().map_err(|e| e.to_string())
    }

    /// The style of each series: its own, or the first of [`Style::nth`] no other series
    /// of the chart uses.
    pub fn styles(&self) -> Vec<Style> {
        let mut used: Vec<Style> = self.series.iter().filter_map(|s| s.style).collect();
        let mut next = 0;
        self.series
            .iter()
            .map(|s| {
                s.style.unwrap_or_else(|| {
                    while used.contains(&Style::nth(next)) {
                        next += 1;
                    }
                    used.push(Style::nth(next));
                    Style::nth(next)
                })
            })
            .collect()
    }

    /// Draws the chart, its legend on the right, into `area`.
    fn draw_on<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        caption: u32,
    ) -> std::result::Result<(), String> {
        let (width, _) = area.dim_in_pixel();
        let (plot_area, legend_area) = area.split_horizontally(width - LEGEND_WIDTH);
        let (x0, x1) = self.range(|p| p.0, self.x.log, true);
        let (y0, y1) = self.range(|p| p.1, self.y.log, false);
        let styles = self.styles();
        let mut builder = ChartBuilder::on(&plot_area);
        builder
            .caption(&self.title, ("sans-serif", caption))
            .margin(14)
            .x_label_area_size(55)
            .y_label_area_size(90);
        // plotters types linear and log coordinates differently: one branch each.
        macro_rules! plot {
            ($x:expr, $y:expr) => {{
                let mut chart = builder
                    .build_cartesian_2d($x, $y)
                    .map_err(|e| e.to_string())?;
                chart
                    .configure_mesh()
                    .x_desc(self.x.label.as_str())
                    .y_desc(self.y.label.as_str())
                    .axis_desc_style(("sans-serif", 19))
                    .label_style(("sans-serif", 15))
                    .x_labels(12)
                    .y_labels(12)
                    .x_label_formatter(&|v| tick_label(*v, self.x.log))
                    .y_label_formatter(&|v| tick_label(*v, self.y.log))
                    .draw()
                    .map_err(|e| e.to_string())?;
                for (series, style) in self.series.iter().zip(&styles) {
                    let colour = style.rgb();
                    let stroke = colour.stroke_width(2);
                    match style.dash.pattern() {
                        None => chart
                            .draw_series(LineSeries::new(self.drawable(series), stroke))
                            .map(|_| ()),
                        Some((dash, gap)) => chart
                            .draw_series(DashedLineSeries::new(
                                self.drawable(series).collect::<Vec<_>>(),
                                dash,
                                gap,
                                stroke,
                            ))
                            .map(|_| ()),
                    }
                    .map_err(|e| e.to_string())?;
                    if series.markers {
                        for p in self.drawable(series) {
                            draw_marker(chart.plotting_area(), style.marker, p, 10, colour)?;
                        }
                    }
                    // A failed run has no value: a cross on the bottom of the plot.
                    let failed = series
                        .failed
                        .iter()
                        .filter(|&&x| x.is_finite() && (!self.x.log || x > 0.0))
                        .map(|&x| Cross::new((x, y0), 7, colour.stroke_width(3)));
                    chart.draw_series(failed).map_err(|e| e.to_string())?;
                }
            }};
        }
        match (self.x.log, self.y.log) {
            (false, false) => plot!(x0..x1, y0..y1),
            (true, false) => plot!(
                (x0..x1).log_scale().with_key_points(log_ticks(x0, x1)),
                y0..y1
            ),
            (false, true) => plot!(
                x0..x1,
                (y0..y1).log_scale().with_key_points(log_ticks(y0, y1))
            ),
            (true, true) => plot!(
                (x0..x1).log_scale().with_key_points(log_ticks(x0, x1)),
                (y0..y1).log_scale().with_key_points(log_ticks(y0, y1))
            ),
        }
        let entries: Vec<Entry> = self
            .series
            .iter()
            .zip(&styles)
            .map(|(s, &style)| Entry {
                label: s.legend_label(),
                key: Key::Line(style, s.markers),
            })
            .collect();
        legend::draw(&legend_area, &entries)
    }
}

/// Line charts stacked top to bottom as the panels of one figure under one title: a
/// comparison with more curves than one panel can show, split by a facet (the transfer,
/// a variant, a family of methods).
#[derive(Debug, Clone, PartialEq)]
pub struct PanelChart {
    /// Title above the panels.
    pub title: String,
    /// The panels; each one's title names its facet.
    pub panels: Vec<LineChart>,
}

/// Height of one panel of a [`PanelChart`].
const PANEL_HEIGHT: u32 = 520;
/// Height of a [`PanelChart`]'s title.
const TITLE_HEIGHT: u32 = 50;

impl PanelChart {
    /// Figure size: the width of a line chart, one panel height per panel.
    pub fn size(&self) -> (u32, u32) {
        (
            SIZE.0,
            TITLE_HEIGHT + PANEL_HEIGHT * self.panels.len().max(1) as u32,
        )
    }

    /// The figure as an SVG document.
    pub fn to_svg(&self) -> Result<String> {
        svg_string(self.size(), |backend| {
            let root = backend.into_drawing_area();
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            let (title, body) = root.split_vertically(TITLE_HEIGHT);
            title
                .titled(&self.title, ("sans-serif", 24))
                .map_err(|e| e.to_string())?;
            let areas = body.split_evenly((self.panels.len().max(1), 1));
            for (panel, area) in self.panels.iter().zip(&areas) {
                panel.draw_on(area, 20)?;
            }
            root.present().map_err(|e| e.to_string())
        })
    }

    /// Writes the figure to `path` as SVG.
    pub fn write_svg(&self, path: &Path) -> Result<()> {
        write_svg(path, self.to_svg())
    }
}

/// Tick positions on a log axis from `lo` to `hi`: the powers of ten, with 2 and 5
/// times them when the range spans few decades, and every digit when it spans less than
/// one — so a narrow range still shows several labelled ticks.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let decades = (hi / lo).log10();
    let mantissas: &[f64] = match decades {
        d if d > 4.0 => &[1.0],
        d if d > 1.5 => &[1.0, 2.0, 5.0],
        _ => &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
    };
    let mut ticks = Vec::new();
    let mut power = 10f64.powi(lo.log10().floor() as i32);
    while power <= hi {
        for m in mantissas {
            let t = m * power;
            if t >= lo && t <= hi {
                ticks.push(t);
            }
        }
        power *= 10.0;
    }
    ticks
}

/// A tick label: short decimals on linear axes, `2e-4` style on log axes.
pub(super) fn tick_label(v: f64, log: bool) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let magnitude = v.abs().log10();
    if log && !(-2.0..4.0).contains(&magnitude) {
        let exponent = magnitude.floor() as i32;
        let mantissa = v / 10f64.powi(exponent);
        let mantissa = (mantissa * 10.0).round() / 10.0;
        if mantissa == 1.0 {
            format!("1e{exponent}")
        } else {
            format!("{mantissa}e{exponent}")
        }
    } else if !(-3.0..6.0).contains(&magnitude) {
        format!("{v:.1e}")
    } else {
        // Enough decimals for the value's magnitude, trailing zeros dropped.
        let decimals = (3.0 - magnitude.floor()).clamp(0.0, 6.0) as usize;
        let text = format!("{v:.decimals$}");
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn infinite_and_log_invalid_points_are_skipped() {
        let chart = LineChart {
            title: "t".into(),
            x: Axis::linear("x [m]"),
            y: Axis::log("error [-]"),
            series: vec![
                Series::new(
                    "a",
                    vec![(0.0, 1e-3), (1.0, f64::INFINITY), (2.0, -1.0), (3.0, 1e-6)],
                )
                .with_markers(),
                Series::new("only bad", vec![(f64::NAN, 1.0)]),
            ],
        };
        assert_eq!(chart.drawable(&chart.series[0]).count(), 2);
        let (lo, hi) = chart.range(|p| p.1, true, false);
        assert!(
            lo < 1e-6 && lo > 1e-7 && hi > 1e-3 && hi < 1e-2,
            "{lo} {hi}"
        );
        let svg = chart.to_svg().unwrap();
        assert!(svg.contains("only bad") && svg.contains("error [-]"));
        // Nothing drawable at all still gives a chart.
        let empty = LineChart {
            series: vec![Series::new("none", vec![(f64::NAN, f64::NAN)])],
            ..chart
        };
        assert!(empty.to_svg().unwrap().starts_with("<svg"));
    }

    #[test]
    fn log_axes_get_readable_ticks() {
        let close = |a: Vec<f64>, b: &[f64]| {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-12 * y)
        };
        // Less than a decade: every digit.
        assert!(close(log_ticks(1.5e-4, 4.5e-4), &[2e-4, 3e-4, 4e-4]));
        // A few decades: 1, 2, 5.
        assert!(close(
            log_ticks(0.8, 60.0),
            &[1.0, 2.0, 5.0, 10.0, 20.0, 50.0]
        ));
        assert_eq!(tick_label(3.0000000000000003e-4, true), "3e-4");
        assert_eq!(tick_label(2e-4, true), "2e-4");
        assert_eq!(tick_label(1e-5, true), "1e-5");
        assert_eq!(tick_label(0.05, true), "0.05");
        assert_eq!(tick_label(250.0, false), "250");
        assert_eq!(tick_label(0.125, false), "0.125");
    }
}
