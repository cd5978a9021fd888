//! Making any of the core's BVH2 state machines from a root, so a BVH2 lane can be started
//! whatever its method; the lane steps it through the core's own
//! [`Machine`](raytrail_core::traverse::Machine).

use raytrail_core::bvh2::traverse::{
    ParentSiblingState, PausingState, PerfectHashLookup, RegisterState, StackState, UncleHops,
};
use raytrail_core::bvh2::NodeRef;
use raytrail_core::key::Key;

/// A BVH2 traversal state that starts at a root node.
pub trait Start {
    /// A traversal starting at `root`.
    fn start(root: NodeRef) -> Self;
}

/// Implements [`Start`] by the state's own `new`.
macro_rules! start_by_new {
    (impl $(<$($g:ident: $b:path),*>)? for $t:ty) => {
        impl$(<$($g: $b),*>)? Start for $t {
            #[inline(always)]
            fn start(root: NodeRef) -> Self {
                <$t>::new(root)
            }
        }
    };
}

start_by_new!(impl for StackState<false>);
start_by_new!(impl for StackState<true>);
start_by_new!(impl<K: Key> for ParentSiblingState<K>);
start_by_new!(impl<K: Key> for RegisterState<K, UncleHops, false>);
start_by_new!(impl<K: Key> for RegisterState<K, PerfectHashLookup, false>);
start_by_new!(impl<K: Key> for RegisterState<K, PerfectHashLookup, true>);
start_by_new!(impl<K: Key> for PausingState<K>);
