//! `energies.svg`: the energy history of a run as a picture any browser opens, for a
//! first look without ParaView (drawn by `umls_io::chart`, the project's one chart
//! helper).

use std::path::Path;

use umls_io::chart::{Axis, LineChart, Series};

use crate::error::{Result, RunError};

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

/// Writes the energy history to `path` as SVG; the potential curve appears for scenes
/// with gravity. Energies of a D-dimensional scene are per unit thickness (2D) or per
/// unit cross-section (1D), and the axis says so.
pub fn energy_plot(
    path: &Path,
    title: &str,
    dimension: usize,
    records: &[EnergyRecord],
    with_potential: bool,
) -> Result<()> {
    let curve = |label: &str, pick: fn(&EnergyRecord) -> f64| {
        Series::new(label, records.iter().map(|r| (r.time, pick(r))).collect())
    };
    let mut series = vec![
        curve("kinetic", |r| r.kinetic),
        curve("elastic", |r| r.elastic),
    ];
    if with_potential {
        series.push(curve("potential (from start)", |r| r.potential));
    }
    series.push(curve("total", |r| r.total));
    let unit = match dimension {
        1 => "J/m²",
        2 => "J/m",
        _ => "J",
    };
    LineChart {
        title: title.to_string(),
        x: Axis::linear("time t [s]"),
        y: Axis::linear(format!("energy [{unit}]")),
        series,
    }
    .write_svg(path)
    .map_err(|e| RunError::Plot {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}
