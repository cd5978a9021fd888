//! PLY: header, ASCII body and binary (little- and big-endian) body.
//!
//! Only vertex `x`, `y`, `z` and the face list `vertex_indices` (or `vertex_index`) are kept;
//! every other element and property is read past (and checked) so that the layout stays in step.
//! ASCII errors give the line; binary errors give the byte offset and the element's index.
//! Faces of fewer than three vertices are skipped and counted, or rejected when loading is strict
//! (their indices are read past either way); other elements (`edge`, ...) are read past as
//! always, not counted. The source of a triangle is its face element's index ([`Source::Face`]).

use super::{LoadOptions, LoadReport, MeshError, Source};
use glam::Vec3;
use raytrail_core::scene::Mesh;
use std::collections::HashSet;
use std::format;
use std::string::{String, ToString};
use std::vec::Vec;

/// Whether the data starts like a PLY file.
pub(super) fn has_magic(data: &[u8]) -> bool {
    data.starts_with(b"ply\n") || data.starts_with(b"ply\r\n")
}

/// Parses a whole PLY file held in memory; `name` is used in errors.
pub(super) fn parse(data: &[u8], name: &str, options: &LoadOptions) -> Result<(Mesh, LoadReport), MeshError> {
    let header = Header::parse(data, name)?;
    let mut out = Out {
        mesh: Mesh::default(),
        vertices: header.vertex_count,
        options: *options,
        report: LoadReport::default(),
        face: 0,
        short: None,
    };
    // Reserve what the header declares, but no more than the data could hold (hostile counts).
    for el in &header.elements {
        match el.kind {
            ElementKind::Vertex => out.mesh.positions.reserve(el.count.min(data.len() / 4)),
            ElementKind::Face => out.mesh.triangles.reserve(
                el.count.min(data.len() / 4).min(usize::try_from(options.max_triangles).unwrap_or(usize::MAX)),
            ),
            ElementKind::Other => {}
        }
    }
    match header.format {
        Format::Ascii => read_ascii(data, name, &header, &mut out)?,
        Format::Binary { big_endian } => read_binary(data, name, &header, big_endian, &mut out)?,
    }
    Ok((out.mesh, out.report))
}

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn from_name(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    /// The range of an integer type; `None` for floating-point types.
    fn int_range(self) -> Option<(i64, i64)> {
        Some(match self {
            Scalar::I8 => (i8::MIN.into(), i8::MAX.into()),
            Scalar::U8 => (0, u8::MAX.into()),
            Scalar::I16 => (i16::MIN.into(), i16::MAX.into()),
            Scalar::U16 => (0, u16::MAX.into()),
            Scalar::I32 => (i32::MIN.into(), i32::MAX.into()),
            Scalar::U32 => (0, u32::MAX.into()),
            Scalar::F32 | Scalar::F64 => return None,
        })
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    Binary { big_endian: bool },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PropertyKind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

/// What reading a property contributes to the mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Role {
    /// Vertex coordinate 0, 1 or 2.
    Coord(usize),
    /// The face's vertex index list.
    Indices,
    Skip,
}

#[derive(Debug)]
struct Property {
    name: String,
    kind: PropertyKind,
    role: Role,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ElementKind {
    Vertex,
    Face,
    Other,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    kind: ElementKind,
    /// Header line declaring it.
    line: usize,
    properties: Vec<Property>,
}

#[derive(Debug)]
struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Number of vertices that face indices may refer to.
    vertex_count: i64,
    /// Byte offset of the body.
    body: usize,
    /// 1-based line on which the body starts (ASCII).
    body_line: usize,
}

fn words(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(u8::is_ascii_whitespace).filter(|w| !w.is_empty())
}

fn show(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

impl Header {
    fn parse(data: &[u8], name: &str) -> Result<Header, MeshError> {
        let mut format = None;
        let mut elements: Vec<Element> = Vec::new();
        // The property names of the last element: a duplicate check in constant time, so that a
        // header of many properties parses in linear time (it was a scan of the element's list).
        let mut names: HashSet<String> = HashSet::new();
        let mut pos = 0;
        let mut line_no = 0;
        loop {
            if pos >= data.len() {
                return Err(MeshError::at_line(name, line_no.max(1), "header ends without `end_header`"));
            }
            line_no += 1;
            let end = data[pos..].iter().position(|&b| b == b'\n').map_or(data.len(), |i| pos + i);
            let line = &data[pos..end];
            pos = end + 1;
            let err = |msg: String| MeshError::at_line(name, line_no, msg);
            let w: Vec<&[u8]> = words(line).collect();
            if line_no == 1 {
                if w != [b"ply"] {
                    return Err(err("not a PLY file: the first line must be `ply`".into()));
                }
                continue;
            }
            match w.first().copied() {
                None | Some(b"comment") | Some(b"obj_info") => {}
                Some(b"format") => {
                    if format.is_some() {
                        return Err(err("second `format` line".into()));
                    }
                    let kind = match w.get(1).copied() {
                        Some(b"ascii") => Format::Ascii,
                        Some(b"binary_little_endian") => Format::Binary { big_endian: false },
                        Some(b"binary_big_endian") => Format::Binary { big_endian: true },
                        _ => return Err(err(format!("unknown format line: {:?}", show(line.trim_ascii())))),
                    };
                    if w.len() != 3 || !matches!(w[2], b"1.0" | b"1") {
                        return Err(err(format!("unsupported format version: {:?}", show(line.trim_ascii()))));
                    }
                    format = Some(kind);
                }
                Some(b"element") => {
                    let (Some(el_name), Some(count), 3) = (w.get(1), w.get(2), w.len()) else {
                        return Err(err("expected `element <name> <count>`".into()));
                    };
                    let count = std::str::from_utf8(count)
                        .ok()
                        .and_then(|c| c.parse::<usize>().ok())
                        .ok_or_else(|| err(format!("bad element count {:?}", show(count))))?;
                    let kind = match *el_name {
                        b"vertex" => ElementKind::Vertex,
                        b"face" => ElementKind::Face,
                        _ => ElementKind::Other,
                    };
                    if kind != ElementKind::Other && elements.iter().any(|e| e.kind == kind) {
                        return Err(err(format!("second `{}` element", show(el_name))));
                    }
                    elements.push(Element { name: show(el_name), count, kind, line: line_no, properties: Vec::new() });
                    names.clear();
                }
                Some(b"property") => {
                    let el = elements.last_mut().ok_or_else(|| err("`property` before any `element`".into()))?;
                    let property = parse_property(&w, el.kind).map_err(err)?;
                    if !names.insert(property.name.clone()) {
                        return Err(err(format!("duplicate property {:?}", property.name)));
                    }
                    el.properties.push(property);
                }
                Some(b"end_header") => break,
                Some(other) => return Err(err(format!("unknown header line starting with {:?}", show(other)))),
            }
        }
        let format = format.ok_or_else(|| MeshError::at_line(name, line_no, "no `format` line before `end_header`"))?;
        let mut vertex_count = 0;
        for el in &elements {
            let roles = el.properties.iter().map(|p| p.role);
            match el.kind {
                ElementKind::Vertex => {
                    for (k, axis) in ["x", "y", "z"].into_iter().enumerate() {
                        if !roles.clone().any(|r| r == Role::Coord(k)) {
                            let msg = format!("vertex element has no `{axis}` property");
                            return Err(MeshError::at_line(name, el.line, msg));
                        }
                    }
                    vertex_count = i64::try_from(el.count)
                        .ok()
                        .filter(|&n| n <= 1 << 32)
                        .ok_or_else(|| MeshError::at_line(name, el.line, "more than 2^32 vertices"))?;
                }
                ElementKind::Face if !roles.clone().any(|r| r == Role::Indices) => {
                    let msg = "face element has no `vertex_indices` (or `vertex_index`) list";
                    return Err(MeshError::at_line(name, el.line, msg));
                }
                _ => {}
            }
        }
        let body = pos.min(data.len());
        Ok(Header { format, elements, vertex_count, body, body_line: line_no + 1 })
    }
}

/// Parses the words of a `property` line of an element of the given kind.
fn parse_property(w: &[&[u8]], element: ElementKind) -> Result<Property, String> {
    let scalar = |t: &[u8]| Scalar::from_name(t).ok_or_else(|| format!("unknown property type {:?}", show(t)));
    let (kind, name) = match w {
        [_, b"list", count, item, name] => {
            let (count, item) = (scalar(count)?, scalar(item)?);
            if count.int_range().is_none() {
                return Err("a list's count type must be an integer type".into());
            }
            (PropertyKind::List { count, item }, show(name))
        }
        [_, b"list", ..] => return Err("expected `property list <count type> <item type> <name>`".into()),
        [_, t, name] => (PropertyKind::Scalar(scalar(t)?), show(name)),
        _ => return Err("expected `property <type> <name>`".into()),
    };
    let role = match (element, name.as_str(), kind) {
        (ElementKind::Vertex, "x" | "y" | "z", PropertyKind::Scalar(_)) => {
            Role::Coord(usize::from(name.as_bytes()[0] - b'x'))
        }
        (ElementKind::Vertex, "x" | "y" | "z", _) => return Err(format!("vertex `{name}` must be a scalar")),
        (ElementKind::Face, "vertex_indices" | "vertex_index", PropertyKind::List { item, .. }) => {
            if item.int_range().is_none() {
                return Err(format!("face `{name}` must hold an integer type"));
            }
            Role::Indices
        }
        (ElementKind::Face, "vertex_indices" | "vertex_index", _) => {
            return Err(format!("face `{name}` must be a list"));
        }
        _ => Role::Skip,
    };
    Ok(Property { name, kind, role })
}

/// The mesh being filled, how many vertices indices may refer to, and the loading policy.
struct Out {
    mesh: Mesh,
    vertices: i64,
    options: LoadOptions,
    report: LoadReport,
    /// Index of the face element being read.
    face: u64,
    /// The vertex count of a face just skipped, for the caller to position it.
    short: Option<i64>,
}

impl Out {
    /// Positions the face that [`read_face`] just skipped, if it skipped one.
    fn note_skipped(&mut self, location: impl FnOnce() -> String) {
        if let Some(n) = self.short.take() {
            self.report.skip(location, || format!("a face with {n} vertices"));
        }
    }
}

/// A source of property values: ASCII tokens or binary numbers. Errors are short messages that
/// the caller positions.
trait Values {
    /// An integer of an integer type.
    fn int(&mut self, t: Scalar) -> Result<i64, String>;
    /// Any type, as `f32`.
    fn float(&mut self, t: Scalar) -> Result<f32, String>;
    /// Reads past (and checks) one value.
    fn skip(&mut self, t: Scalar) -> Result<(), String>;
}

/// Reads one element instance into `out`.
fn read_element(v: &mut impl Values, el: &Element, out: &mut Out) -> Result<(), String> {
    let mut xyz = [0.0f32; 3];
    for p in &el.properties {
        let in_prop = |e: String| format!("property `{}`: {e}", p.name);
        match (p.kind, p.role) {
            (PropertyKind::Scalar(t), Role::Coord(k)) => xyz[k] = v.float(t).map_err(in_prop)?,
            (PropertyKind::Scalar(t), _) => v.skip(t).map_err(in_prop)?,
            (PropertyKind::List { count, item }, role) => {
                let n = v.int(count).map_err(in_prop)?;
                if n < 0 {
                    return Err(in_prop(format!("negative list length {n}")));
                }
                if role == Role::Indices {
                    read_face(v, n, item, out)?;
                } else {
                    for _ in 0..n {
                        v.skip(item).map_err(in_prop)?;
                    }
                }
            }
        }
    }
    if el.kind == ElementKind::Vertex {
        out.mesh.positions.push(Vec3::from_array(xyz));
    }
    Ok(())
}

/// Reads `n` vertex indices and appends their fan `(v0, vi, vi+1)`; a face of fewer than three
/// is read past and left in `out.short` (or is an error when loading is strict).
fn read_face(v: &mut impl Values, n: i64, item: Scalar, out: &mut Out) -> Result<(), String> {
    if n < 3 {
        if out.options.strict {
            return Err(format!("face has {n} vertices; a face needs at least 3"));
        }
        for _ in 0..n {
            v.skip(item)?;
        }
        out.short = Some(n);
        return Ok(());
    }
    let vertices = out.vertices;
    let mut index = || -> Result<u32, String> {
        let i = v.int(item)?;
        // Checked against the header's vertex count, so `to_scene` never sees a bad index.
        if !(0..vertices).contains(&i) {
            return Err(format!("vertex index {i} out of range ({vertices} vertices)"));
        }
        Ok(i as u32)
    };
    let first = index()?;
    let mut prev = index()?;
    for _ in 2..n {
        let next = index()?;
        super::check_triangles(out.mesh.triangles.len() as u64 + 1, "the faces up to here make", &out.options)?;
        out.mesh.triangles.push([first, prev, next]);
        prev = next;
    }
    if out.options.sources {
        let n = (n - 2) as usize;
        out.report.sources.extend(core::iter::repeat_n(Source::Face(out.face), n));
    }
    Ok(())
}

fn read_ascii(data: &[u8], name: &str, header: &Header, out: &mut Out) -> Result<(), MeshError> {
    let mut text = Ascii { data, pos: header.body, line: header.body_line };
    // An element without properties has nothing on its lines to read.
    for el in header.elements.iter().filter(|el| !el.properties.is_empty()) {
        for i in 0..el.count {
            if !text.next_line() {
                let msg = format!("file ends after {i} of {} `{}` elements", el.count, el.name);
                return Err(MeshError::at_line(name, text.last_line(), msg));
            }
            let line = text.line;
            let here = |e: String| MeshError::at_line(name, line, format!("{} {i}: {e}", el.name));
            out.face = i as u64;
            read_element(&mut text, el, out).map_err(here)?;
            out.note_skipped(|| format!("face {i} (line {line})"));
            if let Some(extra) = text.token() {
                let msg = format!("more values than the header declares (extra {:?})", show(extra));
                return Err(here(msg));
            }
        }
    }
    if text.next_line() {
        return Err(MeshError::at_line(name, text.line, "data after the last element the header declares"));
    }
    Ok(())
}

/// ASCII body: one element per line, values separated by spaces or tabs.
struct Ascii<'a> {
    data: &'a [u8],
    pos: usize,
    /// 1-based line of `pos`.
    line: usize,
}

impl<'a> Ascii<'a> {
    /// Moves to the start of the next non-blank line; false at the end of the data.
    fn next_line(&mut self) -> bool {
        while let Some(&b) = self.data.get(self.pos) {
            match b {
                b'\n' => self.line += 1,
                b' ' | b'\t' | b'\r' | b'\x0c' => {}
                _ => return true,
            }
            self.pos += 1;
        }
        false
    }

    /// The last line that has any byte on it.
    fn last_line(&self) -> usize {
        match self.data.last() {
            Some(b'\n') if self.pos == self.data.len() => self.line - 1,
            _ => self.line,
        }
    }

    /// The next value on the current line, if any; never crosses a newline.
    fn token(&mut self) -> Option<&'a [u8]> {
        let data = self.data;
        while matches!(data.get(self.pos), Some(b' ' | b'\t' | b'\r' | b'\x0c')) {
            self.pos += 1;
        }
        let start = self.pos;
        while data.get(self.pos).is_some_and(|b| !b.is_ascii_whitespace()) {
            self.pos += 1;
        }
        (self.pos > start).then(|| &data[start..self.pos])
    }

    fn value(&mut self) -> Result<&'a [u8], String> {
        self.token().ok_or_else(|| "line ends before this value".to_string())
    }
}

fn parse_int(token: &[u8]) -> Option<i64> {
    let (negative, digits) = match token {
        [b'-', rest @ ..] => (true, rest),
        [b'+', rest @ ..] => (false, rest),
        _ => (false, token),
    };
    if digits.is_empty() {
        return None;
    }
    let mut v: i64 = 0;
    for &d in digits {
        let d = d.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        v = v.checked_mul(10)?.checked_add(i64::from(d))?;
    }
    Some(if negative { -v } else { v })
}

fn parse_float<T: core::str::FromStr>(token: &[u8]) -> Result<T, String> {
    std::str::from_utf8(token)
        .ok()
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| format!("not a number: {:?}", show(token)))
}

impl Values for Ascii<'_> {
    fn int(&mut self, t: Scalar) -> Result<i64, String> {
        let token = self.value()?;
        let v = parse_int(token).ok_or_else(|| format!("not an integer: {:?}", show(token)))?;
        let (lo, hi) = t.int_range().unwrap_or((i64::MIN, i64::MAX));
        if !(lo..=hi).contains(&v) {
            return Err(format!("{v} is out of range for {}", t.name()));
        }
        Ok(v)
    }

    fn float(&mut self, t: Scalar) -> Result<f32, String> {
        match t {
            Scalar::F32 => parse_float(self.value()?),
            Scalar::F64 => parse_float::<f64>(self.value()?).map(|v| v as f32),
            _ => self.int(t).map(|v| v as f32),
        }
    }

    fn skip(&mut self, t: Scalar) -> Result<(), String> {
        match t {
            Scalar::F32 | Scalar::F64 => parse_float::<f64>(self.value()?).map(drop),
            _ => self.int(t).map(drop),
        }
    }
}

fn read_binary(data: &[u8], name: &str, header: &Header, big_endian: bool, out: &mut Out) -> Result<(), MeshError> {
    let mut bin = Binary { data, pos: header.body, big_endian };
    // Skipping elements without properties keeps a hostile count from spinning for nothing.
    for el in header.elements.iter().filter(|el| !el.properties.is_empty()) {
        for i in 0..el.count {
            let start = bin.pos;
            out.face = i as u64;
            read_element(&mut bin, el, out).map_err(|e| {
                let msg = format!("{} {i} of {} (starting at byte {start}): {e}", el.name, el.count);
                MeshError::at_offset(name, bin.pos as u64, msg)
            })?;
            out.note_skipped(|| format!("face {i} (byte {start})"));
        }
    }
    if bin.pos != data.len() {
        let msg = format!("{} bytes after the last element the header declares", data.len() - bin.pos);
        return Err(MeshError::at_offset(name, bin.pos as u64, msg));
    }
    Ok(())
}

/// Binary body: values packed back to back in the file's byte order.
struct Binary<'a> {
    data: &'a [u8],
    pos: usize,
    big_endian: bool,
}

impl Binary<'_> {
    fn bytes<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let mut out = [0u8; N];
        let src = self.data.get(self.pos..self.pos + N).ok_or_else(|| self.truncated(N))?;
        out.copy_from_slice(src);
        self.pos += N;
        Ok(out)
    }

    fn truncated(&self, need: usize) -> String {
        format!("file ends: {need} bytes needed, {} left", self.data.len() - self.pos)
    }
}

macro_rules! number {
    ($bin:expr, $t:ty) => {{
        let b = $bin.bytes::<{ core::mem::size_of::<$t>() }>()?;
        if $bin.big_endian {
            <$t>::from_be_bytes(b)
        } else {
            <$t>::from_le_bytes(b)
        }
    }};
}

impl Values for Binary<'_> {
    fn int(&mut self, t: Scalar) -> Result<i64, String> {
        Ok(match t {
            Scalar::I8 => number!(self, i8).into(),
            Scalar::U8 => number!(self, u8).into(),
            Scalar::I16 => number!(self, i16).into(),
            Scalar::U16 => number!(self, u16).into(),
            Scalar::I32 => number!(self, i32).into(),
            Scalar::U32 => number!(self, u32).into(),
            // The header lets only integer types reach here.
            Scalar::F32 | Scalar::F64 => return Err(format!("{} where an integer is needed", t.name())),
        })
    }

    fn float(&mut self, t: Scalar) -> Result<f32, String> {
        match t {
            Scalar::F32 => Ok(number!(self, f32)),
            Scalar::F64 => Ok(number!(self, f64) as f32),
            _ => self.int(t).map(|v| v as f32),
        }
    }

    fn skip(&mut self, t: Scalar) -> Result<(), String> {
        let n = t.size();
        if self.data.len() - self.pos < n {
            return Err(self.truncated(n));
        }
        self.pos += n;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The error of strict loading.
    fn err(text: &[u8]) -> String {
        parse(text, "t.ply", &LoadOptions::STRICT).unwrap_err().to_string()
    }

    fn load(text: &[u8]) -> Mesh {
        parse(text, "t.ply", &LoadOptions::default()).unwrap().0
    }

    const HEAD: &str = "ply\nformat ascii 1.0\ncomment c\nelement vertex 4\nproperty float x\nproperty float y\n\
property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

    #[test]
    fn ascii_quad_fan() {
        let text = format!("{HEAD}0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
        let m = load(text.as_bytes());
        assert_eq!(m.positions[2], Vec3::new(1., 1., 0.));
        assert_eq!(m.triangles, [[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn ascii_skips_other_elements_and_properties() {
        let text = "ply\r\nformat ascii 1.0\r\nobj_info x\r\nelement vertex 3\r\nproperty double x\r\n\
property list uchar float uv\r\nproperty int y\r\nproperty uchar red\r\nproperty short z\r\n\
element edge 2\r\nproperty list ushort uint pair\r\nproperty char flag\r\n\
element face 2\r\nproperty uint8 tag\r\nproperty list uint8 uint32 vertex_index\r\nproperty list uchar float w\r\n\
end_header\r\n0.5 2 0.25 0.75 1 255 -3\r\n1 0 0 0 0\r\n2 1 3 4 0 7\r\n\r\n2 0 1 -1\r\n\t3 0 1 2 1\r\n\
9 3 0 1 2 0\r\n9 3 2 1 0 3 1 2 3\r\n";
        let m = load(text.as_bytes());
        assert_eq!(m.positions, [Vec3::new(0.5, 1., -3.), Vec3::X, Vec3::new(2., 4., 7.)]);
        assert_eq!(m.triangles, [[0, 1, 2], [2, 1, 0]]);
    }

    #[test]
    fn short_faces_are_skipped_and_counted() {
        let options = LoadOptions { strict: false, sources: true, ..LoadOptions::default() };
        let text =
            format!("{}0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 1\n4 0 1 2 3\n0\n1 3\n", HEAD.replace("face 1", "face 4"));
        let (m, report) = parse(text.as_bytes(), "t.ply", &options).unwrap();
        assert_eq!(m.triangles, [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(report.sources, [Source::Face(1), Source::Face(1)]);
        assert_eq!(report.skipped, 3);
        let first = report.first_skipped.unwrap();
        assert_eq!((first.location.as_str(), first.what.as_str()), ("face 0 (line 15)", "a face with 2 vertices"));
        // A skipped face's indices are still read (and checked for their type).
        let bad = text.replace("1 3\n", "1 x\n");
        let e = parse(bad.as_bytes(), "t.ply", &options).unwrap_err().to_string();
        assert_eq!(e, "t.ply:18: face 3: not an integer: \"x\"");
        // Binary: positioned by byte.
        let mut bin = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
            .to_vec();
        let body = bin.len();
        for c in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
            bin.extend(c.to_le_bytes());
        }
        for face in [&[0i32, 1][..], &[0, 1, 2]] {
            bin.push(face.len() as u8);
            face.iter().for_each(|i| bin.extend(i.to_le_bytes()));
        }
        let (m, report) = parse(&bin, "b.ply", &options).unwrap();
        assert_eq!((m.triangles, report.sources), (std::vec![[0, 1, 2]], std::vec![Source::Face(1)]));
        assert_eq!(report.first_skipped.unwrap().location, format!("face 0 (byte {})", body + 36));
        let e = parse(&bin, "b.ply", &LoadOptions::STRICT).unwrap_err().to_string();
        assert!(e.contains("face 0 of 2") && e.ends_with("face has 2 vertices; a face needs at least 3"), "{e}");
    }

    /// A header of 100,000 properties is read (and here rejected) in linear time: the duplicate
    /// check was a scan of the element's properties per property (33 s for 100,000).
    #[test]
    fn many_properties_parse_in_linear_time() {
        let mut text = String::from("ply\nformat ascii 1.0\nelement vertex 1\n");
        for i in 0..100_000 {
            text.push_str(&format!("property float p{i}\n"));
        }
        let start = std::time::Instant::now();
        let e = err(format!("{text}property float p99999\nend_header\n").as_bytes());
        assert!(e.starts_with("t.ply:100004: duplicate property \"p99999\""), "{e}");
        let e = err(format!("{text}end_header\n").as_bytes());
        assert!(e.starts_with("t.ply:3: vertex element has no `x` property"), "{e}");
        assert!(start.elapsed() < std::time::Duration::from_secs(1), "{:?}", start.elapsed());
    }

    #[test]
    fn header_errors() {
        assert_eq!(err(b"plyx\n"), "t.ply:1: not a PLY file: the first line must be `ply`");
        assert!(err(b"ply\nformat ascii 2.0\nend_header\n").starts_with("t.ply:2: unsupported format version"));
        assert!(err(b"ply\nformat text 1.0\nend_header\n").starts_with("t.ply:2: unknown format"));
        assert!(err(b"ply\nformat ascii 1.0\nproperty float x\n").starts_with("t.ply:3: `property` before"));
        assert!(err(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float32 x\n")
            .starts_with("t.ply:4: header ends without"));
        assert!(err(b"ply\nformat ascii 1.0\nelement vertex x\n").starts_with("t.ply:3: bad element count"));
        assert!(err(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\n")
            .starts_with("t.ply:4: unknown property type"));
        assert!(err(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n")
            .starts_with("t.ply:3: vertex element has no `y`"));
        assert!(err(b"ply\nformat ascii 1.0\nelement face 1\nproperty list float int vertex_indices\n")
            .starts_with("t.ply:4: a list's count type"));
        assert!(err(b"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar float vertex_indices\n")
            .starts_with("t.ply:4: face `vertex_indices` must hold an integer"));
        assert!(err(b"ply\nelement face 0\nend_header\n").starts_with("t.ply:3: no `format`"));
        assert!(err(b"ply\nformat ascii 1.0\nbogus\nend_header\n").starts_with("t.ply:3: unknown header line"));
    }

    #[test]
    fn ascii_body_errors() {
        let e = |body: &str| err(format!("{HEAD}{body}").as_bytes());
        assert_eq!(e("0 0 0\n1 0 0\n1 1 0\n"), "t.ply:13: file ends after 3 of 4 `vertex` elements");
        assert_eq!(e("0 0 0\n1 0 0\n1 1 0"), "t.ply:13: file ends after 3 of 4 `vertex` elements");
        assert!(e("0 0 0\n1 0 0\n1 1 0\n4 0 1 2 3\n").starts_with("t.ply:14: vertex 3: more values"));
        assert!(e("0 0 0\n1 0\n").starts_with("t.ply:12: vertex 1: property `z`: line ends"));
        assert!(e("0 0 0\n1 0 q\n").starts_with("t.ply:12: vertex 1: property `z`: not a number: \"q\""));
        assert_eq!(
            e("0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 1\n"),
            "t.ply:15: face 0: face has 2 vertices; a face needs at least 3"
        );
        assert!(e("0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 4\n").starts_with("t.ply:15: face 0: vertex index 4 out of range"));
        assert!(e("0 0 0\n1 0 0\n1 1 0\n0 1 0\n300 0 1 4\n")
            .starts_with("t.ply:15: face 0: property `vertex_indices`: 300 is out of range"));
        assert!(e("0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n5\n").starts_with("t.ply:16: data after"));
    }

    /// Writes one binary PLY exercising every scalar type; `be` picks the byte order.
    fn binary_ply(be: bool) -> Vec<u8> {
        let mut out = format!(
            "ply\nformat binary_{}_endian 1.0\nelement vertex 3\nproperty float x\nproperty double y\n\
property int16 z\nproperty list uint8 float32 uv\nproperty char a\nproperty ushort b\nproperty uint c\n\
element face 2\nproperty list uchar uint vertex_indices\nproperty int8 flags\n\
element extra 1\nproperty list int32 float64 stuff\nend_header\n",
            if be { "big" } else { "little" }
        )
        .into_bytes();
        macro_rules! put {
            ($v:expr) => {
                out.extend_from_slice(&if be { $v.to_be_bytes() } else { $v.to_le_bytes() })
            };
        }
        for (i, (x, y, z)) in [(0.5f32, 1.25f64, -2i16), (1.0, 0.0, 0), (0.0, 2.5, 3)].into_iter().enumerate() {
            put!(x);
            put!(y);
            put!(z);
            put!(2u8);
            put!(0.1f32);
            put!(0.2f32);
            put!(-(i as i8));
            put!(60000u16);
            put!(4_000_000_000u32);
        }
        for (face, flag) in [(&[0u32, 1, 2][..], 1i8), (&[2, 1, 0, 1][..], -1)] {
            put!(face.len() as u8);
            for &v in face {
                put!(v);
            }
            put!(flag);
        }
        put!(2i32);
        put!(1.0f64);
        put!(2.0f64);
        out
    }

    #[test]
    fn binary_round_trip_every_type() {
        for be in [false, true] {
            let m = load(&binary_ply(be));
            assert_eq!(m.positions, [Vec3::new(0.5, 1.25, -2.), Vec3::X, Vec3::new(0., 2.5, 3.)]);
            assert_eq!(m.triangles, [[0, 1, 2], [2, 1, 0], [2, 0, 1]]);
        }
    }

    #[test]
    fn binary_errors_give_element_and_offset() {
        let full = binary_ply(false);
        let body = full.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        // Cut inside vertex 1: 3 vertices of 4+8+2+1+8+1+2+4 = 30 bytes each.
        let e = err(&full[..body + 30 + 5]);
        assert_eq!(
            e,
            format!(
                "t.ply: byte {}: vertex 1 of 3 (starting at byte {}): property `y`: file ends: 8 bytes needed, 1 left",
                body + 34,
                body + 30
            )
        );
        let mut extra = full.clone();
        extra.push(0);
        assert!(err(&extra).ends_with("1 bytes after the last element the header declares"));
        // A face of 2 vertices.
        let mut short = full.clone();
        short[body + 90] = 2;
        let e = err(&short);
        assert!(
            e.contains(&format!("byte {}: face 0 of 2", body + 91))
                && e.ends_with("face has 2 vertices; a face needs at least 3"),
            "{e}"
        );
        // A negative list length in a skipped list.
        let mut neg = full;
        let n = neg.len();
        neg[n - 20..n - 16].copy_from_slice(&(-1i32).to_le_bytes());
        assert!(err(&neg).contains("extra 0 of 1"), "{}", err(&neg));
    }

    #[test]
    fn huge_counts_fail_fast() {
        for format in ["ascii", "binary_big_endian"] {
            let empty = format!("ply\nformat {format} 1.0\nelement junk 18446744073709551615\nend_header\n");
            assert_eq!(load(empty.as_bytes()), Mesh::default());
            let cut = format!(
                "ply\nformat {format} 1.0\nelement vertex 4000000000\nproperty int x\nproperty int y\n\
property int z\nend_header\n"
            );
            let e = err(cut.as_bytes());
            assert!(e.contains("0 of 4000000000"), "{e}");
        }
    }

    #[test]
    fn parse_int_edges() {
        assert_eq!(parse_int(b"-12"), Some(-12));
        assert_eq!(parse_int(b"+7"), Some(7));
        assert_eq!(parse_int(b"-"), None);
        assert_eq!(parse_int(b"1.0"), None);
        assert_eq!(parse_int(b"99999999999999999999"), None);
    }
}
