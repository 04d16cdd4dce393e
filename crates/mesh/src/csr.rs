//! Compressed sparse rows: a list of variable-length rows in two flat arrays.

/// Rows of `T` stored back to back; row `i` is `values[offsets[i]..offsets[i + 1]]`.
///
/// Used for every one-to-many relation of the mesh (vertex adjacency,
/// vertex-to-simplex incidence, 1-rings), so that a lookup is two loads and a
/// slice, with no per-row allocation.
#[derive(Debug, Clone, PartialEq)]
pub struct Csr<T> {
    offsets: Vec<u32>,
    values: Vec<T>,
}

impl<T> Csr<T> {
    /// Builds from per-row vectors.
    pub fn from_rows<I, R>(rows: I) -> Self
    where
        I: IntoIterator<Item = R>,
        R: IntoIterator<Item = T>,
    {
        let mut offsets = vec![0u32];
        let mut values = Vec::new();
        for row in rows {
            values.extend(row);
            offsets.push(u32::try_from(values.len()).expect("CSR larger than u32 range"));
        }
        Self { offsets, values }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Row `i`.
    #[inline]
    pub fn row(&self, i: usize) -> &[T] {
        &self.values[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// Iterator over all rows in order.
    pub fn rows(&self) -> impl ExactSizeIterator<Item = &[T]> + '_ {
        (0..self.len()).map(move |i| self.row(i))
    }

    /// Total number of stored values.
    pub fn nnz(&self) -> usize {
        self.values.len()
    }
}
