//! The error type of the core: every failure names what is wrong.

use core::fmt;

/// What can go wrong in the core. Library code returns these instead of panicking.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Error {
    /// A scene with no triangles was given where one is needed.
    EmptyScene,
    /// A triangle references a vertex that does not exist.
    VertexIndexOutOfRange {
        /// Triangle index.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices.
        vertex_count: usize,
    },
    /// A vertex has a NaN or infinite coordinate.
    NonFiniteVertex {
        /// Vertex index.
        vertex: usize,
    },
    /// The tree is deeper than 64-bit keys allow.
    TreeTooDeep {
        /// The tree's depth.
        depth: u32,
        /// The deepest its keys allow: 63 for a binary tree, 31 for a 4-wide one.
        max: u32,
    },
    /// Node or leaf addresses do not fit the 30 bits the node references reserve for them.
    TreeTooLarge {
        /// What overflowed.
        what: &'static str,
        /// Its size.
        size: usize,
    },
    /// A tree handed to [`crate::bvh2::Bvh2::from_nodes`] is malformed.
    MalformedTree(&'static str),
    /// A tree handed to [`crate::prepared::PreparedScene::new`] does not bound the scene it is
    /// given: it was built for other triangles (another scene, or this one before its vertices
    /// moved), and tracing it would miss what lies outside its boxes.
    TreeMismatch {
        /// The node whose box fails to hold what lies below it (its index in canonical order).
        node: usize,
        /// What does not fit.
        why: &'static str,
    },
    /// The hash tables could not be built within the table-size limit.
    HashConstruction {
        /// Number of keys.
        keys: usize,
        /// Largest table size tried.
        table_size: u64,
    },
    /// Rays and hit buffer lengths differ.
    BufferMismatch {
        /// Number of rays.
        rays: usize,
        /// Number of hit slots.
        hits: usize,
    },
    /// A method needs something the prepared scene was not built with.
    NotPrepared {
        /// The method.
        method: &'static str,
        /// What is missing.
        missing: &'static str,
    },
    /// A method was handed to something that cannot run it: a traversal of another structure,
    /// or a backend that does not implement it.
    Unsupported {
        /// The method.
        method: &'static str,
        /// What cannot run it.
        by: &'static str,
    },
    /// An instance of an instanced scene cannot be placed.
    InvalidInstance {
        /// Its position in the list of instances.
        index: usize,
        /// What is wrong with it.
        why: &'static str,
    },
    /// A parameter is out of its range.
    InvalidParameter {
        /// The parameter.
        name: &'static str,
        /// What it must be.
        why: &'static str,
    },
    /// A backend's device failed or lacks something (no adapter, a missing feature, a limit).
    #[cfg(feature = "alloc")]
    Device {
        /// The backend.
        backend: &'static str,
        /// What went wrong, in the backend's words.
        detail: alloc::string::String,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::EmptyScene => write!(f, "the scene has no triangles"),
            Error::VertexIndexOutOfRange { triangle, index, vertex_count } => {
                write!(f, "triangle {triangle} references vertex {index}, but there are only {vertex_count} vertices")
            }
            Error::NonFiniteVertex { vertex } => write!(f, "vertex {vertex} has a NaN or infinite coordinate"),
            Error::TreeTooDeep { depth, max } => {
                write!(f, "tree depth {depth} exceeds the {max} levels that 64-bit keys allow")
            }
            Error::TreeTooLarge { what, size } => {
                write!(f, "{what} ({size}) exceeds the 2^30 addresses node references allow")
            }
            Error::MalformedTree(why) => write!(f, "malformed tree: {why}"),
            Error::TreeMismatch { node, why } => {
                write!(f, "the tree was not built for this scene: node {node}: {why}")
            }
            Error::HashConstruction { keys, table_size } => {
                write!(f, "no perfect hash for {keys} keys up to table size {table_size}")
            }
            Error::BufferMismatch { rays, hits } => write!(f, "{rays} rays but {hits} hit slots"),
            Error::NotPrepared { method, missing } => {
                write!(f, "method {method} needs {missing}, which the scene was not prepared with")
            }
            Error::Unsupported { method, by } => write!(f, "method {method} is not supported by {by}"),
            Error::InvalidInstance { index, why } => write!(f, "instance {index}: {why}"),
            Error::InvalidParameter { name, why } => write!(f, "invalid {name}: {why}"),
            #[cfg(feature = "alloc")]
            Error::Device { backend, detail } => write!(f, "{backend} backend: {detail}"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for Error {}
