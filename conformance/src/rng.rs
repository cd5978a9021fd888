//! A small deterministic random number generator for scenes and ray sets.
//!
//! The suite must produce the same scenes and rays on every machine and every run, so it uses its
//! own generator (PCG32, O'Neill 2014: a 64-bit LCG with a permuted 32-bit output) rather than a
//! crate whose stream could change between versions. Everything drawn from it uses only `+ - * /`
//! and `sqrt` (correctly rounded in IEEE 754), never `sin`, `cos` or `pow`, whose results differ
//! between platforms' math libraries: the same seed gives the same bits everywhere.

use glam::Vec3;

/// PCG32 (XSH-RR variant): 64-bit state, 32-bit output, selectable stream.
#[derive(Clone, Debug)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
}

impl Pcg32 {
    /// LCG multiplier (Knuth's MMIX constant, as in the PCG reference).
    const MUL: u64 = 6_364_136_223_846_793_005;

    /// A generator for `seed` on stream `stream`; different streams give independent sequences.
    pub fn new(seed: u64, stream: u64) -> Self {
        // The increment must be odd; seeding follows the reference procedure.
        let mut rng = Pcg32 { state: 0, inc: (stream << 1) | 1 };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    /// Next 32 uniformly distributed bits.
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(Self::MUL).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Next 64 uniformly distributed bits.
    pub fn next_u64(&mut self) -> u64 {
        (u64::from(self.next_u32()) << 32) | u64::from(self.next_u32())
    }

    /// Uniform in `[0, 1)`, with 24 random bits (every value exactly representable).
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// Uniform in `[lo, hi)` (or `lo` when the range is empty).
    pub fn range_f32(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f32()
    }

    /// Uniform integer in `[0, n)`; `n` must be positive.
    pub fn below(&mut self, n: u32) -> u32 {
        assert!(n > 0, "Pcg32::below(0)");
        // Lemire's multiply-shift with rejection: unbiased and division-free on the fast path.
        let mut m = u64::from(self.next_u32()) * u64::from(n);
        if (m as u32) < n {
            let threshold = n.wrapping_neg() % n;
            while (m as u32) < threshold {
                m = u64::from(self.next_u32()) * u64::from(n);
            }
        }
        (m >> 32) as u32
    }

    /// Uniform index into a slice of length `len` (positive).
    pub fn index(&mut self, len: usize) -> usize {
        self.below(u32::try_from(len).expect("index range fits in u32")) as usize
    }

    /// Uniform point in the box `[lo, hi)`.
    pub fn in_box(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
        Vec3::new(self.range_f32(lo.x, hi.x), self.range_f32(lo.y, hi.y), self.range_f32(lo.z, hi.z))
    }

    /// Uniform direction on the unit sphere: a uniform point of the unit ball (by rejection from
    /// the cube), normalized.
    pub fn unit_vector(&mut self) -> Vec3 {
        loop {
            let p = self.in_box(Vec3::splat(-1.0), Vec3::splat(1.0));
            let l2 = p.length_squared();
            // Tiny vectors would amplify the grid of the 24-bit coordinates; reject them too.
            if l2 <= 1.0 && l2 > 1e-4 {
                return p / l2.sqrt();
            }
        }
    }

    /// Uniform point of the unit disk `x^2 + y^2 < 1` (by rejection from the square).
    pub fn in_unit_disk(&mut self) -> (f32, f32) {
        loop {
            let (x, y) = (self.range_f32(-1.0, 1.0), self.range_f32(-1.0, 1.0));
            if x * x + y * y < 1.0 {
                return (x, y);
            }
        }
    }

    /// Fisher-Yates shuffle.
    pub fn shuffle<T>(&mut self, items: &mut [T]) {
        for i in (1..items.len()).rev() {
            let j = self.index(i + 1);
            items.swap(i, j);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_stream() {
        let mut a = Pcg32::new(42, 7);
        let mut b = Pcg32::new(42, 7);
        for _ in 0..100 {
            assert_eq!(a.next_u32(), b.next_u32());
        }
        let mut c = Pcg32::new(42, 8);
        let (xs, ys): (Vec<u32>, Vec<u32>) = (0..8).map(|_| (a.next_u32(), c.next_u32())).unzip();
        assert_ne!(xs, ys);
    }

    #[test]
    fn ranges_hold() {
        let mut r = Pcg32::new(1, 1);
        for _ in 0..10_000 {
            let f = r.next_f32();
            assert!((0.0..1.0).contains(&f));
            assert!(r.below(7) < 7);
            let u = r.unit_vector();
            assert!((u.length() - 1.0).abs() < 1e-5);
            let (x, y) = r.in_unit_disk();
            assert!(x * x + y * y < 1.0);
        }
    }

    #[test]
    fn below_covers_all_values() {
        let mut r = Pcg32::new(3, 0);
        let mut seen = [false; 5];
        for _ in 0..200 {
            seen[r.below(5) as usize] = true;
        }
        assert!(seen.iter().all(|&s| s));
    }
}
