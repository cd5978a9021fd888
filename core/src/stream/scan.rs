//! The parallel primitives the stream method is built from (Sengupta et al. 2008, as Garanzha &
//! Loop use them), in their serial reference form: every backend's stages must give these arrays.

use alloc::vec::Vec;

/// The exclusive prefix sum of `values` (wrapping, as a GPU's `u32` adds) and the total.
pub fn exclusive_scan(values: &[u32]) -> (Vec<u32>, u32) {
    let mut sum = 0u32;
    let out = values
        .iter()
        .map(|&v| {
            let before = sum;
            sum = sum.wrapping_add(v);
            before
        })
        .collect();
    (out, sum)
}

/// The inclusive segmented prefix sum of `values` in place: the running sum restarts at every
/// position whose head flag is set.
pub fn segmented_inclusive_scan(values: &mut [u32], heads: &[bool]) {
    let mut sum = 0u32;
    for (v, &head) in values.iter_mut().zip(heads) {
        sum = if head { *v } else { sum.wrapping_add(*v) };
        *v = sum;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scans() {
        assert_eq!(exclusive_scan(&[3, 1, 4, 1]), (alloc::vec![0, 3, 4, 8], 9));
        assert_eq!(exclusive_scan(&[]), (alloc::vec![], 0));
        let mut v = [3, 1, 1, 9, 1, 1];
        segmented_inclusive_scan(&mut v, &[true, false, false, true, false, false]);
        assert_eq!(v, [3, 4, 5, 9, 10, 11]);
    }
}
