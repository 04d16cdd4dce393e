//! Line charts as SVG files a browser opens: one helper for every chart the project
//! draws, so they all read the same way — a title, axis labels with units, tick labels
//! large enough to read, optional logarithmic axes for data spanning decades, and the
//! legend in a panel beside the plot where it cannot cover a curve. Non-finite points
//! (and non-positive ones on a log axis) are left out rather than allowed to break the
//! axis ranges.
//!
//! ```
//! use umls_io::chart::{Axis, LineChart, Series};
//!
//! let chart = LineChart {
//!     title: "Energy of the colliding disks".into(),
//!     x: Axis::linear("time t [s]"),
//!     y: Axis::linear("energy [J/m]"),
//!     series: vec![Series::new("kinetic", vec![(0.0, 1.0), (1.0, 0.5), (2.0, 0.9)])],
//! };
//! let svg = chart.to_svg()?;
//! assert!(svg.contains("kinetic") && svg.contains("time t [s]"));
//! # Ok::<(), umls_io::IoError>(())
//! ```

use std::path::Path;

use plotters::prelude::*;

use crate::error::{IoError, Result};

/// Width and height of a chart in pixels.
const SIZE: (u32, u32) = (1100, 600);
/// Width of the legend panel on the right.
const LEGEND_WIDTH: u32 = 230;

/// Colours cycled through the series: distinguishable, and readable on white.
const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(0, 0, 0),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
    RGBColor(140, 86, 75),
];

/// One axis: its label (with the unit in brackets) and its scale.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Label, e.g. "time t [s]".
    pub label: String,
    /// Logarithmic scale.
    pub log: bool,
}

impl Axis {
    /// A linear axis.
    pub fn linear(label: impl Into<String>) -> Self {
        Self {
            label: label.into(),
            log: false,
        }
    }

    /// A logarithmic axis (only positive values are drawn).
    pub fn log(label: impl Into<String>) -> Self {
        Self {
            label: label.into(),
            log: true,
        }
    }
}

/// One curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry.
    pub label: String,
    /// (x, y) points, drawn in order.
    pub points: Vec<(f64, f64)>,
    /// Draw markers at the points as well as the line (for few points).
    pub markers: bool,
}

impl Series {
    /// A line through `points`.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            points,
            markers: false,
        }
    }

    /// The same series with markers at its points.
    pub fn with_markers(mut self) -> Self {
        self.markers = true;
        self
    }
}

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
        let mut svg = String::new();
        self.draw(SVGBackend::with_string(&mut svg, SIZE))
            .map_err(|message| IoError::Chart {
                path: "<memory>".into(),
                message,
            })?;
        Ok(svg)
    }

    /// Writes the chart to `path` as SVG.
    pub fn write_svg(&self, path: &Path) -> Result<()> {
        let svg = self.to_svg().map_err(|e| match e {
            IoError::Chart { message, .. } => IoError::Chart {
                path: path.to_path_buf(),
                message,
            },
            other => other,
        })?;
        crate::write_file(path, svg.as_bytes())
    }

    /// The points of a series that the axes can show.
    fn drawable<'a>(&self, series: &'a Series) -> impl Iterator<Item = (f64, f64)> + 'a {
        let (log_x, log_y) = (self.x.log, self.y.log);
        series.points.iter().copied().filter(move |&(x, y)| {
            x.is_finite() && y.is_finite() && (!log_x || x > 0.0) && (!log_y || y > 0.0)
        })
    }

    /// Data range of one coordinate, padded by 5 % (a factor on log axes).
    fn range(&self, pick: fn(&(f64, f64)) -> f64, log: bool) -> (f64, f64) {
        let (lo, hi) = self
            .series
            .iter()
            .flat_map(|s| self.drawable(s))
            .map(|p| pick(&p))
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
        let (plot_area, legend_area) = root.split_horizontally(SIZE.0 - LEGEND_WIDTH);
        let (x0, x1) = self.range(|p| p.0, self.x.log);
        let (y0, y1) = self.range(|p| p.1, self.y.log);
        let mut builder = ChartBuilder::on(&plot_area);
        builder
            .caption(&self.title, ("sans-serif", 24))
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
                    .x_labels(8)
                    .y_labels(8)
                    .draw()
                    .map_err(|e| e.to_string())?;
                for (i, series) in self.series.iter().enumerate() {
                    let colour = PALETTE[i % PALETTE.len()];
                    chart
                        .draw_series(LineSeries::new(
                            self.drawable(series),
                            colour.stroke_width(2),
                        ))
                        .map_err(|e| e.to_string())?;
                    if series.markers {
                        chart
                            .draw_series(
                                self.drawable(series)
                                    .map(|p| Circle::new(p, 4, colour.filled())),
                            )
                            .map_err(|e| e.to_string())?;
                    }
                }
            }};
        }
        match (self.x.log, self.y.log) {
            (false, false) => plot!(x0..x1, y0..y1),
            (true, false) => plot!((x0..x1).log_scale(), y0..y1),
            (false, true) => plot!(x0..x1, (y0..y1).log_scale()),
            (true, true) => plot!((x0..x1).log_scale(), (y0..y1).log_scale()),
        }
        for (i, series) in self.series.iter().enumerate() {
            let colour = PALETTE[i % PALETTE.len()];
            let y = 70 + 30 * i as i32;
            legend_area
                .draw(&PathElement::new(
                    vec![(10, y), (40, y)],
                    colour.stroke_width(3),
                ))
                .map_err(|e| e.to_string())?;
            legend_area
                .draw(&Text::new(
                    series.label.clone(),
                    (48, y - 9),
                    ("sans-serif", 17).into_font(),
                ))
                .map_err(|e| e.to_string())?;
        }
        root.present().map_err(|e| e.to_string())
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
        let (lo, hi) = chart.range(|p| p.1, true);
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
}
