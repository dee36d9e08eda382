//! The simulator's random generator: xoshiro256++ (Blackman and Vigna,
//! "Scrambled linear pseudorandom number generators", 2021), seeded through
//! SplitMix64 as its authors recommend. 256 bits of state, period
//! `2^256 - 1`, passes BigCrush and PractRand; a draw is a few shifts,
//! rotations and additions (ChaCha8, used before, cost about a fifth of a
//! simulator step). Not cryptographic, which noise does not need.
//!
//! It implements `rand`'s [`RngCore`] and [`SeedableRng`], so placement
//! draws go through `rand`'s usual conversions; the per-action noise takes
//! whole 64-bit words ([`Xoshiro256pp::next_u64`]) and cuts them into
//! 16-bit draws.

use rand::{RngCore, SeedableRng};

/// xoshiro256++.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Xoshiro256pp {
    s: [u64; 4],
}

/// One step of SplitMix64: the next state and its output.
fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl RngCore for Xoshiro256pp {
    #[inline]
    fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let out = s[0].wrapping_add(s[3]).rotate_left(23).wrapping_add(s[0]);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        out
    }

    /// The high half of a 64-bit draw (the better bits).
    #[inline]
    fn next_u32(&mut self) -> u32 {
        (self.next_u64() >> 32) as u32
    }

    fn fill_bytes(&mut self, dst: &mut [u8]) {
        for chunk in dst.chunks_mut(8) {
            let bytes = self.next_u64().to_le_bytes();
            chunk.copy_from_slice(&bytes[..chunk.len()]);
        }
    }
}

impl SeedableRng for Xoshiro256pp {
    type Seed = [u8; 32];

    /// The state from 32 little-endian bytes; the all-zero state (the one
    /// the generator cannot leave) is replaced by the state of seed 0.
    fn from_seed(seed: [u8; 32]) -> Xoshiro256pp {
        let mut s = [0u64; 4];
        for (w, b) in s.iter_mut().zip(seed.chunks_exact(8)) {
            let mut word = [0u8; 8];
            word.copy_from_slice(b);
            *w = u64::from_le_bytes(word);
        }
        if s == [0; 4] {
            return Xoshiro256pp::seed_from_u64(0);
        }
        Xoshiro256pp { s }
    }

    /// Four SplitMix64 outputs from `seed`: never all zero (SplitMix64's
    /// outputs of distinct states are distinct).
    fn seed_from_u64(seed: u64) -> Xoshiro256pp {
        let mut state = seed;
        let s =
            [splitmix64(&mut state), splitmix64(&mut state), splitmix64(&mut state), splitmix64(&mut state)];
        Xoshiro256pp { s }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_reference_implementation() {
        // The reference C code (xoshiro256plusplus.c) from the state
        // {1, 2, 3, 4}: its first outputs, worked by hand from the
        // algorithm (s0 + s3 = 5, rotl(5, 23) + 1 = 41943041).
        let mut r = Xoshiro256pp { s: [1, 2, 3, 4] };
        assert_eq!(r.next_u64(), 41_943_041);
        // The state after one step: t = 2 << 17; s2 = 3 ^ 1 = 2; s3 = 4 ^ 2
        // = 6; s1 = 2 ^ 2 = 0; s0 = 1 ^ 6 = 7; s2 = 2 ^ 262144; s3 = rotl(6, 45).
        assert_eq!(r.s, [7, 0, 262_146, 6u64.rotate_left(45)]);
    }

    #[test]
    fn splitmix_seeding_matches_its_reference() {
        // SplitMix64 from state 0: its first output is 0xe220a8397b1dcdaf.
        let mut state = 0u64;
        assert_eq!(splitmix64(&mut state), 0xe220_a839_7b1d_cdaf);
        let r = Xoshiro256pp::seed_from_u64(0);
        assert_eq!(r.s[0], 0xe220_a839_7b1d_cdaf);
        assert_eq!(Xoshiro256pp::from_seed([0; 32]), r);
    }

    #[test]
    fn draws_are_uniform_enough() {
        // 16 bins of the top 4 bits over 64,000 draws: each within 5% of
        // its expected 4,000 (a broken rotation or shift fails this).
        let mut r = Xoshiro256pp::seed_from_u64(42);
        let mut bins = [0u32; 16];
        for _ in 0..64_000 {
            bins[(r.next_u64() >> 60) as usize] += 1;
        }
        assert!(bins.iter().all(|&b| (3800..=4200).contains(&b)), "{bins:?}");
        let mut low = [0u32; 16];
        for _ in 0..64_000 {
            low[(r.next_u64() & 15) as usize] += 1;
        }
        assert!(low.iter().all(|&b| (3800..=4200).contains(&b)), "{low:?}");
    }
}
