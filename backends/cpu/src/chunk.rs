//! The unit of parallel work: one task's rays, hit slots and (when recorded) enumeration slots.

use raytrail_core::{Hit, Ray};

/// One chunk's rays, hit slots and enumeration slots (empty unless enumerations are recorded).
pub(crate) struct Chunk<'a> {
    pub rays: &'a [Ray],
    pub hits: &'a mut [Hit],
    pub enumerations: &'a mut [Vec<u32>],
}
