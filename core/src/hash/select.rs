use crate::bvh2::{Bvh2, NodeKind};
use alloc::vec::Vec;

/// Which nodes' keys go into the hash.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum HashCoverage {
    /// Only the backtracking targets the register cannot always serve (constant-time
    /// backtracking, methods d and e).
    Backtracking,
    /// Every node, so traversal can resume from any key alone (Sec. 2.4, method f).
    All,
}

/// Canonical indices of the nodes whose keys must be hashed.
///
/// A backtracking target `X` (any non-root node) is reached from the last node `Z` processed
/// before it, which lies in the subtree of `X`'s sibling `C`. If the register is empty there, `Z`
/// loads it from its links: an internal `Z` knows the siblings of its ancestors one and two levels
/// up (uncle, grand uncle), a leaf also three levels up (Fig. 5). So `X` needs the hash only if
/// some `Z` lies three or more levels below `X`'s level as an internal node, or four or more as a
/// leaf; both happen exactly when `C`'s subtree holds an internal node three levels below `C`.
///
/// The paper's rule ("a grand nephew which is an internal node, or a grand grand nephew that is a
/// leaf") is the same argument for leaves that load only uncle and grand uncle, as its
/// Algorithm 1 does; with the third leaf link its text describes, one level less needs hashing.
/// The conformance suite checks the rule: an unhashed target would break the enumeration.
pub fn keys_to_hash(bvh: &Bvh2, coverage: HashCoverage) -> Vec<u32> {
    let nodes = bvh.nodes();
    if coverage == HashCoverage::All {
        return (0..nodes.len() as u32).collect();
    }
    // Deepest internal node below each node, in levels relative to it (-1: a leaf).
    // Children follow parents in pre-order, so a reverse sweep sees children first.
    let mut internal_height = alloc::vec![-1i32; nodes.len()];
    for (i, n) in nodes.iter().enumerate().rev() {
        if let NodeKind::Internal { left, right } = n.kind {
            internal_height[i] = 1 + internal_height[left as usize].max(internal_height[right as usize]);
        }
    }
    let mut out = Vec::new();
    for n in nodes {
        if let NodeKind::Internal { left, right } = n.kind {
            if internal_height[right as usize] >= 3 {
                out.push(left);
            }
            if internal_height[left as usize] >= 3 {
                out.push(right);
            }
        }
    }
    out.sort_unstable();
    out
}
