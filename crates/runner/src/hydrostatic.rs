//! `[reference.hydrostatic]`: the closed-form state of a laterally confined elastic column
//! at rest under gravity, or of a fluid at rest in a container of any shape, and the
//! metrics of a run against it.
//!
//! With slip walls and a slip base the column is in uniaxial strain, so at depth d below
//! the free surface (scene frame, "up" = −g)
//!
//! - σ_vv = −ρ g d, σ_hh = K0 σ_vv with K0 = ν / (1 − ν) (plane strain and 3D alike);
//! - the downward displacement at depth d is ρ g (H² − d²) / (2M), M = E(1 − ν) /
//!   ((1 + ν)(1 − 2ν)) the constrained (P-wave) modulus, so the surface settles by
//!   ρ g H² / (2M).
//!
//! A fluid at rest carries the pressure ρ g d in any container: σ = −ρ g d I, K0 = 1, and
//! no settlement metric (it depends on the container's shape).
//!
//! The metrics compare each particle, by its initial position, with these at the end of
//! the run (the scene brings the column to rest by damping or a gravity ramp).

use nalgebra::{SMatrix, SVector};
use serde_json::{Map, Value, json};

use crate::error::Result;
use crate::frame::SceneFrame;
use crate::scene::Scene;
use crate::schema::{HydrostaticSpec, MaterialSpec, SeedingSpec};
use crate::seeds::Seeds;

/// The column's closed form, resolved against the scene.
#[derive(Debug, Clone)]
pub struct Hydrostatic<const D: usize> {
    /// Unit vector against gravity, scene frame.
    up: SVector<f64, D>,
    surface: f64,
    height: f64,
    margin: f64,
    row: f64,
    /// ρ g.
    unit_weight: f64,
    /// K0 = ν / (1 − ν) for an elastic column, 1 for a fluid.
    k0: f64,
    /// Constrained modulus M of an elastic column (none for a fluid, whose settlement
    /// depends on its container).
    modulus: Option<f64>,
}

/// Which particles a metric averages over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Band {
    Interior,
    BottomRow,
    TopRow,
}

impl<const D: usize> Hydrostatic<D> {
    /// Resolves `spec` for a scene whose gravity (scene frame) is `gravity` and whose
    /// particles are `seeds` (scene frame). The column must be of one elastic material.
    pub fn new(
        scene: &Scene,
        spec: &HydrostaticSpec,
        gravity: &SVector<f64, D>,
        seeds: &Seeds<D>,
    ) -> Result<Self> {
        let key = |k: &str| format!("reference.hydrostatic.{k}");
        if gravity.norm() == 0.0 {
            return Err(scene.value_error(
                "reference.hydrostatic",
                "a hydrostatic column needs `scene.gravity`",
            ));
        }
        let up = -gravity.normalize();
        if !(spec.surface.is_finite() && spec.base.is_finite() && spec.surface > spec.base) {
            return Err(scene.value_error(
                key("surface"),
                format!(
                    "{} must be finite and above the base ({})",
                    spec.surface, spec.base
                ),
            ));
        }
        let height = spec.surface - spec.base;
        let margin = spec.margin.unwrap_or(0.1 * height);
        if !(margin.is_finite() && margin >= 0.0 && margin < 0.5 * height) {
            return Err(scene.value_error(
                key("margin"),
                format!("{margin} must lie in [0, {})", 0.5 * height),
            ));
        }
        let row = match spec.row {
            Some(r) => r,
            None => match scene.spec.bodies.first().map(|b| &b.seeding) {
                Some(SeedingSpec::Lattice(h)) => *h,
                Some(SeedingSpec::LatticeFrom { spacing, .. }) => *spacing,
                _ => {
                    return Err(scene.value_error(
                        key("row"),
                        "needed when the first body is not seeded on a lattice",
                    ));
                }
            },
        };
        if !(row.is_finite() && row > 0.0 && row < height) {
            return Err(scene.value_error(
                key("row"),
                format!("{row} must be positive and below the column's height {height}"),
            ));
        }
        let material = match seeds.material.first() {
            Some(&m) if seeds.material.iter().all(|&n| n == m) => m,
            _ => {
                return Err(scene.value_error(
                    "reference.hydrostatic",
                    "the column must be one body material",
                ));
            }
        };
        // An elastic column is in uniaxial strain: K0 = ν/(1 − ν), constrained modulus M.
        // A fluid at rest is in hydrostatic pressure in any container: K0 = 1; its
        // settlement depends on the container's shape, so it has none.
        let (density, k0, modulus) = match &scene.spec.materials[usize::from(material)] {
            MaterialSpec::LinearElastic(s)
            | MaterialSpec::NeoHookean(s)
            | MaterialSpec::StVenantKirchhoff(s)
            | MaterialSpec::FixedCorotated(s) => {
                let nu = s.poisson;
                (
                    s.density,
                    nu / (1.0 - nu),
                    Some(s.young * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))),
                )
            }
            MaterialSpec::Fluid(f) => (f.density, 1.0, None),
            _ => {
                return Err(scene.value_error(
                    "reference.hydrostatic",
                    "the body's material must be elastic or a fluid (the closed form is theirs)",
                ));
            }
        };
        let column = Self {
            up,
            surface: spec.surface,
            height,
            margin,
            row,
            unit_weight: density * gravity.norm(),
            k0,
            modulus,
        };
        for (band, name) in [
            (Band::Interior, "margin"),
            (Band::BottomRow, "row"),
            (Band::TopRow, "row"),
        ] {
            if !seeds.position.iter().any(|x| column.in_band(band, x)) {
                return Err(scene.value_error(
                    key(name),
                    format!("no particle lies in the column's {band:?} band"),
                ));
            }
        }
        Ok(column)
    }

    /// Depth below the free surface of a scene-frame point.
    fn depth(&self, x: &SVector<f64, D>) -> f64 {
        self.surface - x.dot(&self.up)
    }

    fn in_band(&self, band: Band, x: &SVector<f64, D>) -> bool {
        let d = self.depth(x);
        match band {
            Band::Interior => d >= self.margin && d <= self.height - self.margin,
            Band::BottomRow => d >= self.height - self.row,
            Band::TopRow => d <= self.row,
        }
    }

    /// The metrics of a run's end state: initial and current positions and Cauchy
    /// stresses in the world, turned into the scene frame by `frame`.
    pub fn metrics(
        &self,
        frame: &SceneFrame<D>,
        initial: &[SVector<f64, D>],
        current: &[SVector<f64, D>],
        stress: &[SMatrix<f64, D, D>],
    ) -> Map<String, Value> {
        let (mut squared, mut interior) = (0.0, 0usize);
        let (mut horizontal, mut vertical) = (0.0, 0.0);
        let (mut bottom, mut bottom_exact) = (0.0, 0.0);
        let (mut settled, mut settled_exact, mut top) = (0.0, 0.0, 0usize);
        let up_world = frame.vector_to_world(&self.up);
        for ((x0, x), sigma) in initial.iter().zip(current).zip(stress) {
            let xs = frame.point_to_scene(x0);
            let d = self.depth(&xs);
            let s = frame.tensor_to_scene(sigma);
            let vv = self.up.dot(&(s * self.up));
            let hh = (s.trace() - vv) / (D - 1) as f64;
            let exact = -self.unit_weight * d;
            if self.in_band(Band::Interior, &xs) {
                squared += (vv - exact).powi(2);
                interior += 1;
                horizontal += hh;
                vertical += vv;
            }
            if self.in_band(Band::BottomRow, &xs) {
                bottom += vv;
                bottom_exact += exact;
            }
            if let (Some(modulus), true) = (self.modulus, self.in_band(Band::TopRow, &xs)) {
                settled += (x0 - x).dot(&up_world);
                settled_exact +=
                    self.unit_weight * (self.height * self.height - d * d) / (2.0 * modulus);
                top += 1;
            }
        }
        let scale = self.unit_weight * self.height;
        let mut m = Map::new();
        m.insert(
            "stress_rms".into(),
            json!((squared / interior.max(1) as f64).sqrt() / scale),
        );
        m.insert("interior_particles".into(), json!(interior));
        m.insert("bottom_row_ratio".into(), json!(bottom / bottom_exact));
        m.insert("k0".into(), json!(horizontal / vertical));
        m.insert("k0_exact".into(), json!(self.k0));
        if let Some(modulus) = self.modulus {
            m.insert("settlement".into(), json!(settled / top.max(1) as f64));
            m.insert(
                "settlement_exact".into(),
                json!(scale * self.height / (2.0 * modulus)),
            );
            m.insert("settlement_ratio".into(), json!(settled / settled_exact));
        }
        m
    }
}
