//! Element quality: radius ratio, angles, edge-length ratio, and a whole-mesh summary.

use crate::geometry::{longest_edge, shortest_edge};
use crate::mesh::SimplexMesh;

/// Quality measures of one simplex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimplexQuality {
    /// Normalised radius ratio D · r_in / R_circ: 1 for the regular simplex, → 0 for slivers.
    pub radius_ratio: f64,
    /// Smallest angle in radians: interior angle (D = 2) or dihedral angle (D = 3); `None` for D = 1.
    pub min_angle: Option<f64>,
    /// Largest angle in radians, as for `min_angle`.
    pub max_angle: Option<f64>,
    /// Longest over shortest edge (≥ 1).
    pub edge_ratio: f64,
}

impl<const D: usize> SimplexMesh<D> {
    /// Quality measures of simplex `s`.
    ///
    /// The in-radius is 1 / Σ_n |∇λ_n| (each |∇λ_n| is one over the height onto facet n);
    /// the circumcentre c solves 2 (x_i − x_0)·(c − x_0) = |x_i − x_0|², i.e.
    /// c − x_0 = T⁻ᵀ b / 2. Angles between facets i and j are acos(−n_i·n_j) with n the
    /// outward normals −∇λ / |∇λ|.
    pub fn simplex_quality(&self, s: usize) -> SimplexQuality {
        let corners = self.corners(s);
        let corners = &corners[..=D];
        let inverse = &self.inverse_maps[s];
        let gradients = self.barycentric_gradients(s);
        let grads = gradients.as_slice();
        let in_radius = 1.0 / grads.iter().map(|g| g.norm()).sum::<f64>();
        let b = nalgebra::SVector::<f64, D>::from_fn(|i, _| {
            (corners[i + 1] - corners[0]).norm_squared()
        });
        let circum_radius = (inverse.transpose() * b / 2.0).norm();
        let (min_angle, max_angle) = if D == 1 {
            (None, None)
        } else {
            let mut lo = f64::INFINITY;
            let mut hi: f64 = 0.0;
            for i in 0..=D {
                for j in i + 1..=D {
                    let cos = -grads[i].dot(&grads[j]) / (grads[i].norm() * grads[j].norm());
                    let angle = cos.clamp(-1.0, 1.0).acos();
                    lo = lo.min(angle);
                    hi = hi.max(angle);
                }
            }
            (Some(lo), Some(hi))
        };
        SimplexQuality {
            radius_ratio: D as f64 * in_radius / circum_radius,
            min_angle,
            max_angle,
            edge_ratio: longest_edge(corners) / shortest_edge(corners),
        }
    }

    /// Quality statistics over the whole mesh.
    pub fn quality_summary(&self) -> QualitySummary {
        let mut summary = QualitySummary {
            simplices: self.simplex_count(),
            min_radius_ratio: f64::INFINITY,
            mean_radius_ratio: 0.0,
            worst_simplex: 0,
            min_angle: None,
            max_angle: None,
            max_edge_ratio: 0.0,
            min_edge_length: self.min_edge_length(),
            max_edge_length: self.max_edge_length(),
            min_volume: f64::INFINITY,
            max_volume: 0.0,
        };
        for s in 0..self.simplex_count() {
            let q = self.simplex_quality(s);
            if q.radius_ratio < summary.min_radius_ratio {
                summary.min_radius_ratio = q.radius_ratio;
                summary.worst_simplex = s;
            }
            summary.mean_radius_ratio += q.radius_ratio;
            summary.min_angle = merge(summary.min_angle, q.min_angle, f64::min);
            summary.max_angle = merge(summary.max_angle, q.max_angle, f64::max);
            summary.max_edge_ratio = summary.max_edge_ratio.max(q.edge_ratio);
            summary.min_volume = summary.min_volume.min(self.volume(s));
            summary.max_volume = summary.max_volume.max(self.volume(s));
        }
        summary.mean_radius_ratio /= self.simplex_count() as f64;
        summary
    }
}

fn merge(acc: Option<f64>, x: Option<f64>, pick: fn(f64, f64) -> f64) -> Option<f64> {
    match (acc, x) {
        (Some(a), Some(b)) => Some(pick(a, b)),
        (a, b) => a.or(b),
    }
}

/// Quality statistics of a mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QualitySummary {
    /// Number of simplices.
    pub simplices: usize,
    /// Smallest normalised radius ratio.
    pub min_radius_ratio: f64,
    /// Mean normalised radius ratio.
    pub mean_radius_ratio: f64,
    /// The simplex with the smallest radius ratio.
    pub worst_simplex: usize,
    /// Smallest interior (2D) or dihedral (3D) angle in radians.
    pub min_angle: Option<f64>,
    /// Largest interior (2D) or dihedral (3D) angle in radians.
    pub max_angle: Option<f64>,
    /// Largest per-simplex edge-length ratio.
    pub max_edge_ratio: f64,
    /// Shortest edge in the mesh.
    pub min_edge_length: f64,
    /// Longest edge in the mesh.
    pub max_edge_length: f64,
    /// Smallest simplex volume.
    pub min_volume: f64,
    /// Largest simplex volume.
    pub max_volume: f64,
}

impl std::fmt::Display for QualitySummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "simplices          {}", self.simplices)?;
        writeln!(
            f,
            "radius ratio       min {:.4} (simplex {}), mean {:.4}",
            self.min_radius_ratio, self.worst_simplex, self.mean_radius_ratio
        )?;
        if let (Some(lo), Some(hi)) = (self.min_angle, self.max_angle) {
            writeln!(
                f,
                "angles (deg)       min {:.2}, max {:.2}",
                lo.to_degrees(),
                hi.to_degrees()
            )?;
        }
        writeln!(
            f,
            "edge length        min {:.4e}, max {:.4e}, worst ratio {:.3}",
            self.min_edge_length, self.max_edge_length, self.max_edge_ratio
        )?;
        write!(
            f,
            "volume             min {:.4e}, max {:.4e}",
            self.min_volume, self.max_volume
        )
    }
}
