//! An unstructured grid for VTK: points, cells of one or more kinds, and named fields.

use nalgebra::{SMatrix, SVector};
use umls_mesh::SimplexMesh;

use crate::error::{IoError, Result};

/// VTK cell types used here.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellType {
    /// One point (`VTK_VERTEX`, 1).
    Vertex,
    /// A segment (`VTK_LINE`, 3).
    Line,
    /// A triangle (`VTK_TRIANGLE`, 5).
    Triangle,
    /// A tetrahedron (`VTK_TETRA`, 10).
    Tetra,
}

impl CellType {
    /// The VTK type number.
    pub fn vtk_id(self) -> u8 {
        match self {
            CellType::Vertex => 1,
            CellType::Line => 3,
            CellType::Triangle => 5,
            CellType::Tetra => 10,
        }
    }

    /// The simplex of dimension `dim` (0 to 3).
    pub fn simplex(dim: usize) -> Option<Self> {
        [Self::Vertex, Self::Line, Self::Triangle, Self::Tetra]
            .get(dim)
            .copied()
    }
}

/// Values of a field.
#[derive(Debug, Clone, PartialEq)]
pub enum FieldValues {
    /// 64-bit floats, `components` per point or cell.
    Float64(Vec<f64>),
    /// 32-bit integers (ids, flags), one per point or cell.
    Int32(Vec<i32>),
}

/// A named field on points or cells.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// Name shown in ParaView.
    pub name: String,
    /// Components per entry (1 scalar, 3 vector, 9 tensor).
    pub components: usize,
    /// The values, entry-major.
    pub values: FieldValues,
}

/// Points, cells and fields of one `.vtu` file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UnstructuredGrid {
    /// Point coordinates (padded to 3D).
    pub points: Vec<[f64; 3]>,
    /// Flat cell connectivity.
    pub connectivity: Vec<u64>,
    /// End of each cell in `connectivity`.
    pub offsets: Vec<u64>,
    /// Type of each cell.
    pub types: Vec<CellType>,
    /// Fields on points.
    pub point_data: Vec<Field>,
    /// Fields on cells.
    pub cell_data: Vec<Field>,
}

/// Pads a D-vector to the 3 components VTK expects.
pub fn pad_vector<const D: usize>(v: &SVector<f64, D>) -> [f64; 3] {
    std::array::from_fn(|k| if k < D { v[k] } else { 0.0 })
}

/// Pads a D×D tensor to 3×3, row-major (the 9 components of a VTK tensor).
pub fn pad_tensor<const D: usize>(m: &SMatrix<f64, D, D>) -> [f64; 9] {
    std::array::from_fn(|k| {
        let (i, j) = (k / 3, k % 3);
        if i < D && j < D { m[(i, j)] } else { 0.0 }
    })
}

impl UnstructuredGrid {
    /// A point cloud: one vertex cell per point.
    pub fn point_cloud(points: Vec<[f64; 3]>) -> Self {
        let n = points.len() as u64;
        Self {
            points,
            connectivity: (0..n).collect(),
            offsets: (1..=n).collect(),
            types: vec![CellType::Vertex; n as usize],
            ..Self::default()
        }
    }

    /// The simplices of a mesh as lines, triangles or tetrahedra.
    pub fn from_mesh<const D: usize>(mesh: &SimplexMesh<D>) -> Self {
        let stride = (D + 1) as u64;
        let cells = mesh.simplex_count() as u64;
        Self {
            points: mesh.vertices().iter().map(pad_vector).collect(),
            connectivity: mesh.connectivity().iter().map(|&v| u64::from(v)).collect(),
            offsets: (1..=cells).map(|c| c * stride).collect(),
            types: vec![CellType::simplex(D).unwrap_or(CellType::Tetra); cells as usize],
            ..Self::default()
        }
    }

    /// Number of cells.
    pub fn cell_count(&self) -> usize {
        self.types.len()
    }

    fn field(name: &str, components: usize, values: FieldValues, entries: usize) -> Result<Field> {
        let found = match &values {
            FieldValues::Float64(v) => v.len(),
            FieldValues::Int32(v) => v.len(),
        };
        if components == 0 || found != entries * components {
            return Err(IoError::FieldLength {
                field: name.to_string(),
                found,
                expected: entries * components.max(1),
            });
        }
        Ok(Field {
            name: name.to_string(),
            components,
            values,
        })
    }

    /// Adds a float field with `components` values per point.
    pub fn add_point_field(
        &mut self,
        name: &str,
        components: usize,
        values: Vec<f64>,
    ) -> Result<()> {
        let field = Self::field(
            name,
            components,
            FieldValues::Float64(values),
            self.points.len(),
        )?;
        self.point_data.push(field);
        Ok(())
    }

    /// Adds an integer field with one value per point.
    pub fn add_point_ids(&mut self, name: &str, values: Vec<i32>) -> Result<()> {
        let field = Self::field(name, 1, FieldValues::Int32(values), self.points.len())?;
        self.point_data.push(field);
        Ok(())
    }

    /// Adds a float field with `components` values per cell.
    pub fn add_cell_field(
        &mut self,
        name: &str,
        components: usize,
        values: Vec<f64>,
    ) -> Result<()> {
        let field = Self::field(
            name,
            components,
            FieldValues::Float64(values),
            self.cell_count(),
        )?;
        self.cell_data.push(field);
        Ok(())
    }

    /// Adds an integer field with one value per cell.
    pub fn add_cell_ids(&mut self, name: &str, values: Vec<i32>) -> Result<()> {
        let field = Self::field(name, 1, FieldValues::Int32(values), self.cell_count())?;
        self.cell_data.push(field);
        Ok(())
    }

    /// Adds a D-vector per point, padded to 3 components.
    pub fn add_point_vectors<const D: usize>(
        &mut self,
        name: &str,
        vectors: &[SVector<f64, D>],
    ) -> Result<()> {
        let values = vectors.iter().flat_map(pad_vector).collect();
        self.add_point_field(name, 3, values)
    }

    /// Adds a D×D tensor per point, padded to 3×3.
    pub fn add_point_tensors<const D: usize>(
        &mut self,
        name: &str,
        tensors: &[SMatrix<f64, D, D>],
    ) -> Result<()> {
        let values = tensors.iter().flat_map(pad_tensor).collect();
        self.add_point_field(name, 9, values)
    }
}
