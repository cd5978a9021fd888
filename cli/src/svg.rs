//! What the hand-written SVG plots (the bench's, `accuracy`'s) share.

/// `s` with the XML special characters escaped, for text and attribute values.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}
