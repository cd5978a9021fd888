//! Which traversal to run, grouped by the structure it traverses.
//!
//! Each structure has its own method enum ([`Bvh2Method`], [`KdMethod`]) and its entry points take
//! that enum, so a kd method cannot be handed to a BVH2 traversal: it does not compile. [`Method`]
//! names any method, for backends, reports and the command line; turning it into a structure's
//! method at run time ([`Bvh2Method::try_from`]) fails with [`Error::Unsupported`] rather than
//! tracing nothing.

mod bvh2;
mod kd;
mod query;
mod stream;
mod wide;

pub use bvh2::Bvh2Method;
pub use kd::KdMethod;
pub use query::Query;
pub use stream::StreamMethod;
pub use wide::{Collapse, WideMethod, WideTreeKind, WideWalk};

use crate::Error;
use core::fmt;

/// Any traversal method, by the structure it traverses. New structures (the wide BVH, the ray
/// stream) add variants, hence `non_exhaustive`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[non_exhaustive]
pub enum Method {
    /// A method of the binary BVH.
    Bvh2(Bvh2Method),
    /// A method of the kd-tree.
    Kd(KdMethod),
    /// A method of a wide BVH.
    Wide(WideMethod),
    /// A ray-stream method: the whole batch sorted into packets and traced by frustums.
    Stream(StreamMethod),
}

/// The acceleration structure a method traverses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Structure {
    /// The binary BVH.
    Bvh2,
    /// The kd-tree.
    Kd,
    /// A wide BVH collapsed from the binary one.
    Wide,
    /// The 8-wide BVH stored level by level, traversed by packet frustums.
    Levels,
}

impl Method {
    /// The BVH2 methods, as [`Method`]s.
    pub const BVH2: [Method; Bvh2Method::ALL.len()] = {
        let mut out = [Method::Bvh2(Bvh2Method::Stack); Bvh2Method::ALL.len()];
        let mut i = 0;
        while i < out.len() {
            out[i] = Method::Bvh2(Bvh2Method::ALL[i]);
            i += 1;
        }
        out
    };

    /// The kd-tree methods, as [`Method`]s.
    pub const KD: [Method; KdMethod::ALL.len()] = {
        let mut out = [Method::Kd(KdMethod::Stack); KdMethod::ALL.len()];
        let mut i = 0;
        while i < out.len() {
            out[i] = Method::Kd(KdMethod::ALL[i]);
            i += 1;
        }
        out
    };

    /// The wide-BVH methods, as [`Method`]s.
    pub const WIDE: [Method; WideMethod::ALL.len()] = {
        let mut out = [Method::Wide(WideMethod::BVH4); WideMethod::ALL.len()];
        let mut i = 0;
        while i < out.len() {
            out[i] = Method::Wide(WideMethod::ALL[i]);
            i += 1;
        }
        out
    };

    /// The stream methods, as [`Method`]s.
    pub const STREAM: [Method; StreamMethod::ALL.len()] = [Method::Stream(StreamMethod::Frustum8)];

    /// Every method: the BVH2 methods, the kd methods, the wide methods, then the stream methods.
    pub const ALL: [Method; Method::BVH2.len() + Method::KD.len() + Method::WIDE.len() + Method::STREAM.len()] = {
        let (b, k, w) = (Method::BVH2.len(), Method::KD.len(), Method::WIDE.len());
        let mut out = [Method::Bvh2(Bvh2Method::Stack);
            Method::BVH2.len() + Method::KD.len() + Method::WIDE.len() + Method::STREAM.len()];
        let mut i = 0;
        while i < out.len() {
            out[i] = if i < b {
                Method::BVH2[i]
            } else if i < b + k {
                Method::KD[i - b]
            } else if i < b + k + w {
                Method::WIDE[i - b - k]
            } else {
                Method::STREAM[i - b - k - w]
            };
            i += 1;
        }
        out
    };

    /// The structure the method traverses.
    pub fn structure(self) -> Structure {
        match self {
            Method::Bvh2(_) => Structure::Bvh2,
            Method::Kd(_) => Structure::Kd,
            Method::Wide(_) => Structure::Wide,
            Method::Stream(_) => Structure::Levels,
        }
    }

    /// Command-line name (unique over every method).
    pub fn name(self) -> &'static str {
        match self {
            Method::Bvh2(m) => m.name(),
            Method::Kd(m) => m.name(),
            Method::Wide(m) => m.name(),
            Method::Stream(m) => m.name(),
        }
    }

    /// The method of a command-line name, or of a former one that is still accepted
    /// ([`WideMethod::OLD_NAMES`]).
    pub fn from_name(name: &str) -> Option<Method> {
        Self::ALL.into_iter().find(|m| m.name() == name).or_else(|| WideMethod::from_name(name).map(Method::Wide))
    }

    /// The method whose node enumeration this one must equal, closest hit and any hit alike
    /// (for kd methods the enumeration is the sequence of leaves: restarts revisit inner nodes).
    /// A wide method is its own reference: each tree is its own, and its enumeration is checked
    /// against the scalar reference traversal of the same tree (the serial backend's) instead;
    /// but the stackless trail walk `bvh4-hash` must equal the stack traversal `bvh4` of its tree.
    /// So is a stream method, whose enumeration is its packets' leaf lists.
    pub fn reference(self) -> Method {
        match self {
            Method::Bvh2(m) => Method::Bvh2(m.reference()),
            Method::Kd(_) => Method::Kd(KdMethod::Stack),
            // The trail walk visits its stack twin's nodes, in its order.
            Method::Wide(WideMethod::BVH4_HASH) => Method::Wide(WideMethod::BVH4),
            Method::Wide(m) => Method::Wide(m),
            Method::Stream(m) => Method::Stream(m),
        }
    }

    /// Per-ray traversal state in bytes, beyond the ray and its answer: the registers the paper
    /// names, for a tree of the given depth and key width in bytes, as a hardware unit or a
    /// shader sized for this tree would hold them. (The Rust state types are larger: the stack
    /// is fixed at 64 entries so one type serves every tree.)
    pub fn state_bytes(self, depth: u32, key_bytes: usize) -> usize {
        match self {
            Method::Bvh2(m) => m.state_bytes(depth, key_bytes),
            Method::Kd(m) => m.state_bytes(depth),
            Method::Wide(m) => m.state_bytes(depth),
            Method::Stream(m) => m.state_bytes(),
        }
    }

    /// The BVH2 method, if this is one.
    pub fn bvh2(self) -> Option<Bvh2Method> {
        match self {
            Method::Bvh2(m) => Some(m),
            _ => None,
        }
    }

    /// The kd method, if this is one.
    pub fn kd(self) -> Option<KdMethod> {
        match self {
            Method::Kd(m) => Some(m),
            _ => None,
        }
    }

    /// The wide method, if this is one.
    pub fn wide(self) -> Option<WideMethod> {
        match self {
            Method::Wide(m) => Some(m),
            _ => None,
        }
    }

    /// The stream method, if this is one.
    pub fn stream(self) -> Option<StreamMethod> {
        match self {
            Method::Stream(m) => Some(m),
            _ => None,
        }
    }

    /// Whether the method needs the perfect hash over backtracking targets.
    pub fn needs_hash(self) -> bool {
        self.bvh2().is_some_and(Bvh2Method::needs_hash)
    }

    /// Whether the method needs the hash over every node (resuming from any key).
    pub fn needs_full_hash(self) -> bool {
        self.bvh2().is_some_and(Bvh2Method::needs_full_hash)
    }

    /// Whether the method needs the parent/sibling layout rather than the uncle layout.
    pub fn needs_parent_links(self) -> bool {
        self.bvh2().is_some_and(Bvh2Method::needs_parent_links)
    }
}

impl From<Bvh2Method> for Method {
    fn from(m: Bvh2Method) -> Method {
        Method::Bvh2(m)
    }
}

impl From<KdMethod> for Method {
    fn from(m: KdMethod) -> Method {
        Method::Kd(m)
    }
}

impl TryFrom<Method> for Bvh2Method {
    type Error = Error;
    /// The BVH2 method, or [`Error::Unsupported`] naming a method of another structure.
    fn try_from(m: Method) -> Result<Bvh2Method, Error> {
        m.bvh2().ok_or(Error::Unsupported { method: m.name(), by: "a BVH2 traversal" })
    }
}

impl From<WideMethod> for Method {
    fn from(m: WideMethod) -> Method {
        Method::Wide(m)
    }
}

impl TryFrom<Method> for WideMethod {
    type Error = Error;
    /// The wide method, or [`Error::Unsupported`] naming a method of another structure.
    fn try_from(m: Method) -> Result<WideMethod, Error> {
        m.wide().ok_or(Error::Unsupported { method: m.name(), by: "a wide-BVH traversal" })
    }
}

impl From<StreamMethod> for Method {
    fn from(m: StreamMethod) -> Method {
        Method::Stream(m)
    }
}

impl TryFrom<Method> for StreamMethod {
    type Error = Error;
    /// The stream method, or [`Error::Unsupported`] naming a method of another structure.
    fn try_from(m: Method) -> Result<StreamMethod, Error> {
        m.stream().ok_or(Error::Unsupported { method: m.name(), by: "a ray-stream traversal" })
    }
}

impl TryFrom<Method> for KdMethod {
    type Error = Error;
    /// The kd method, or [`Error::Unsupported`] naming a method of another structure.
    fn try_from(m: Method) -> Result<KdMethod, Error> {
        m.kd().ok_or(Error::Unsupported { method: m.name(), by: "a kd-tree traversal" })
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_round_trip() {
        for m in Method::ALL {
            assert_eq!(Method::from_name(m.name()), Some(m));
        }
        assert_eq!(Method::from_name("nope"), None);
        assert_eq!(
            Method::BVH2.len() + Method::KD.len() + Method::WIDE.len() + Method::STREAM.len(),
            Method::ALL.len()
        );
        assert_eq!((Method::ALL[0], Method::ALL[7]), (Method::Bvh2(Bvh2Method::Stack), Method::Kd(KdMethod::Stack)));
    }

    #[test]
    fn the_ray_list_walks_former_names_still_name_them() {
        assert_eq!(Method::from_name("bvh8-stream"), Some(Method::Wide(WideMethod::BVH8_LISTS)));
        assert_eq!(Method::from_name("bvh8-sah-stream"), Some(Method::Wide(WideMethod::BVH8_SAH_LISTS)));
        // The current names are the lists', and "stream" alone is still Garanzha & Loop's.
        assert_eq!(WideMethod::BVH8_LISTS.name(), "bvh8-lists");
        assert_eq!(Method::from_name("stream"), Some(Method::Stream(StreamMethod::Frustum8)));
    }

    #[test]
    fn the_results_page_knows_every_former_name() {
        // scripts/benchmarks_page.py shows results recorded under a former name under the current
        // one (its RENAMED list): each pair here must be there.
        let script = include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/../scripts/benchmarks_page.py"));
        for (old, m) in WideMethod::OLD_NAMES {
            let pair = std::format!("(\"{old}\", \"{}\")", m.name());
            assert!(script.contains(&pair), "scripts/benchmarks_page.py's RENAMED lacks {pair}");
        }
    }

    #[test]
    fn a_wide_method_is_a_tree_and_a_walk_of_those_that_exist() {
        for (i, m) in WideMethod::ALL.into_iter().enumerate() {
            assert_eq!(WideMethod::new(m.tree(), m.walk()), Ok(m));
            // Methods order as the list does.
            assert!(WideMethod::ALL[..i].iter().all(|&earlier| earlier < m), "{m}");
        }
        for (tree, walk) in [
            (WideTreeKind::Four, WideWalk::Packet),
            (WideTreeKind::FourNaive, WideWalk::Trail),
            (WideTreeKind::Eight, WideWalk::Trail),
            (WideTreeKind::EightSah, WideWalk::Trail),
        ] {
            assert!(matches!(WideMethod::new(tree, walk), Err(Error::Unsupported { .. })), "{tree:?} {walk:?}");
        }
    }

    #[test]
    fn a_method_of_another_structure_is_rejected_with_a_typed_error() {
        let kd = Method::Kd(KdMethod::Stack);
        assert_eq!(Bvh2Method::try_from(kd), Err(Error::Unsupported { method: "kd-stack", by: "a BVH2 traversal" }));
        assert_eq!(
            KdMethod::try_from(Method::Bvh2(Bvh2Method::Hash)),
            Err(Error::Unsupported { method: "hash", by: "a kd-tree traversal" })
        );
        assert_eq!(Bvh2Method::try_from(Method::Bvh2(Bvh2Method::Uncle)), Ok(Bvh2Method::Uncle));
    }

    #[test]
    fn references_stay_within_their_structure() {
        for m in Method::ALL {
            assert_eq!(m.reference().structure(), m.structure(), "{m}");
        }
    }
}
