//! Random offsets for lattice-seeded particles (`[[bodies]] jitter`): each particle
//! moves within its own lattice cell, so a regular particle layout no longer lines up
//! with the background's cells. Which points belong to the body is decided before the
//! offsets, at the cell centres, so the particle count and volumes are the unjittered
//! lattice's. The offsets come from a counter-based hash (SplitMix64) of the seed and
//! the particle's index: the same scene and seed give the same particles on any machine
//! and thread count, and no random-number crate is needed for it.

use nalgebra::SVector;

/// Uniform offsets of up to `half_width` per axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jitter {
    half_width: f64,
    seed: u64,
}

impl Jitter {
    /// Offsets of up to `amount` × `spacing` / 2 per axis (`amount` in [0, 1]: at 1 a
    /// particle can reach its cell's faces).
    pub fn new(amount: f64, spacing: f64, seed: u64) -> Self {
        Self {
            half_width: 0.5 * amount * spacing,
            seed,
        }
    }

    /// The offset of the particle with this index among the body's particles, each
    /// component uniform in [−half width, half width).
    pub fn offset<const D: usize>(&self, index: usize) -> SVector<f64, D> {
        SVector::from_fn(|k, _| {
            let n = (index as u64).wrapping_mul(D as u64).wrapping_add(k as u64);
            (2.0 * unit(self.seed, n) - 1.0) * self.half_width
        })
    }
}

/// SplitMix64's output function: a bijective mix of all 64 bits.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A number in [0, 1) from the seed and a counter (the top 53 bits of the hash).
fn unit(seed: u64, n: u64) -> f64 {
    (mix(seed ^ mix(n)) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Offsets stay within the bound, fill it, average to zero, and depend on the seed.
    #[test]
    fn offsets_are_uniform_within_the_bound() {
        let jitter = Jitter::new(0.5, 0.1, 7);
        let bound = 0.025;
        let n = 20_000;
        let offsets: Vec<SVector<f64, 2>> = (0..n).map(|i| jitter.offset(i)).collect();
        let largest = offsets.iter().map(|o| o.amax()).fold(0.0, f64::max);
        assert!(largest < bound && largest > 0.999 * bound, "{largest}");
        let mean: SVector<f64, 2> = offsets.iter().sum::<SVector<f64, 2>>() / n as f64;
        // The mean of n uniform numbers has the deviation bound / √(3n) ≈ 1.0e-4.
        assert!(mean.amax() < 5e-4, "{mean:?}");
        // Uniform: a quarter of the components in each quarter of the range.
        let first_quarter = offsets
            .iter()
            .flat_map(|o| o.iter().copied())
            .filter(|&c| c < -0.5 * bound)
            .count() as f64
            / (2 * n) as f64;
        assert!((first_quarter - 0.25).abs() < 0.01, "{first_quarter}");
        assert_eq!(
            jitter.offset::<2>(123),
            Jitter::new(0.5, 0.1, 7).offset::<2>(123)
        );
        assert_ne!(
            jitter.offset::<2>(123),
            Jitter::new(0.5, 0.1, 8).offset::<2>(123)
        );
    }
}
