//! STL, binary and ASCII, read by hand.
//!
//! Why not a crate: `stl_io` (0.11, the maintained one) tells ASCII from binary by the first line
//! starting with `solid ` alone, so binary files whose 80-byte header starts with "solid" (as
//! several CAD exporters write it) are misread as text, and ASCII files starting `solid\t` or
//! `solid` without a name as binary; it trusts the binary header's triangle count (a count too
//! large fails at the end, one too small silently drops triangles); it reads only the first solid
//! of an ASCII file; and its errors are `io::Error`s with no line or byte offset. The format is
//! small enough that a reader giving positioned errors is shorter than the wrapping would be.
//!
//! Binary: an 80-byte header, a `u32` triangle count, then 50 bytes per facet (normal, three
//! vertices, attribute bytes; little-endian `f32`). The count in the header is often wrong
//! (0, or left over from an exporter that never went back to fill it in): the number of facets is
//! taken from the file's size, and a size that is not a whole number of facets is an error.
//!
//! Told apart: a file whose size is exactly what its header's count says is binary; else one that
//! starts with `solid` and is text (no control bytes in its first kilobyte) is ASCII; else binary.
//!
//! ASCII: `solid [name]`, then facets `facet normal nx ny nz` / `outer loop` / three `vertex x y
//! z` / `endloop` / `endfacet`, then `endsolid [name]`; several solids may follow one another.
//! Keywords are matched without regard to case and may be split across lines in any way; a facet
//! may omit `normal ...`. A loop of more than three vertices is split as a fan; one of fewer is
//! skipped and counted, or rejected when loading is strict.
//!
//! The mesh has three vertices per facet, in order (STL has no shared vertices). The source of a
//! triangle is its facet's index, counted across solids ([`Source::Facet`]).

use super::{show, LoadOptions, LoadReport, MeshError, Source, MAX_TRIANGLES, MAX_VERTICES};
use glam::Vec3;
use raytrail_core::scene::Mesh;
use std::format;
use std::string::String;
use std::vec::Vec;

const HEADER: usize = 84;
const FACET: usize = 50;

/// Whether the data looks like STL: ASCII starting with `solid`, or binary of exactly the size
/// its header's count says.
pub(super) fn has_magic(data: &[u8]) -> bool {
    binary_count_matches(data) || is_ascii(data)
}

fn binary_count_matches(data: &[u8]) -> bool {
    let Some(count) = data.get(80..HEADER) else { return false };
    let count = u32::from_le_bytes([count[0], count[1], count[2], count[3]]) as u64;
    count * FACET as u64 + HEADER as u64 == data.len() as u64
}

/// Starts with the `solid` keyword and is text.
fn is_ascii(data: &[u8]) -> bool {
    let text = data.trim_ascii_start();
    let starts = text.len() >= 5
        && text[..5].eq_ignore_ascii_case(b"solid")
        && text.get(5).is_none_or(|b| b.is_ascii_whitespace());
    let head = &data[..data.len().min(1024)];
    starts && head.iter().all(|&b| b.is_ascii_graphic() || b.is_ascii_whitespace() || b >= 0x80)
}

/// Parses an STL file held in memory; `name` is used in errors.
pub(super) fn parse(data: &[u8], name: &str, options: &LoadOptions) -> Result<(Mesh, LoadReport), MeshError> {
    if !binary_count_matches(data) && is_ascii(data) {
        return parse_ascii(data, name, options);
    }
    parse_binary(data, name, options)
}

fn parse_binary(data: &[u8], name: &str, options: &LoadOptions) -> Result<(Mesh, LoadReport), MeshError> {
    if data.len() < HEADER {
        let msg = format!("binary STL of {} bytes: shorter than its 84-byte header", data.len());
        return Err(MeshError::new(name, msg));
    }
    let claimed = u32::from_le_bytes([data[80], data[81], data[82], data[83]]);
    let body = data.len() - HEADER;
    if body % FACET != 0 {
        let whole = body / FACET;
        let msg = format!(
            "file ends inside facet {whole}: {} bytes left of its 50 (the header claims {claimed} facets)",
            body % FACET
        );
        return Err(MeshError::at_offset(name, (HEADER + whole * FACET) as u64, msg));
    }
    let facets = body / FACET;
    if facets as u64 > MAX_TRIANGLES || 3 * facets as u64 > MAX_VERTICES {
        return Err(MeshError::new(name, format!("{facets} facets: more than 2^32 vertices")));
    }
    super::check_triangles(facets as u64, "the file's facets make", options).map_err(|e| MeshError::new(name, e))?;
    let mut mesh = Mesh::default();
    mesh.positions.reserve(3 * facets);
    mesh.triangles.reserve(facets);
    let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    for (i, facet) in data[HEADER..].chunks_exact(FACET).enumerate() {
        // Bytes 0..12 are the normal, 48..50 the attribute bytes: neither is needed.
        for v in facet[12..48].chunks_exact(12) {
            mesh.positions.push(Vec3::new(f(&v[0..4]), f(&v[4..8]), f(&v[8..12])));
        }
        let base = 3 * i as u32;
        mesh.triangles.push([base, base + 1, base + 2]);
    }
    let mut report = LoadReport::default();
    if options.sources {
        report.sources = (0..facets as u64).map(Source::Facet).collect();
    }
    Ok((mesh, report))
}

fn parse_ascii(data: &[u8], name: &str, options: &LoadOptions) -> Result<(Mesh, LoadReport), MeshError> {
    let mut t = Tokens { data, pos: 0, line: 1, name };
    let mut mesh = Mesh::default();
    let mut report = LoadReport::default();
    let mut facet: u64 = 0;
    let mut corners: Vec<Vec3> = Vec::new();
    let mut solids = 0usize;
    loop {
        // Between solids: `solid [name]` or the end.
        match t.next() {
            None if solids > 0 => break,
            None => return Err(t.error("file ends before `solid`")),
            Some(w) if w.eq_ignore_ascii_case(b"solid") => t.skip_line(),
            Some(w) => return Err(t.error(&format!("expected `solid`, found {:?}", show(w)))),
        }
        solids += 1;
        loop {
            let w = t.word("`facet` or `endsolid`")?;
            if w.eq_ignore_ascii_case(b"endsolid") {
                t.skip_line();
                break;
            }
            if !w.eq_ignore_ascii_case(b"facet") {
                return Err(t.error(&format!("expected `facet` or `endsolid`, found {:?}", show(w))));
            }
            let facet_line = t.line;
            let mut w = t.word("`outer loop` or `normal`")?;
            if w.eq_ignore_ascii_case(b"normal") {
                for _ in 0..3 {
                    t.number("a normal component")?;
                }
                w = t.word("`outer loop`")?;
            }
            if !w.eq_ignore_ascii_case(b"outer") {
                return Err(t.error(&format!("expected `outer loop`, found {:?}", show(w))));
            }
            t.keyword(b"loop")?;
            corners.clear();
            loop {
                let w = t.word("`vertex` or `endloop`")?;
                if w.eq_ignore_ascii_case(b"endloop") {
                    break;
                }
                if !w.eq_ignore_ascii_case(b"vertex") {
                    return Err(t.error(&format!("expected `vertex` or `endloop`, found {:?}", show(w))));
                }
                let mut xyz = [0f32; 3];
                for c in &mut xyz {
                    *c = t.number("a vertex coordinate")?;
                }
                corners.push(Vec3::from_array(xyz));
            }
            t.keyword(b"endfacet")?;
            let n = corners.len();
            if n < 3 {
                if options.strict {
                    let msg = format!("facet {facet}: loop has {n} vertices; a facet needs at least 3");
                    return Err(MeshError::at_line(name, facet_line, msg));
                }
                report.skip(|| format!("facet {facet} (line {facet_line})"), || format!("a loop of {n} vertices"));
            } else {
                let base = mesh.positions.len() as u64;
                if base + n as u64 > MAX_VERTICES || (mesh.triangles.len() + n - 2) as u64 > MAX_TRIANGLES {
                    return Err(MeshError::at_line(name, facet_line, "more than 2^32 vertices"));
                }
                let made = (mesh.triangles.len() + n - 2) as u64;
                super::check_triangles(made, "the facets up to here make", options)
                    .map_err(|e| MeshError::at_line(name, facet_line, e))?;
                mesh.positions.extend_from_slice(&corners);
                let base = base as u32;
                mesh.triangles.extend((1..n as u32 - 1).map(|i| [base, base + i, base + i + 1]));
                if options.sources {
                    report.sources.extend(core::iter::repeat_n(Source::Facet(facet), n - 2));
                }
            }
            facet += 1;
        }
    }
    Ok((mesh, report))
}

/// Whitespace-separated words of ASCII STL, with the line they are on.
struct Tokens<'a> {
    data: &'a [u8],
    pos: usize,
    /// 1-based line of the last word returned (or of `pos` before any).
    line: usize,
    name: &'a str,
}

impl<'a> Tokens<'a> {
    fn next(&mut self) -> Option<&'a [u8]> {
        let data = self.data;
        while let Some(&b) = data.get(self.pos) {
            if !b.is_ascii_whitespace() {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        let start = self.pos;
        while data.get(self.pos).is_some_and(|b| !b.is_ascii_whitespace()) {
            self.pos += 1;
        }
        (self.pos > start).then(|| &data[start..self.pos])
    }

    /// Skips the rest of the current line (a solid's name).
    fn skip_line(&mut self) {
        while self.data.get(self.pos).is_some_and(|&b| b != b'\n') {
            self.pos += 1;
        }
    }

    fn error(&self, msg: &str) -> MeshError {
        MeshError::at_line(self.name, self.line, msg)
    }

    fn word(&mut self, expected: &str) -> Result<&'a [u8], MeshError> {
        self.next().ok_or_else(|| self.error(&format!("file ends where {expected} should be")))
    }

    fn keyword(&mut self, keyword: &[u8]) -> Result<(), MeshError> {
        let what = format!("`{}`", String::from_utf8_lossy(keyword));
        let w = self.word(&what)?;
        if !w.eq_ignore_ascii_case(keyword) {
            return Err(self.error(&format!("expected {what}, found {:?}", show(w))));
        }
        Ok(())
    }

    fn number(&mut self, what: &str) -> Result<f32, MeshError> {
        let w = self.word(what)?;
        std::str::from_utf8(w)
            .ok()
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| self.error(&format!("{what} is not a number: {:?}", show(w))))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::string::ToString;

    fn load(data: &[u8]) -> (Mesh, LoadReport) {
        parse(data, "t.stl", &LoadOptions { strict: false, sources: true, ..LoadOptions::default() }).unwrap()
    }

    fn err(data: &[u8]) -> String {
        parse(data, "t.stl", &LoadOptions::STRICT).unwrap_err().to_string()
    }

    /// A binary STL of the triangles; `claim` overrides the header's count, `header` its start.
    fn binary(tris: &[[[f32; 3]; 3]], claim: Option<u32>, header: &[u8]) -> Vec<u8> {
        let mut out = std::vec![0u8; 80];
        out[..header.len()].copy_from_slice(header);
        out.extend(claim.unwrap_or(tris.len() as u32).to_le_bytes());
        for t in tris {
            out.extend([0f32, 0., 1.].iter().flat_map(|c| c.to_le_bytes()));
            out.extend(t.iter().flatten().flat_map(|c| c.to_le_bytes()));
            out.extend([0xab, 0xcd]);
        }
        out
    }

    const TRIS: [[[f32; 3]; 3]; 2] =
        [[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], [[1., 1., 1.], [2., 1., 1.], [1., 2., 1.]]];

    fn corners(m: &Mesh) -> Vec<[[f32; 3]; 3]> {
        m.triangles.iter().map(|t| t.map(|i| m.positions[i as usize].to_array())).collect()
    }

    #[test]
    fn binary_with_right_and_wrong_counts() {
        for claim in [None, Some(0), Some(1), Some(7), Some(u32::MAX)] {
            for header in [&b""[..], b"solid exported by a CAD tool"] {
                let (m, report) = load(&binary(&TRIS, claim, header));
                assert_eq!(corners(&m), TRIS, "claim {claim:?}");
                assert_eq!(report.sources, [Source::Facet(0), Source::Facet(1)]);
            }
        }
    }

    #[test]
    fn binary_errors() {
        let data = binary(&TRIS, None, b"");
        assert_eq!(
            err(&data[..data.len() - 1]),
            "t.stl: byte 134: file ends inside facet 1: 49 bytes left of its 50 (the header claims 2 facets)"
        );
        assert_eq!(err(&data[..50]), "t.stl: binary STL of 50 bytes: shorter than its 84-byte header");
        // No facets at all is an empty mesh (to_scene rejects it).
        assert_eq!(load(&data[..84]).0, Mesh::default());
    }

    const ASCII: &str = "solid two\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n\
      vertex 0 1 0\n    endloop\n  endfacet\nendsolid two\nSOLID\nFACET NORMAL 0 0 1 OUTER LOOP VERTEX 1 1 1\n\
VERTEX 2e0 1 1 VERTEX 1 2 1 ENDLOOP ENDFACET\nENDSOLID\n";

    #[test]
    fn ascii_solids_in_any_layout() {
        let (m, report) = load(ASCII.as_bytes());
        assert_eq!(corners(&m), TRIS);
        assert_eq!(report.sources, [Source::Facet(0), Source::Facet(1)]);
        assert!(is_ascii(ASCII.as_bytes()) && is_ascii(b"solid\n") && is_ascii(b"  solid\tx\r\n"));
        assert!(!is_ascii(b"solidity") && !is_ascii(b"solid \x01\x00"));
        // No normal; a quad loop.
        let quad =
            "solid\nfacet outer loop vertex 0 0 0 vertex 1 0 0 vertex 1 1 0 vertex 0 1 0 endloop endfacet endsolid";
        let (m, report) = load(quad.as_bytes());
        assert_eq!(m.triangles, [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(report.sources, [Source::Facet(0), Source::Facet(0)]);
        // An empty solid.
        assert_eq!(load(b"solid empty\nendsolid empty\n").0, Mesh::default());
    }

    #[test]
    fn short_loops_are_skipped_and_counted() {
        let text = "solid\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\n\
facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n";
        let (m, report) = load(text.as_bytes());
        assert_eq!(m.triangles, [[0, 1, 2]]);
        assert_eq!(report.sources, [Source::Facet(1)]);
        let first = report.first_skipped.unwrap();
        assert_eq!((report.skipped, first.location.as_str()), (1, "facet 0 (line 2)"));
        assert_eq!(err(text.as_bytes()), "t.stl:2: facet 0: loop has 2 vertices; a facet needs at least 3");
    }

    #[test]
    fn ascii_errors_carry_the_line() {
        let cut = |n: usize| err(&ASCII.as_bytes()[..n]);
        assert_eq!(cut(5), "t.stl:1: file ends where `facet` or `endsolid` should be");
        assert_eq!(cut(52), "t.stl:4: file ends where `vertex` or `endloop` should be");
        assert_eq!(cut(60), "t.stl:4: file ends where a vertex coordinate should be");
        let bad = ASCII.replace("vertex 1 0 0", "vertex 1 zero 0");
        assert_eq!(err(bad.as_bytes()), "t.stl:5: a vertex coordinate is not a number: \"zero\"");
        let bad = ASCII.replace("outer loop", "outer space");
        assert_eq!(err(bad.as_bytes()), "t.stl:3: expected `loop`, found \"space\"");
        let bad = ASCII.replace("endfacet\nendsolid two", "endfacet\nfacet\nendsolid two");
        assert_eq!(err(bad.as_bytes()), "t.stl:10: expected `outer loop`, found \"endsolid\"");
        assert_eq!(err(b"solid x\nendsolid x\ngarbage\n"), "t.stl:3: expected `solid`, found \"garbage\"");
    }
}
