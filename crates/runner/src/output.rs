//! The files a run writes: particle frames (`particles_NNNNN.vtu`) listed in
//! `particles.pvd`, the mesh with grid fields (`mesh.vtu`), and the history (`history.csv`).

use std::path::{Path, PathBuf};

use nalgebra::SVector;
use umls_constitutive::Constitutive;
use umls_engine::{Simulation, TransferScheme};
use umls_io::gmsh::PhysicalGroup;
use umls_io::vtk::{Collection, Encoding, UnstructuredGrid, pad_vector};
use umls_mesh::SimplexMesh;
use umls_transfer::Kernel;

use crate::error::{Result, RunError};
use umls_constitutive::table::{MaterialTable, PlasticPart};

/// The output directory of a run; a run without one counts its frames and writes
/// nothing.
#[derive(Debug)]
pub struct OutputDir {
    dir: Option<PathBuf>,
    encoding: Encoding,
    collection: Collection,
}

impl OutputDir {
    /// Creates `dir` (and its parents) and removes an earlier run's files from it;
    /// `None` for a run that writes no files.
    pub fn create(dir: Option<&Path>, encoding: Encoding) -> Result<Self> {
        if let Some(dir) = dir {
            std::fs::create_dir_all(dir).map_err(|source| RunError::File {
                path: dir.to_path_buf(),
                source,
            })?;
            clear_previous_run(dir)?;
        }
        Ok(Self {
            dir: dir.map(Path::to_path_buf),
            encoding,
            collection: Collection::default(),
        })
    }

    /// Names of the files a run writes (frames are `particles_NNNNN.vtu`).
    pub const OWNED: [&'static str; 7] = [
        "particles.pvd",
        "mesh.vtu",
        "grid.vtu",
        "history.csv",
        "summary.json",
        "energies.svg",
        "particles_*.vtu",
    ];

    /// A path inside the directory (`None` for a run that writes no files).
    pub fn path(&self, name: &str) -> Option<PathBuf> {
        self.dir.as_ref().map(|dir| dir.join(name))
    }

    /// Frames written so far.
    pub fn frames(&self) -> usize {
        self.collection.frames.len()
    }

    /// Writes one particle frame and rewrites `particles.pvd` to include it, so a run
    /// stopped early still opens in ParaView.
    pub fn write_particles<const D: usize, K, P, T>(
        &mut self,
        sim: &Simulation<D, K, MaterialTable<P>, T>,
        reference_positions: &[SVector<f64, D>],
    ) -> Result<()>
    where
        K: Kernel<D>,
        P: PlasticPart<D>,
        T: TransferScheme,
    {
        let Some(dir) = self.dir.clone() else {
            self.collection.push(sim.time(), String::new());
            return Ok(());
        };
        let p = &sim.particles();
        let mut grid = UnstructuredGrid::point_cloud(p.position.iter().map(pad_vector).collect());
        grid.add_point_vectors("velocity", &p.velocity)?;
        let displacement: Vec<SVector<f64, D>> = p
            .position
            .iter()
            .zip(reference_positions)
            .map(|(x, x0)| x - x0)
            .collect();
        grid.add_point_vectors("displacement", &displacement)?;
        let jacobian: Vec<f64> = p
            .deformation
            .iter()
            .map(umls_constitutive::determinant)
            .collect();
        let (cauchy, mean) = cauchy_stresses(sim, &jacobian)?;
        grid.add_point_field("cauchy_stress", 9, cauchy)?;
        grid.add_point_field("mean_stress", 1, mean)?;
        let deformation = p
            .deformation
            .iter()
            .flat_map(|f| full_tensor(f, 1.0))
            .collect();
        grid.add_point_field("deformation_gradient", 9, deformation)?;
        grid.add_point_field("jacobian", 1, jacobian)?;
        grid.add_point_field("mass", 1, p.mass.clone())?;
        // The particle's index in the scene: sorting moves particles between slots, so the
        // point order of two frames may differ.
        grid.add_point_ids(
            "id",
            (0..p.len())
                .map(|slot| i32::try_from(sim.particle_id(slot)).unwrap_or(i32::MAX))
                .collect(),
        )?;
        grid.add_point_ids(
            "material",
            p.state.iter().map(|s| i32::from(s.material)).collect(),
        )?;
        add_state_fields(sim, &mut grid)?;
        let name = format!("particles_{:05}.vtu", self.frames());
        grid.write_vtu(dir.join(&name), self.encoding)?;
        self.collection.push(sim.time(), name);
        self.collection.write(dir.join("particles.pvd"))?;
        Ok(())
    }

    /// Writes `mesh.vtu`: the mesh, its physical groups as 0/1 fields, cell quality, and
    /// (for mesh kernels) the last step's nodal mass and velocity.
    pub fn write_mesh<const D: usize>(
        &self,
        mesh: &SimplexMesh<D>,
        groups: &[PhysicalGroup],
        grid_fields: Option<(&[f64], &[SVector<f64, D>])>,
    ) -> Result<()> {
        let Some(path) = self.path("mesh.vtu") else {
            return Ok(());
        };
        let mut grid = UnstructuredGrid::from_mesh(mesh);
        if let Some((mass, velocity)) = grid_fields {
            grid.add_point_field("node_mass", 1, mass.to_vec())?;
            grid.add_point_vectors("node_velocity", velocity)?;
        }
        grid.add_cell_field(
            "radius_ratio",
            1,
            (0..mesh.simplex_count())
                .map(|s| mesh.simplex_quality(s).radius_ratio)
                .collect(),
        )?;
        for g in groups {
            let mut flags = vec![0; mesh.vertex_count()];
            for &v in &g.vertices {
                flags[v as usize] = 1;
            }
            grid.add_point_ids(&format!("group {}", g.name), flags)?;
            if g.dimension == D {
                let mut cells = vec![0; mesh.simplex_count()];
                for &c in &g.cells {
                    cells[c as usize] = 1;
                }
                grid.add_cell_ids(&format!("group {}", g.name), cells)?;
            }
        }
        grid.write_vtu(path, self.encoding)?;
        Ok(())
    }

    /// Writes `grid.vtu` for grid kernels: the nodes as points with the last step's
    /// nodal mass and velocity (the mesh kernels' `mesh.vtu` carries these instead).
    pub fn write_grid<const D: usize>(
        &self,
        nodes: &[SVector<f64, D>],
        mass: &[f64],
        velocity: &[SVector<f64, D>],
    ) -> Result<()> {
        let Some(path) = self.path("grid.vtu") else {
            return Ok(());
        };
        let mut grid = UnstructuredGrid::point_cloud(nodes.iter().map(pad_vector).collect());
        grid.add_point_field("node_mass", 1, mass.to_vec())?;
        grid.add_point_vectors("node_velocity", velocity)?;
        grid.write_vtu(path, self.encoding)?;
        Ok(())
    }
}

/// Removes what an earlier run wrote into `dir` (the files of [`OutputDir::OWNED`], and
/// nothing else): a 3-frame run into a folder that held 61 frames would otherwise leave 58
/// stale frames that ParaView loads as one series, and a B-spline run's `grid.vtu` would
/// outlive it.
fn clear_previous_run(dir: &Path) -> Result<()> {
    let entries = std::fs::read_dir(dir).map_err(|source| RunError::File {
        path: dir.to_path_buf(),
        source,
    })?;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        let frame = name
            .strip_prefix("particles_")
            .and_then(|r| r.strip_suffix(".vtu"));
        let owned = OutputDir::OWNED[..6].contains(&name)
            || frame.is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
        if owned && entry.file_type().is_ok_and(|t| t.is_file()) {
            let path = entry.path();
            std::fs::remove_file(&path).map_err(|source| RunError::File { path, source })?;
        }
    }
    Ok(())
}

/// A D×D tensor as a row-major 3×3 one, with `rest` on the diagonal entries beyond D.
fn full_tensor<const D: usize>(m: &nalgebra::SMatrix<f64, D, D>, rest: f64) -> [f64; 9] {
    std::array::from_fn(|k| {
        let (i, j) = (k / 3, k % 3);
        if i < D && j < D {
            m[(i, j)]
        } else if i == j {
            rest
        } else {
            0.0
        }
    })
}

/// Cauchy stresses of every particle as full 3×3 tensors (row-major), and their means:
/// in 2D the plane-strain σ_zz (not zero), in 1D (uniaxial stress) σ_yy = σ_zz = 0.
fn cauchy_stresses<const D: usize, K, P, T>(
    sim: &Simulation<D, K, MaterialTable<P>, T>,
    jacobian: &[f64],
) -> Result<(Vec<f64>, Vec<f64>)>
where
    K: Kernel<D>,
    P: PlasticPart<D>,
    T: TransferScheme,
{
    let p = sim.particles();
    let kirchhoff = sim.stresses()?;
    let mut cauchy = Vec::with_capacity(9 * p.len());
    let mut mean = Vec::with_capacity(p.len());
    for (i, ((tau, j), (f, state))) in kirchhoff
        .iter()
        .zip(jacobian)
        .zip(p.deformation.iter().zip(&p.state))
        .enumerate()
    {
        let zz = if D == 2 {
            let tau_zz = sim
                .material()
                .out_of_plane_stress(f, state)
                .map_err(|source| umls_engine::EngineError::Material {
                    step: sim.step_count(),
                    particle: sim.particle_id(i),
                    source,
                })?;
            tau_zz / j
        } else {
            0.0
        };
        let sigma = full_tensor(&(tau / *j), zz);
        mean.push((sigma[0] + sigma[4] + sigma[8]) / 3.0);
        cauchy.extend(sigma);
    }
    Ok((cauchy, mean))
}

/// The material state's scalars (plastic strain, …), one point field each.
fn add_state_fields<const D: usize, K, P, T>(
    sim: &Simulation<D, K, MaterialTable<P>, T>,
    grid: &mut UnstructuredGrid,
) -> Result<()>
where
    K: Kernel<D>,
    P: PlasticPart<D>,
    T: TransferScheme,
{
    let names = sim.material().state_scalar_names();
    if names.is_empty() {
        return Ok(());
    }
    let states = &sim.particles().state;
    let mut values = Vec::with_capacity(states.len() * names.len());
    for s in states {
        sim.material().state_scalars(s, &mut values);
    }
    for (k, name) in names.iter().enumerate() {
        let column = values
            .iter()
            .skip(k)
            .step_by(names.len())
            .copied()
            .collect();
        grid.add_point_field(name, 1, column)?;
    }
    Ok(())
}
