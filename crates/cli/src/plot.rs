//! `energies.svg`: the energy history of a run as a picture any browser opens, for a
//! first look without ParaView (plotters, the workspace's plotting crate).

use std::path::Path;

use plotters::prelude::*;

use crate::error::{CliError, Result};

/// Energies at one recorded time.
#[derive(Debug, Clone, Copy)]
pub struct EnergyRecord {
    /// Time.
    pub time: f64,
    /// Kinetic energy.
    pub kinetic: f64,
    /// Elastic energy.
    pub elastic: f64,
    /// Gravitational potential energy relative to the start.
    pub potential: f64,
    /// Their sum.
    pub total: f64,
}

fn draw(
    path: &Path,
    title: &str,
    records: &[EnergyRecord],
    with_potential: bool,
) -> std::result::Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (1000, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    type Pick = fn(&EnergyRecord) -> f64;
    let mut curves: Vec<(&str, RGBColor, Pick)> = vec![
        ("kinetic", BLUE, |r| r.kinetic),
        ("elastic", RED, |r| r.elastic),
        ("total", BLACK, |r| r.total),
    ];
    if with_potential {
        curves.insert(2, ("potential", GREEN, |r| r.potential));
    }
    let (mut low, mut high) = (0.0f64, 0.0f64);
    for r in records {
        for (_, _, pick) in &curves {
            low = low.min(pick(r));
            high = high.max(pick(r));
        }
    }
    let pad = 0.05 * (high - low).max(f64::MIN_POSITIVE);
    let end = records
        .last()
        .map_or(1.0, |r| r.time)
        .max(f64::MIN_POSITIVE);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..end, (low - pad)..(high + pad))?;
    chart
        .configure_mesh()
        .x_desc("time")
        .y_desc("energy")
        .draw()?;
    for (label, color, pick) in curves {
        chart
            .draw_series(LineSeries::new(
                records.iter().map(|r| (r.time, pick(r))),
                color.stroke_width(2),
            ))?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

/// Writes the energy history to `path` as SVG; the potential curve appears for scenes
/// with gravity.
pub fn energy_plot(
    path: &Path,
    title: &str,
    records: &[EnergyRecord],
    with_potential: bool,
) -> Result<()> {
    draw(path, title, records, with_potential).map_err(|e| CliError::Plot {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}
