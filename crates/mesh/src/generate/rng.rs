//! SplitMix64: a tiny, seedable generator for jitter.
//!
//! Generated meshes must be reproducible from a seed across platforms and crate
//! versions; a ten-line generator with a fixed algorithm guarantees that without
//! adding a random-number crate to the mesh crate's dependencies.

pub(crate) struct SplitMix64(u64);

impl SplitMix64 {
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed)
    }

    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [−1, 1).
    pub(crate) fn symmetric_unit(&mut self) -> f64 {
        // 53 random bits → [0, 1), then affine to [−1, 1).
        let unit = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        2.0 * unit - 1.0
    }
}
