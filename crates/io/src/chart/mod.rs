//! Charts as SVG files a browser opens: one module for every chart the project draws,
//! so they all read the same way — a title, axis labels with units, tick labels
//! large enough to read, optional logarithmic axes for data spanning decades, and the
//! legend in a panel beside the plot where it cannot cover a curve. Non-finite points
//! (and non-positive ones on a log axis) are left out rather than allowed to break the
//! axis ranges.
//!
//! - [`LineChart`]: curves (energies, convergence, error against time);
//! - [`StatusMap`]: a grid of outcomes over two parameters, one panel per method
//!   (stability maps);
//! - [`StackedBars`]: horizontal bars split into parts (time per step by stage).
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

mod bars;
mod line;
mod status_map;

pub use bars::{Bar, StackedBars};
pub use line::LineChart;
pub use status_map::{MapCell, MapPanel, Outcome, StatusMap};

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
    /// Label, e.g. `time t [s]`.
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

/// Draws with `draw` on an SVG backend of `size` into a string.
fn svg_string<F>(size: (u32, u32), draw: F) -> Result<String>
where
    F: FnOnce(SVGBackend<'_>) -> std::result::Result<(), String>,
{
    let mut svg = String::new();
    draw(SVGBackend::with_string(&mut svg, size)).map_err(|message| IoError::Chart {
        path: "<memory>".into(),
        message,
    })?;
    Ok(svg)
}

/// Writes a drawn chart to `path`, naming the path in a drawing error.
fn write_svg(path: &Path, svg: Result<String>) -> Result<()> {
    let svg = svg.map_err(|e| match e {
        IoError::Chart { message, .. } => IoError::Chart {
            path: path.to_path_buf(),
            message,
        },
        other => other,
    })?;
    crate::write_file(path, svg.as_bytes())
}

/// Draws the legend entries `(label, colour)` as swatches down a panel.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    entries: &[(String, RGBColor)],
    swatch: bool,
) -> std::result::Result<(), String> {
    for (i, (label, colour)) in entries.iter().enumerate() {
        let y = 70 + 30 * i as i32;
        if swatch {
            area.draw(&Rectangle::new([(10, y - 9), (40, y + 9)], colour.filled()))
        } else {
            area.draw(&PathElement::new(
                vec![(10, y), (40, y)],
                colour.stroke_width(3),
            ))
        }
        .map_err(|e| e.to_string())?;
        area.draw(&Text::new(
            label.clone(),
            (48, y - 9),
            ("sans-serif", 17).into_font(),
        ))
        .map_err(|e| e.to_string())?;
    }
    Ok(())
}
