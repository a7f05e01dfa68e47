//! Seeded randomness. Every run takes one `u64` seed; independent parts of a run (a trial, an
//! object, a reading) derive their own stream from it with [`substream`], so results do not depend
//! on the order or the thread in which the parts run.

use rand::SeedableRng;

/// The one random generator of the project: ChaCha8 is portable and stable across platforms and
/// `rand` versions, so the same seed gives the same results bit for bit.
pub type Rng = rand_chacha::ChaCha8Rng;

/// A generator seeded from `seed`.
pub fn rng(seed: u64) -> Rng {
    Rng::seed_from_u64(seed)
}

/// The seed of stream `index` of a run seeded with `seed` (SplitMix64 finaliser over both words),
/// so that streams are decorrelated and independent of how many other streams exist.
pub fn substream(seed: u64, index: u64) -> u64 {
    let mut z = seed ^ index.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A generator for stream `index` of the run seeded with `seed`.
pub fn stream(seed: u64, index: u64) -> Rng {
    rng(substream(seed, index))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    #[test]
    fn same_seed_same_draws_and_streams_differ() {
        let a: Vec<u64> = (0..8)
            .map(|_| 0)
            .scan(stream(7, 3), |r, _| Some(r.random::<u64>()))
            .collect();
        let b: Vec<u64> = (0..8)
            .map(|_| 0)
            .scan(stream(7, 3), |r, _| Some(r.random::<u64>()))
            .collect();
        let c: Vec<u64> = (0..8)
            .map(|_| 0)
            .scan(stream(7, 4), |r, _| Some(r.random::<u64>()))
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_ne!(substream(0, 0), substream(0, 1));
        assert_ne!(substream(0, 1), substream(1, 0));
    }
}
