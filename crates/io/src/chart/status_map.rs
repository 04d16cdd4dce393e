//! Stability maps: for each method a panel, a grid over two parameters (time step ×
//! mesh jitter, say), each cell coloured by how the run ended and labelled with a short
//! note (the failure kind, or the energy change), and a heavy line where failed cells
//! meet cells that ran to the end: the method's failure boundary.

use std::path::Path;

use plotters::prelude::*;

use super::legend::{self, Entry, Key};
use super::{LEGEND_WIDTH, svg_string, write_svg};
use crate::error::Result;

/// How one run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Outcome {
    /// Completed, energy bounded.
    Completed,
    /// Completed, but the energy grew beyond the study's threshold.
    EnergyGrowth,
    /// Stopped with an error.
    Failed,
    /// Not run (or no result).
    Missing,
}

impl Outcome {
    /// Every outcome, in legend order.
    pub const ALL: [Outcome; 4] = [
        Outcome::Completed,
        Outcome::EnergyGrowth,
        Outcome::Failed,
        Outcome::Missing,
    ];

    /// Legend text.
    pub fn label(self) -> &'static str {
        match self {
            Outcome::Completed => "completed",
            Outcome::EnergyGrowth => "energy growth",
            Outcome::Failed => "failed",
            Outcome::Missing => "not run",
        }
    }

    /// Fill colour: green, amber, red, grey (distinct in lightness as well as hue).
    fn colour(self) -> RGBColor {
        match self {
            Outcome::Completed => RGBColor(150, 215, 140),
            Outcome::EnergyGrowth => RGBColor(250, 195, 80),
            Outcome::Failed => RGBColor(225, 90, 80),
            Outcome::Missing => RGBColor(215, 215, 215),
        }
    }
}

/// One cell of a panel.
#[derive(Debug, Clone, PartialEq)]
pub struct MapCell {
    /// Column (index into the x ticks).
    pub x: usize,
    /// Row (index into the y ticks).
    pub y: usize,
    /// How the run ended.
    pub outcome: Outcome,
    /// A short note drawn in the cell (≤ 12 characters read well).
    pub note: String,
}

/// One method's grid.
#[derive(Debug, Clone, PartialEq)]
pub struct MapPanel {
    /// Panel title (the method).
    pub title: String,
    /// Its cells; cells not listed are drawn as [`Outcome::Missing`].
    pub cells: Vec<MapCell>,
}

/// Panels side by side over the same two categorical axes.
#[derive(Debug, Clone, PartialEq)]
pub struct StatusMap {
    /// Title above the panels.
    pub title: String,
    /// Horizontal axis label (with unit).
    pub x_label: String,
    /// Column tick labels.
    pub x_ticks: Vec<String>,
    /// Vertical axis label (with unit).
    pub y_label: String,
    /// Row tick labels, bottom to top.
    pub y_ticks: Vec<String>,
    /// One panel per method.
    pub panels: Vec<MapPanel>,
}

/// Pixels per panel column (two panels per row of the figure).
const PANEL_SIZE: (u32, u32) = (520, 420);
const PANELS_PER_ROW: usize = 2;

impl StatusMap {
    /// Figure size: panels in rows of two, the legend on the right, the title on top.
    fn size(&self) -> (u32, u32) {
        let rows = self.panels.len().div_ceil(PANELS_PER_ROW).max(1) as u32;
        let columns = self.panels.len().clamp(1, PANELS_PER_ROW) as u32;
        (
            columns * PANEL_SIZE.0 + LEGEND_WIDTH,
            rows * PANEL_SIZE.1 + 50,
        )
    }

    /// The chart as an SVG document.
    pub fn to_svg(&self) -> Result<String> {
        svg_string(self.size(), |backend| self.draw(backend))
    }

    /// Writes the chart to `path` as SVG.
    pub fn write_svg(&self, path: &Path) -> Result<()> {
        write_svg(path, self.to_svg())
    }

    fn draw<DB: DrawingBackend>(&self, backend: DB) -> std::result::Result<(), String> {
        let root = backend.into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root
            .titled(&self.title, ("sans-serif", 24))
            .map_err(|e| e.to_string())?;
        let (width, _) = root.dim_in_pixel();
        let (plots, legend) = root.split_horizontally(width - LEGEND_WIDTH);
        let rows = self.panels.len().div_ceil(PANELS_PER_ROW).max(1);
        let columns = self.panels.len().clamp(1, PANELS_PER_ROW);
        let areas = plots.split_evenly((rows, columns));
        for (panel, area) in self.panels.iter().zip(&areas) {
            self.draw_panel(panel, area)?;
        }
        let entries: Vec<Entry> = Outcome::ALL
            .iter()
            .map(|o| Entry {
                label: o.label().to_string(),
                key: Key::Swatch(o.colour()),
            })
            .collect();
        legend::draw(&legend, &entries)?;
        root.present().map_err(|e| e.to_string())
    }

    fn draw_panel<DB: DrawingBackend>(
        &self,
        panel: &MapPanel,
        area: &DrawingArea<DB, plotters::coord::Shift>,
    ) -> std::result::Result<(), String> {
        let (nx, ny) = (self.x_ticks.len().max(1), self.y_ticks.len().max(1));
        let mut chart = ChartBuilder::on(area)
            .caption(&panel.title, ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(50)
            .y_label_area_size(75)
            .build_cartesian_2d(
                (0..2 * nx as i32).with_key_points(centres(nx)),
                (0..2 * ny as i32).with_key_points(centres(ny)),
            )
            .map_err(|e| e.to_string())?;
        // Cell i spans [2i, 2i + 2] so that its centre, where its tick sits, is the
        // whole number 2i + 1 (plotters formats key points of integer axes only).
        let tick = |ticks: &[String], v: &i32| {
            ticks
                .get((v.max(&1) / 2) as usize)
                .cloned()
                .unwrap_or_default()
        };
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .axis_desc_style(("sans-serif", 17))
            .label_style(("sans-serif", 14))
            .x_labels(nx + 1)
            .y_labels(ny + 1)
            .x_label_formatter(&|v| tick(&self.x_ticks, v))
            .y_label_formatter(&|v| tick(&self.y_ticks, v))
            .draw()
            .map_err(|e| e.to_string())?;
        let mut grid = vec![None; nx * ny];
        for cell in &panel.cells {
            if cell.x < nx && cell.y < ny {
                grid[cell.y * nx + cell.x] = Some(cell);
            }
        }
        for (index, cell) in grid.iter().enumerate() {
            let (x, y) = (index % nx, index / nx);
            let outcome = cell.map_or(Outcome::Missing, |c| c.outcome);
            let corner = |dx: usize, dy: usize| (2 * (x + dx) as i32, 2 * (y + dy) as i32);
            let mut rectangle =
                Rectangle::new([corner(0, 0), corner(1, 1)], outcome.colour().filled());
            rectangle.set_margin(2, 2, 2, 2);
            chart
                .plotting_area()
                .draw(&rectangle)
                .map_err(|e| e.to_string())?;
            // The failure boundary: a heavy line on every side a failed cell shares with
            // a cell that ran to the end, so the region where the method fails reads at a
            // glance.
            if outcome == Outcome::Failed {
                let ran = |cx: isize, cy: isize| {
                    (0..nx as isize).contains(&cx)
                        && (0..ny as isize).contains(&cy)
                        && grid[cy as usize * nx + cx as usize].is_some_and(|c| {
                            matches!(c.outcome, Outcome::Completed | Outcome::EnergyGrowth)
                        })
                };
                let (xi, yi) = (x as isize, y as isize);
                let sides = [
                    (ran(xi - 1, yi), [corner(0, 0), corner(0, 1)]),
                    (ran(xi + 1, yi), [corner(1, 0), corner(1, 1)]),
                    (ran(xi, yi - 1), [corner(0, 0), corner(1, 0)]),
                    (ran(xi, yi + 1), [corner(0, 1), corner(1, 1)]),
                ];
                for (_, side) in sides.iter().filter(|(on, _)| *on) {
                    chart
                        .plotting_area()
                        .draw(&PathElement::new(side.to_vec(), BLACK.stroke_width(4)))
                        .map_err(|e| e.to_string())?;
                }
            }
            if let Some(cell) = cell.filter(|c| !c.note.is_empty()) {
                let style = ("sans-serif", 14).into_font().color(&BLACK).pos(
                    plotters::style::text_anchor::Pos::new(
                        plotters::style::text_anchor::HPos::Center,
                        plotters::style::text_anchor::VPos::Center,
                    ),
                );
                let centre = (2 * x as i32 + 1, 2 * y as i32 + 1);
                chart
                    .plotting_area()
                    .draw(&(EmptyElement::at(centre) + Text::new(cell.note.clone(), (0, 0), style)))
                    .map_err(|e| e.to_string())?;
            }
        }
        Ok(())
    }
}

/// The centres 2i + 1 of `n` cells of width 2: the ticks of a categorical axis.
pub(super) fn centres(n: usize) -> Vec<i32> {
    (0..n as i32).map(|i| 2 * i + 1).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_notes_and_legend_are_drawn() {
        let map = StatusMap {
            title: "stability".into(),
            x_label: "wave CFL [-]".into(),
            x_ticks: vec!["0.1".into(), "0.5".into()],
            y_label: "jitter [h]".into(),
            y_ticks: vec!["0".into(), "0.3".into()],
            panels: vec![
                MapPanel {
                    title: "umls".into(),
                    cells: vec![
                        MapCell {
                            x: 0,
                            y: 0,
                            outcome: Outcome::Completed,
                            note: "-2%".into(),
                        },
                        MapCell {
                            x: 1,
                            y: 1,
                            outcome: Outcome::Failed,
                            note: "inverted".into(),
                        },
                    ],
                },
                MapPanel {
                    title: "bspline2".into(),
                    cells: vec![],
                },
            ],
        };
        let svg = map.to_svg().unwrap();
        for text in [
            "umls",
            "bspline2",
            "inverted",
            "-2%",
            "wave CFL [-]",
            "not run",
            "0.5",
        ] {
            assert!(svg.contains(text), "{text}");
        }
        // Every cell is drawn whether or not it ran: besides one failed and one completed
        // cell (each with its legend swatch), two cells of the first panel and all four of
        // the second are "not run", plus that swatch.
        let fill = |o: Outcome| {
            let RGBColor(r, g, b) = o.colour();
            format!("fill=\"#{r:02X}{g:02X}{b:02X}\"")
        };
        assert_eq!(svg.matches(&fill(Outcome::Failed)).count(), 2);
        assert_eq!(svg.matches(&fill(Outcome::Completed)).count(), 2);
        assert_eq!(svg.matches(&fill(Outcome::Missing)).count(), 2 + 4 + 1);
        // The failed cell (1, 1) borders no completed cell (its neighbours were not run):
        // no boundary. A failed cell beside a completed one gets one heavy side.
        assert_eq!(svg.matches("stroke-width=\"4\"").count(), 0);
        let mut beside = map.clone();
        beside.panels[0].cells.push(MapCell {
            x: 1,
            y: 0,
            outcome: Outcome::Failed,
            note: "kick".into(),
        });
        let svg = beside.to_svg().unwrap();
        // (1, 0) borders (0, 0) on its left; (1, 1) above it is failed too.
        assert_eq!(svg.matches("stroke-width=\"4\"").count(), 1);
    }
}
