//! The fuzzer's one source of randomness: SplitMix64, seeded per input.
//!
//! Every input is a pure function of `(seed, target, iteration)`
//! ([`Rng::for_input`]), never of the inputs before it: a worker restarted
//! after a crash at iteration `i` goes on with `i + 1` exactly as an
//! uninterrupted one would, and any reported input can be regenerated from
//! its three numbers.

/// A SplitMix64 generator (Steele, Lea & Flood 2014): tiny, fast, and
/// good enough to pick mutations; not for cryptography.
#[derive(Debug, Clone)]
pub struct Rng(u64);

/// FNV-1a over the bytes: a stable hash of a target's name (the standard
/// library's hasher may change between Rust releases, which would change
/// every input of a given seed).
fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// The SplitMix64 output function, also used to spread seeds.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Rng {
    /// A generator from a plain seed.
    pub fn new(seed: u64) -> Rng {
        Rng(mix(seed))
    }

    /// The generator of one input: depends on the run's seed, the target's
    /// name and the input's iteration number, and on nothing else.
    pub fn for_input(seed: u64, target: &str, iteration: u64) -> Rng {
        Rng(mix(seed ^ fnv1a(target.as_bytes())) ^ mix(iteration.wrapping_add(0x5eed)))
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        mix(self.0)
    }

    /// A number in `0..n`; 0 when `n` is 0, so callers need no special case
    /// for empty inputs.
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            return 0;
        }
        // The modulo bias is at most n / 2^64: irrelevant for picking mutations.
        (self.next_u64() % n as u64) as usize
    }

    /// True with probability `percent` / 100.
    pub fn chance(&mut self, percent: u32) -> bool {
        self.below(100) < percent as usize
    }

    /// One element of a slice, `None` when it is empty.
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> Option<&'a T> {
        if items.is_empty() {
            None
        } else {
            items.get(self.below(items.len()))
        }
    }

    /// 32 random bytes: the seed of a proptest `TestRng` (ChaCha).
    pub fn seed32(&mut self) -> [u8; 32] {
        let mut out = [0u8; 32];
        for chunk in out.chunks_mut(8) {
            chunk.copy_from_slice(&self.next_u64().to_le_bytes());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inputs_depend_only_on_seed_target_and_iteration() {
        let a: Vec<u64> = (0..4)
            .map(|_| Rng::for_input(7, "fol", 12).next_u64())
            .collect();
        assert!(a.windows(2).all(|w| w[0] == w[1]));
        assert_ne!(
            Rng::for_input(7, "fol", 12).next_u64(),
            Rng::for_input(7, "fol", 13).next_u64()
        );
        assert_ne!(
            Rng::for_input(7, "fol", 12).next_u64(),
            Rng::for_input(7, "query", 12).next_u64()
        );
        assert_ne!(
            Rng::for_input(7, "fol", 12).next_u64(),
            Rng::for_input(8, "fol", 12).next_u64()
        );
    }

    #[test]
    fn below_stays_in_range_and_handles_zero() {
        let mut r = Rng::new(1);
        assert_eq!(r.below(0), 0);
        assert!((0..1000).all(|_| r.below(7) < 7));
        assert_eq!(r.pick::<u8>(&[]), None);
    }
}
