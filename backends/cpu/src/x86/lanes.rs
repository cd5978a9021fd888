//! Lane helpers the packet walk's files share: a mask of picked lanes, a fold over the lanes.

use std::arch::x86_64::{
    __m256, _mm256_and_si256, _mm256_castps256_ps128, _mm256_castsi256_ps, _mm256_cmpeq_epi32, _mm256_extractf128_ps,
    _mm256_set1_epi32, _mm256_setr_epi32, _mm_cvtss_f32, _mm_max_ps, _mm_max_ss, _mm_min_ps, _mm_min_ss, _mm_movehl_ps,
    _mm_shuffle_ps,
};

/// The lanes picked by the low 8 bits of `group` (bit `k`: lane `k`), as an all-ones mask per
/// picked lane.
///
/// # Safety
/// The processor must support AVX2.
#[target_feature(enable = "avx2")]
#[inline]
pub(crate) unsafe fn lanes_of(group: u32) -> __m256 {
    // Bit k of a lane's own constant.
    let bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(group as i32), bits), bits))
}

/// Which way [`horizontal`] folds.
#[derive(Clone, Copy)]
pub(crate) enum Fold {
    /// To the least lane.
    Min,
    /// To the greatest lane.
    Max,
}

/// The least or greatest of `v`'s eight lanes (none is NaN).
///
/// # Safety
/// The processor must support AVX.
#[target_feature(enable = "avx")]
#[inline]
pub(crate) unsafe fn horizontal(v: __m256, fold: Fold) -> f32 {
    let (low, high) = (_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v));
    match fold {
        Fold::Min => {
            let h = _mm_min_ps(low, high);
            let h = _mm_min_ps(h, _mm_movehl_ps(h, h));
            _mm_cvtss_f32(_mm_min_ss(h, _mm_shuffle_ps::<1>(h, h)))
        }
        Fold::Max => {
            let h = _mm_max_ps(low, high);
            let h = _mm_max_ps(h, _mm_movehl_ps(h, h));
            _mm_cvtss_f32(_mm_max_ss(h, _mm_shuffle_ps::<1>(h, h)))
        }
    }
}
