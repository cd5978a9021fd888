//! A small deterministic generator for the AVX paths' tests.

/// xorshift64.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Mostly ordinary values in [-4, 4], with zeros of both signs and exact repeats.
    pub(crate) fn value(&mut self) -> f32 {
        match self.next() % 12 {
            0 => 0.0,
            1 => -0.0,
            2 => 1.0,
            _ => ((self.next() >> 8) % 4001) as f32 / 500.0 - 4.0,
        }
    }
}
