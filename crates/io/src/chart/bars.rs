//! Horizontal stacked bars: one bar per case (a kernel on some threads), split into
//! parts (the stages of a step), with the parts' legend beside the plot.

use std::path::Path;

use plotters::prelude::*;

use super::legend::{self, Entry, Key};
use super::{LEGEND_WIDTH, PALETTE, svg_string, write_svg};
use crate::error::Result;

/// One bar.
#[derive(Debug, Clone, PartialEq)]
pub struct Bar {
    /// Its label on the vertical axis.
    pub label: String,
    /// The length of each part, in the order of [`StackedBars::parts`]; non-finite or
    /// negative parts are drawn as zero.
    pub values: Vec<f64>,
}

/// A stacked horizontal bar chart.
#[derive(Debug, Clone, PartialEq)]
pub struct StackedBars {
    /// Title above the plot.
    pub title: String,
    /// Label of the value axis (with unit).
    pub value_label: String,
    /// Names of the parts, coloured in order.
    pub parts: Vec<String>,
    /// The bars, top to bottom.
    pub bars: Vec<Bar>,
}

impl StackedBars {
    fn size(&self) -> (u32, u32) {
        (1100, 160 + 44 * self.bars.len().max(1) as u32)
    }

    /// The chart as an SVG document.
    pub fn to_svg(&self) -> Result<String> {
        svg_string(self.size(), |backend| self.draw(backend))
    }

    /// Writes the chart to `path` as SVG.
    pub fn write_svg(&self, path: &Path) -> Result<()> {
        write_svg(path, self.to_svg())
    }

    fn clean(v: f64) -> f64 {
        if v.is_finite() && v > 0.0 { v } else { 0.0 }
    }

    fn draw<DB: DrawingBackend>(&self, backend: DB) -> std::result::Result<(), String> {
        let root = backend.into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let (width, _) = root.dim_in_pixel();
        let (plot, legend) = root.split_horizontally(width - LEGEND_WIDTH);
        let longest = self
            .bars
            .iter()
            .map(|b| b.values.iter().copied().map(Self::clean).sum::<f64>())
            .fold(0.0, f64::max);
        let x_max = if longest > 0.0 { longest * 1.05 } else { 1.0 };
        let n = self.bars.len().max(1);
        let label_width = self
            .bars
            .iter()
            .map(|b| b.label.chars().count())
            .max()
            .unwrap_or(0) as u32
            * 8
            + 30;
        let mut chart = ChartBuilder::on(&plot)
            .caption(&self.title, ("sans-serif", 24))
            .margin(14)
            .x_label_area_size(55)
            .y_label_area_size(label_width.clamp(60, 330))
            .build_cartesian_2d(
                0.0..x_max,
                (0..2 * n as i32).with_key_points(super::status_map::centres(n)),
            )
            .map_err(|e| e.to_string())?;
        // Bars are listed top to bottom; rows count from the bottom.
        let row = |i: usize| n - 1 - i;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .x_desc(self.value_label.as_str())
            .axis_desc_style(("sans-serif", 19))
            .label_style(("sans-serif", 15))
            .x_labels(8)
            .x_label_formatter(&|v| super::line::tick_label(*v, false))
            .y_labels(n + 1)
            .y_label_formatter(&|v| {
                // Row r spans [2r, 2r + 2]; its label sits at 2r + 1.
                let r = (v.max(&1) / 2) as usize;
                (r < n)
                    .then(|| self.bars.get(n - 1 - r))
                    .flatten()
                    .map(|b| b.label.clone())
                    .unwrap_or_default()
            })
            .draw()
            .map_err(|e| e.to_string())?;
        for (i, bar) in self.bars.iter().enumerate() {
            let mut start = 0.0;
            for (part, &value) in bar.values.iter().enumerate() {
                let length = Self::clean(value);
                let colour = PALETTE[part % PALETTE.len()];
                let r = row(i);
                let mut rectangle = Rectangle::new(
                    [(start, 2 * r as i32), (start + length, 2 * (r + 1) as i32)],
                    colour.filled(),
                );
                rectangle.set_margin(6, 6, 0, 0);
                chart
                    .plotting_area()
                    .draw(&rectangle)
                    .map_err(|e| e.to_string())?;
                start += length;
            }
        }
        let entries: Vec<Entry> = self
            .parts
            .iter()
            .enumerate()
            .map(|(i, p)| Entry {
                label: p.clone(),
                key: Key::Swatch(PALETTE[i % PALETTE.len()]),
            })
            .collect();
        legend::draw(&legend, &entries)?;
        root.present().map_err(|e| e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bars_and_parts_are_labelled() {
        let chart = StackedBars {
            title: "time per particle-step".into(),
            value_label: "time [ns]".into(),
            parts: vec!["P2G".into(), "G2P".into()],
            bars: vec![
                Bar {
                    label: "bspline2, 2 threads".into(),
                    values: vec![100.0, 50.0],
                },
                Bar {
                    label: "umls, 2 threads".into(),
                    values: vec![f64::NAN, 80.0],
                },
            ],
        };
        let svg = chart.to_svg().unwrap();
        for text in [
            "bspline2, 2 threads",
            "umls, 2 threads",
            "P2G",
            "G2P",
            "time [ns]",
        ] {
            assert!(svg.contains(text), "{text}");
        }
    }
}
