//! Charts as SVG files a browser opens: one module for every chart the project draws,
//! so they all read the same way — a title, axis labels with units, tick labels
//! large enough to read, optional logarithmic axes for data spanning decades, and the
//! legend in a panel beside the plot where it cannot cover a curve, its lines wrapped and
//! its font shrunk until it fits the canvas. Non-finite points
//! (and non-positive ones on a log axis) are left out rather than allowed to break the
//! axis ranges.
//!
//! - [`LineChart`]: curves (energies, convergence, error against time), each in a
//!   [`Style`] of its own; failed runs are crosses on the bottom axis;
//! - [`PanelChart`]: line charts stacked as panels of one figure, for comparisons with
//!   more curves than one panel can show;
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
mod legend;
mod line;
mod status_map;
mod style;

pub use bars::{Bar, StackedBars};
pub use line::{LineChart, PanelChart};
pub use status_map::{MapCell, MapPanel, Outcome, StatusMap};
pub use style::{COLOURS, Dash, Marker, Style};

/// Width and height of a chart in pixels.
const SIZE: (u32, u32) = (1100, 600);
/// Width of the legend panel on the right.
const LEGEND_WIDTH: u32 = 260;

/// Colours of the parts of bars and of unstyled legend swatches.
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

/// Width of one character of the sans-serif font in units of the font size, generous so
/// that a wrapped legend line is never wider than measured.
pub const CHAR_WIDTH: f64 = 0.6;

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
    /// Its look; `None` takes [`Style::nth`] of its place in the chart.
    pub style: Option<Style>,
    /// Horizontal positions of runs that failed and have no value: drawn as crosses on
    /// the bottom of the plot, and counted in the legend.
    pub failed: Vec<f64>,
    /// Runs that failed, including those without a horizontal position.
    pub failed_count: usize,
}

impl Series {
    /// A line through `points`.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            points,
            markers: false,
            style: None,
            failed: Vec::new(),
            failed_count: 0,
        }
    }

    /// The same series in `style`.
    pub fn with_style(mut self, style: Style) -> Self {
        self.style = Some(style);
        self
    }

    /// The same series with `count` failed runs, of which those at `positions` are drawn.
    pub fn with_failures(mut self, positions: Vec<f64>, count: usize) -> Self {
        self.failed_count = count.max(positions.len());
        self.failed = positions;
        self
    }

    /// Its legend text: the label, and the failed runs' count.
    pub fn legend_label(&self) -> String {
        match self.failed_count {
            0 => self.label.clone(),
            n => format!("{} (✗ {n} failed)", self.label),
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
