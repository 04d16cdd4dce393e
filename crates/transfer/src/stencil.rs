//! The port's stencil: what a kernel hands the transfers for one particle.

use nalgebra::SVector;

/// One particle's stencil: node indices, shape-function values N_i, gradients ∇N_i and
/// the node offsets x_i − x_p.
///
/// The storage grows as needed (no cap a kernel inherits); reuse one stencil across
/// evaluations, and once it has grown to the largest stencil nothing is allocated. The
/// offsets are part of the port because the affine transfers need them for every node,
/// and a kernel knows them cheaply (a B-spline from its base node, a mesh kernel from
/// its vertex array) where recovering a node's position from its index would not be
/// (integer division on a grid).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stencil<const D: usize> {
    nodes: Vec<u32>,
    values: Vec<f64>,
    gradients: Vec<SVector<f64, D>>,
    offsets: Vec<SVector<f64, D>>,
}

impl<const D: usize> Stencil<D> {
    /// An empty stencil.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty stencil with room for `entries` nodes.
    pub fn with_capacity(entries: usize) -> Self {
        Self {
            nodes: Vec::with_capacity(entries),
            values: Vec::with_capacity(entries),
            gradients: Vec::with_capacity(entries),
            offsets: Vec::with_capacity(entries),
        }
    }

    /// Empties the stencil, keeping its storage.
    #[inline]
    pub fn clear(&mut self) {
        self.nodes.clear();
        self.values.clear();
        self.gradients.clear();
        self.offsets.clear();
    }

    /// Appends node `node` with its value N, gradient ∇N and offset x_node − x_p.
    #[inline]
    pub fn push(
        &mut self,
        node: u32,
        value: f64,
        gradient: SVector<f64, D>,
        offset: SVector<f64, D>,
    ) {
        self.nodes.push(node);
        self.values.push(value);
        self.gradients.push(gradient);
        self.offsets.push(offset);
    }

    /// Resizes the stencil to `len` entries and hands out its node, value, gradient and
    /// offset arrays to be written in place (faster than [`Self::push`] for a kernel
    /// that knows its stencil size up front). Entries keep whatever they held.
    #[inline]
    pub fn entries_mut(&mut self, len: usize) -> EntriesMut<'_, D> {
        self.nodes.resize(len, 0);
        self.values.resize(len, 0.0);
        self.gradients.resize(len, SVector::zeros());
        self.offsets.resize(len, SVector::zeros());
        EntriesMut {
            nodes: &mut self.nodes,
            values: &mut self.values,
            gradients: &mut self.gradients,
            offsets: &mut self.offsets,
        }
    }

    /// Number of nodes.
    #[inline]
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the stencil has no nodes.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Node indices.
    #[inline]
    pub fn nodes(&self) -> &[u32] {
        &self.nodes
    }

    /// Shape-function values, one per node.
    #[inline]
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Shape-function gradients, one per node.
    #[inline]
    pub fn gradients(&self) -> &[SVector<f64, D>] {
        &self.gradients
    }

    /// Node offsets x_i − x_p, one per node.
    #[inline]
    pub fn offsets(&self) -> &[SVector<f64, D>] {
        &self.offsets
    }

    /// The smallest and largest node index (`None` when empty).
    pub fn node_range(&self) -> Option<(u32, u32)> {
        node_range(&self.nodes)
    }

    /// Iterator over (node, N_i, ∇N_i).
    pub fn iter(&self) -> impl Iterator<Item = (u32, f64, &SVector<f64, D>)> + '_ {
        self.nodes
            .iter()
            .zip(&self.values)
            .zip(&self.gradients)
            .map(|((&n, &v), g)| (n, v, g))
    }
}

/// A stencil's arrays, all of one length, for writing in place
/// ([`Stencil::entries_mut`]).
#[derive(Debug)]
pub struct EntriesMut<'a, const D: usize> {
    /// Node indices.
    pub nodes: &'a mut [u32],
    /// Shape-function values.
    pub values: &'a mut [f64],
    /// Shape-function gradients.
    pub gradients: &'a mut [SVector<f64, D>],
    /// Node offsets x_i − x_p.
    pub offsets: &'a mut [SVector<f64, D>],
}

/// The smallest and largest of a stencil's `nodes` (`None` when empty): what
/// [`Stencil::node_range`] gives, for nodes an engine keeps in arrays of its own.
pub fn node_range(nodes: &[u32]) -> Option<(u32, u32)> {
    let lo = nodes.iter().copied().min()?;
    let hi = nodes.iter().copied().max()?;
    Some((lo, hi))
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector2;

    use super::*;

    #[test]
    fn entries_stay_aligned_and_storage_is_reused() {
        let mut st = Stencil::<2>::with_capacity(2);
        st.push(7, 0.25, Vector2::new(1.0, 0.0), Vector2::new(0.5, 0.0));
        st.push(3, 0.75, Vector2::new(-1.0, 0.0), Vector2::new(-0.5, 0.0));
        assert_eq!(st.len(), 2);
        assert_eq!(st.nodes(), &[7, 3]);
        assert_eq!(st.values(), &[0.25, 0.75]);
        assert_eq!(st.offsets()[1], Vector2::new(-0.5, 0.0));
        assert_eq!(st.node_range(), Some((3, 7)));
        let (node, value, gradient) = st.iter().nth(1).unwrap();
        assert_eq!((node, value, *gradient), (3, 0.75, Vector2::new(-1.0, 0.0)));
        let capacity = st.nodes.capacity();
        st.clear();
        assert!(st.is_empty());
        assert_eq!(st.node_range(), None);
        assert_eq!(st.nodes.capacity(), capacity);
        // No cap: a stencil grows past any fixed size.
        for k in 0..1000 {
            st.push(k, 1e-3, Vector2::zeros(), Vector2::zeros());
        }
        assert_eq!(st.len(), 1000);
        // Written in place: the arrays have the asked length, and shrink back.
        let entries = st.entries_mut(3);
        assert_eq!(entries.nodes.len(), 3);
        entries.values.copy_from_slice(&[0.2, 0.3, 0.5]);
        assert_eq!(st.len(), 3);
        assert_eq!(st.values(), &[0.2, 0.3, 0.5]);
        assert_eq!(st.offsets().len(), 3);
    }
}
