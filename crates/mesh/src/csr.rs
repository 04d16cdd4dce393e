//! Compressed sparse rows: a list of variable-length rows in two flat arrays.

use crate::error::MeshError;

/// `len` as a 32-bit offset, or the error naming the relation that outgrew it.
fn offset(len: usize, what: &'static str) -> Result<u32, MeshError> {
    u32::try_from(len).map_err(|_| MeshError::TooLarge { what, count: len })
}

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
    /// Builds from per-row vectors; `what` names the relation in the error when it has
    /// more entries than 32-bit offsets address.
    pub fn from_rows<I, R>(rows: I, what: &'static str) -> Result<Self, MeshError>
    where
        I: IntoIterator<Item = R>,
        R: IntoIterator<Item = T>,
    {
        let mut offsets = vec![0u32];
        let mut values = Vec::new();
        for row in rows {
            values.extend(row);
            offsets.push(offset(values.len(), what)?);
        }
        Ok(Self { offsets, values })
    }

    /// Builds from row lengths and the rows' values back to back.
    pub(crate) fn from_lengths(
        lengths: impl IntoIterator<Item = usize>,
        values: Vec<T>,
        what: &'static str,
    ) -> Result<Self, MeshError> {
        offset(values.len(), what)?;
        let mut offsets = vec![0u32];
        let mut end = 0usize;
        for len in lengths {
            end += len;
            offsets.push(offset(end, what)?);
        }
        if end != values.len() {
            return Err(MeshError::TooLarge { what, count: end });
        }
        Ok(Self { offsets, values })
    }

    /// Builds `rows` rows from `(row, value)` pairs sorted by row (values keep their
    /// order within a row); rows without pairs are empty.
    pub(crate) fn from_sorted_pairs(
        rows: usize,
        pairs: &[(u32, T)],
        what: &'static str,
    ) -> Result<Self, MeshError>
    where
        T: Copy,
    {
        offset(pairs.len(), what)?;
        let mut offsets = Vec::with_capacity(rows + 1);
        offsets.push(0u32);
        let mut next = 0usize;
        for row in 0..rows {
            while next < pairs.len() && pairs[next].0 as usize == row {
                next += 1;
            }
            offsets.push(next as u32);
        }
        Ok(Self {
            offsets,
            values: pairs[..next].iter().map(|&(_, v)| v).collect(),
        })
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_from_pairs_lengths_and_vectors_agree() {
        let pairs = [(0u32, 5u32), (0, 7), (2, 1), (3, 4), (3, 9)];
        let from_pairs = Csr::from_sorted_pairs(5, &pairs, "test").unwrap();
        let rows = [vec![5u32, 7], vec![], vec![1], vec![4, 9], vec![]];
        let from_rows = Csr::from_rows(rows.iter().cloned(), "test").unwrap();
        let from_lengths =
            Csr::from_lengths(rows.iter().map(Vec::len), vec![5, 7, 1, 4, 9], "test").unwrap();
        assert_eq!(from_pairs, from_rows);
        assert_eq!(from_lengths, from_rows);
        assert_eq!(from_pairs.row(3), &[4, 9]);
        assert!(from_pairs.row(4).is_empty());
        // Lengths that do not add up to the values are an error, not a bad row.
        assert!(Csr::from_lengths([1, 1], vec![1u32], "test").is_err());
    }
}
