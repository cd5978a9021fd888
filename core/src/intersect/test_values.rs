//! Adversarial inputs for the tests that hold a fast path to its reference bit for bit.

use super::{BoxHit, SlabRay};
use crate::Ray;

/// Values that recur exactly, so that planes and origins coincide.
const POOL: [f32; 4] = [0.5, -0.25, 1.0, 3.0];

/// A small deterministic generator (xorshift).
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Mostly ordinary values, with zeros of both signs, infinities, NaN, a subnormal and exact
    /// repeats from `pool`.
    pub fn value(&mut self, pool: &[f32]) -> f32 {
        match self.next() % 16 {
            0 => 0.0,
            1 => -0.0,
            2 => pool[(self.next() % pool.len() as u64) as usize],
            3 => [f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 1e-40][(self.next() % 4) as usize],
            _ => ((self.next() % 2001) as f32 - 1000.0) / 256.0,
        }
    }

    /// [`Rng::value`] over the shared pool of exact repeats.
    pub fn adversarial(&mut self) -> f32 {
        self.value(&POOL)
    }

    /// An adversarial ray (any of its values may be zero, infinite or NaN) and its slab constants
    /// with a slack of 0, 1e-5 or infinity.
    pub fn ray_and_slab(&mut self) -> (Ray, SlabRay) {
        let mut v = || self.adversarial();
        let ray = Ray { origin: [v(), v(), v()], tmin: v(), dir: [v(), v(), v()], tmax: v() };
        let slab = SlabRay { slack: [0.0, 1e-5, f32::INFINITY][(self.next() % 3) as usize], ..SlabRay::new(&ray) };
        (ray, slab)
    }
}

/// Whether two box answers are the same, bit for bit.
pub fn same(a: Option<BoxHit>, b: Option<BoxHit>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => a.t_enter.to_bits() == b.t_enter.to_bits() && a.t_exit.to_bits() == b.t_exit.to_bits(),
        _ => false,
    }
}
