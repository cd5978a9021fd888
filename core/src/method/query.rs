/// What a ray asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Query {
    /// The closest hit (ties to the smaller primitive id).
    Closest,
    /// Whether anything is hit (occlusion); the hit reported is the first one found.
    Any,
}

impl Query {
    /// Both queries, closest first.
    pub const ALL: [Query; 2] = [Query::Closest, Query::Any];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Query::Closest => "closest",
            Query::Any => "any",
        }
    }

    /// Whether the query stops at the first hit.
    pub fn is_any(self) -> bool {
        self == Query::Any
    }
}
