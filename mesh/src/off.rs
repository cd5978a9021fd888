//! OFF (Object File Format, as Geomview, CGAL and the shape benchmarks write it), ASCII.
//!
//! ```text
//! OFF                      optional keyword: [ST][C][N]OFF (texture coordinates, colors and
//! 8 6 0                      normals after each vertex's x y z; read past)
//! -0.5 -0.5 0.5            one vertex per line: x y z, then anything the keyword adds
//! ...
//! 4 0 1 3 2                one face per line: n, then n vertex indices (0-based), then an
//! ...                        optional color (read past)
//! ```
//!
//! The counts line holds the vertex and face counts and, optionally, the edge count (ignored); it
//! may follow the keyword on its line. `#` starts a comment anywhere; blank lines are skipped.
//! Polygons are split as fans. Faces of fewer than three vertices are skipped and counted, or
//! rejected when loading is strict. The 4D and n-dimensional variants (`4OFF`, `nOFF`) and binary
//! OFF are rejected with an error. The source of a triangle is its face's index
//! ([`Source::Face`]).

use super::{show, words, LoadOptions, LoadReport, MeshError, Source, MAX_TRIANGLES, MAX_VERTICES};
use glam::Vec3;
use raytrail_core::scene::Mesh;
use std::format;
use std::string::String;
use std::vec::Vec;

/// Whether the data starts with an OFF keyword (after blank space and comments).
pub(super) fn has_magic(data: &[u8]) -> bool {
    let mut lines = Lines::new(data);
    lines.next().and_then(|(_, line)| words(line).next()).is_some_and(|w| keyword(w).is_some())
}

/// What the keyword says: `Ok(())` for a 3D OFF we read, an error message for variants we do not.
fn keyword(word: &[u8]) -> Option<Result<(), &'static str>> {
    let rest = word.strip_prefix(b"ST").unwrap_or(word);
    let rest = rest.strip_prefix(b"C").unwrap_or(rest);
    let rest = rest.strip_prefix(b"N").unwrap_or(rest);
    let (rest, dims) = match rest {
        [b'4', rest @ ..] => (rest, true),
        [b'n', rest @ ..] => (rest, true),
        _ => (rest, false),
    };
    if !rest.eq_ignore_ascii_case(b"OFF") {
        return None;
    }
    Some(if dims { Err("4D and n-dimensional OFF (4OFF, nOFF) are not supported") } else { Ok(()) })
}

/// Parses OFF text; `name` is used in errors.
pub(super) fn parse(data: &[u8], name: &str, options: &LoadOptions) -> Result<(Mesh, LoadReport), MeshError> {
    let mut lines = Lines::new(data);
    let at = |line: usize, msg: String| MeshError::at_line(name, line, msg);

    // Keyword (optional) and counts, which may share its line.
    let Some((mut line_no, mut line)) = lines.next() else {
        return Err(MeshError::at_line(name, lines.last_line(), "no OFF keyword or counts (only comments)"));
    };
    let mut w: Vec<&[u8]> = words(line).collect();
    if let Some(kind) = keyword(w[0]) {
        kind.map_err(|msg| at(line_no, msg.into()))?;
        if w.get(1).is_some_and(|b| b.eq_ignore_ascii_case(b"BINARY")) {
            return Err(at(line_no, "binary OFF is not supported".into()));
        }
        if w.len() == 1 {
            (line_no, line) = lines
                .next()
                .ok_or_else(|| at(lines.last_line(), "file ends before the vertex and face counts".into()))?;
            w = words(line).collect();
        } else {
            w.remove(0);
        }
    }
    let count = |word: &[u8]| std::str::from_utf8(word).ok().and_then(|s| s.parse::<u64>().ok());
    let counts: Option<Vec<u64>> = w.iter().map(|&word| count(word)).collect();
    let (vertices, faces) = match counts.as_deref() {
        Some(&[v, f]) | Some(&[v, f, _]) => (v, f),
        _ => {
            let msg = format!("expected `<vertices> <faces> [<edges>]`, found {:?}", show(line.trim_ascii()));
            return Err(at(line_no, msg));
        }
    };
    if vertices > MAX_VERTICES {
        return Err(at(line_no, format!("{vertices} vertices: more than 2^32")));
    }

    let mut mesh = Mesh::default();
    let mut report = LoadReport::default();
    // Reserve what the counts claim, but no more than the data could hold (hostile counts): a
    // vertex line takes at least 6 bytes, a face line at least 8.
    mesh.positions.reserve((vertices as usize).min(data.len() / 6));
    mesh.triangles.reserve((faces as usize).min(data.len() / 8));

    for k in 0..vertices {
        let (line_no, line) =
            lines.next().ok_or_else(|| at(lines.last_line(), format!("file ends after {k} of {vertices} vertices")))?;
        let mut xyz = [0f32; 3];
        let mut w = words(line);
        for (axis, c) in ["x", "y", "z"].into_iter().zip(&mut xyz) {
            let word = w.next().ok_or_else(|| at(line_no, format!("vertex {k}: no {axis} coordinate")))?;
            *c = std::str::from_utf8(word)
                .ok()
                .and_then(|s| s.parse().ok())
                .ok_or_else(|| at(line_no, format!("vertex {k}: {axis} is not a number: {:?}", show(word))))?;
        }
        mesh.positions.push(Vec3::from_array(xyz));
    }

    for f in 0..faces {
        let (line_no, line) =
            lines.next().ok_or_else(|| at(lines.last_line(), format!("file ends after {f} of {faces} faces")))?;
        let here = |msg: String| at(line_no, format!("face {f}: {msg}"));
        let mut w = words(line);
        let first = w.next().unwrap_or_default();
        let n = count(first).ok_or_else(|| here(format!("the vertex count is not a count: {:?}", show(first))))?;
        if n < 3 {
            if options.strict {
                return Err(here(format!("face has {n} vertices; a face needs at least 3")));
            }
            report.skip(|| format!("face {f} (line {line_no})"), || format!("a face with {n} vertices"));
            continue;
        }
        let mut index = |i: u64| -> Result<u32, MeshError> {
            let word = w.next().ok_or_else(|| here(format!("declares {n} vertices but the line has {i}")))?;
            match count(word) {
                Some(v) if v < vertices => Ok(v as u32),
                Some(v) => Err(here(format!("vertex index {v} out of range ({vertices} vertices)"))),
                None => Err(here(format!("not a vertex index: {:?}", show(word)))),
            }
        };
        let v0 = index(0)?;
        let mut prev = index(1)?;
        for i in 2..n {
            let next = index(i)?;
            if mesh.triangles.len() as u64 >= MAX_TRIANGLES {
                return Err(here("more than 2^32 - 1 triangles".into()));
            }
            super::check_triangles(mesh.triangles.len() as u64 + 1, "the faces up to here make", options)
                .map_err(here)?;
            mesh.triangles.push([v0, prev, next]);
            prev = next;
        }
        if options.sources {
            report.sources.extend(core::iter::repeat_n(Source::Face(f), (n - 2) as usize));
        }
    }
    if let Some((line_no, _)) = lines.next() {
        return Err(at(line_no, "data after the last face the counts declare".into()));
    }
    Ok((mesh, report))
}

/// The lines of the text that hold something, comments removed, with their 1-based numbers.
struct Lines<'a> {
    data: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Lines<'a> {
    fn new(data: &'a [u8]) -> Self {
        // A UTF-8 byte order mark is not content.
        let pos = if data.starts_with(b"\xef\xbb\xbf") { 3 } else { 0 };
        Lines { data, pos, line: 0 }
    }

    /// The number of the last line read (1 before any).
    fn last_line(&self) -> usize {
        self.line.max(1)
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = (usize, &'a [u8]);

    fn next(&mut self) -> Option<(usize, &'a [u8])> {
        while self.pos < self.data.len() {
            let rest = &self.data[self.pos..];
            let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
            self.pos += end + 1;
            self.line += 1;
            let line = &rest[..end];
            let line = &line[..line.iter().position(|&b| b == b'#').unwrap_or(line.len())];
            if line.iter().any(|b| !b.is_ascii_whitespace()) {
                return Some((self.line, line));
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::string::ToString;

    fn load(text: &str) -> (Mesh, LoadReport) {
        parse(text.as_bytes(), "t.off", &LoadOptions { strict: false, sources: true, ..LoadOptions::default() })
            .unwrap()
    }

    fn err(text: &str) -> String {
        parse(text.as_bytes(), "t.off", &LoadOptions::STRICT).unwrap_err().to_string()
    }

    const CUBE_TOP: &str = "OFF\n# a comment\n\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";

    #[test]
    fn quad_fan_with_and_without_edge_count() {
        let (m, report) = load(CUBE_TOP);
        assert_eq!(m.positions[2], Vec3::new(1., 1., 0.));
        assert_eq!(m.triangles, [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(report.sources, [Source::Face(0), Source::Face(0)]);
        assert_eq!(load(&CUBE_TOP.replace("4 1 0", "4 1")).0, m);
        // Counts on the keyword's line, no keyword at all, CRLF, comments after values.
        assert_eq!(load(&CUBE_TOP.replace("OFF\n# a comment\n\n4 1 0", "OFF 4 1 0")).0, m);
        assert_eq!(load(&CUBE_TOP.replace("OFF\n", "")).0, m);
        assert_eq!(load(&CUBE_TOP.replace('\n', "\r\n")).0, m);
        assert_eq!(load(&CUBE_TOP.replace("1 1 0\n", "1 1 0 # top right\n")).0, m);
    }

    #[test]
    fn keyword_variants() {
        let text = "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2 0.5 0.5 0.5\n";
        assert_eq!(load(text).0.triangles, [[0, 1, 2]]);
        let text =
            "STCNOFF\n3 1 0\n0 0 0 0 0 1 1 1 1 1 0 0\n1 0 0 0 0 1 1 1 1 1 1 0\n0 1 0 0 0 1 1 1 1 1 0 1\n3 0 1 2\n";
        assert_eq!(load(text).0.positions[1], Vec3::X);
        assert!(has_magic(b"# c\n  NOFF\n") && has_magic(b"off 1 2 0") && !has_magic(b"OFFX\n") && !has_magic(b"v 1"));
        assert_eq!(err("4OFF\n1 0 0\n0 0 0 1\n"), "t.off:1: 4D and n-dimensional OFF (4OFF, nOFF) are not supported");
        assert_eq!(err("OFF BINARY\n"), "t.off:1: binary OFF is not supported");
    }

    #[test]
    fn short_faces_are_skipped_and_counted() {
        let text = "OFF\n3 4 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n3 0 1 2\n0\n1 2\n";
        let (m, report) = load(text);
        assert_eq!(m.triangles, [[0, 1, 2]]);
        assert_eq!(report.sources, [Source::Face(1)]);
        assert_eq!(report.skipped, 3);
        let first = report.first_skipped.unwrap();
        assert_eq!((first.location.as_str(), first.what.as_str()), ("face 0 (line 6)", "a face with 2 vertices"));
        assert_eq!(err(text), "t.off:6: face 0: face has 2 vertices; a face needs at least 3");
    }

    #[test]
    fn errors_carry_the_line() {
        assert_eq!(err("# only a comment\n"), "t.off:1: no OFF keyword or counts (only comments)");
        assert_eq!(err("OFF\n"), "t.off:1: file ends before the vertex and face counts");
        assert!(err("OFF\n3\n").starts_with("t.off:2: expected `<vertices> <faces> [<edges>]`"));
        assert!(err("OFF\n3 -1 0\n").starts_with("t.off:2: expected"));
        assert!(err("OFF\n3 1 0 9\n").starts_with("t.off:2: expected"));
        assert_eq!(err("OFF\n3 1\n0 0 0\n1 0\n"), "t.off:4: vertex 1: no z coordinate");
        assert_eq!(err("OFF\n3 1\n0 0 0\n1 q 0\n"), "t.off:4: vertex 1: y is not a number: \"q\"");
        assert_eq!(err("OFF\n3 1\n0 0 0\n1 0 0\n"), "t.off:4: file ends after 2 of 3 vertices");
        let tri = "OFF\n3 2\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        assert_eq!(err(tri), "t.off:6: file ends after 1 of 2 faces");
        assert_eq!(err(&format!("{tri}3 0 1\n")), "t.off:7: face 1: declares 3 vertices but the line has 2");
        assert_eq!(err(&format!("{tri}3 0 1 3\n")), "t.off:7: face 1: vertex index 3 out of range (3 vertices)");
        assert_eq!(err(&format!("{tri}3 0 1 -2\n")), "t.off:7: face 1: not a vertex index: \"-2\"");
        assert_eq!(err(&format!("{tri}x 0 1 2\n")), "t.off:7: face 1: the vertex count is not a count: \"x\"");
        assert_eq!(err(&format!("{tri}3 0 1 2\n1 1 1\n")), "t.off:8: data after the last face the counts declare");
    }

    #[test]
    fn huge_counts_fail_fast() {
        let e = err("OFF\n4000000000 1 0\n0 0 0\n");
        assert_eq!(e, "t.off:3: file ends after 1 of 4000000000 vertices");
        let e = err("OFF\n1 18446744073709551615 0\n0 0 0\n3 0 0 0\n");
        assert_eq!(e, "t.off:4: file ends after 1 of 18446744073709551615 faces");
        assert!(err("OFF\n9999999999 1 0\n").ends_with("more than 2^32"));
        let e = err("OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n18446744073709551615 0 1 2\n");
        assert_eq!(e, "t.off:6: face 0: declares 18446744073709551615 vertices but the line has 3");
    }
}
