use core::fmt;

/// The key width a tree needs: 32 bits where its depth allows, 64 otherwise.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum KeyWidth {
    /// `u32` keys and trails: trees of depth at most 31.
    W32,
    /// `u64` keys and trails: trees of depth at most 63.
    W64,
}

impl KeyWidth {
    /// The narrowest width for a tree of the given depth (root: depth 0), or `None` past 63.
    pub fn for_depth(depth: u32) -> Option<KeyWidth> {
        match depth {
            0..=31 => Some(KeyWidth::W32),
            32..=63 => Some(KeyWidth::W64),
            _ => None,
        }
    }

    /// Bytes of one key (and of one bit trail).
    pub fn bytes(self) -> usize {
        match self {
            KeyWidth::W32 => 4,
            KeyWidth::W64 => 8,
        }
    }
}

impl fmt::Display for KeyWidth {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            KeyWidth::W32 => "32-bit",
            KeyWidth::W64 => "64-bit",
        })
    }
}
