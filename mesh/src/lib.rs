//! Mesh files: OBJ (through tobj), PLY (ASCII and binary), OFF, STL (binary and ASCII) and glTF 2.0
//! (`.gltf` and `.glb`, through the `gltf` crate's JSON model); any of them gzip-compressed.
//!
//! # Primitive ids
//!
//! Every loader returns a [`Mesh`] whose primitive id is the index of the triangle in file order
//! over the triangles kept, polygons split as fans `(v0, vi, vi+1)`:
//! - OBJ: `f` lines in file order (across `o`, `g` and material changes);
//! - PLY, OFF: the face elements in order;
//! - STL: the facets in order (across the solids of an ASCII file);
//! - glTF: the scene's nodes depth first, in the order the scene and each node list them (a node
//!   before its children); per node with a mesh, its primitives in order; per primitive, its
//!   triangles in order, triangle strips and fans converted as the glTF specification numbers
//!   them. A mesh used by several nodes is there once per node, transformed by each.
//!
//! [`LoadReport::sources`] (with [`LoadOptions::sources`]) gives, per primitive id, where in the
//! file the triangle came from ([`Source`]).
//!
//! # Loading policy
//!
//! Elements that are not triangles or polygons (faces of fewer than three vertices, OBJ `l`
//! polylines and `p` points, STL loops of fewer than three vertices, glTF primitives in a point or
//! line mode) are skipped and counted in the [`LoadReport`], which keeps the first one's location.
//! With [`LoadOptions::strict`] the first of them is an error instead (for short faces, the error
//! the loaders gave before they learned to skip: "face has 2 vertices; a face needs at least 3").
//!
//! # Errors and limits
//!
//! Every failure is a [`MeshError`] naming the file and, where there is one, the line (text), the
//! byte offset (binary) or the JSON path (glTF). Counts that a file claims (PLY and OFF headers,
//! STL's triangle count, glTF accessors) never size an allocation beyond what the data can hold,
//! and no input makes a loader panic. What a file may expand to is limited: gzip data by
//! [`LoadOptions::max_inflated`], triangles (after fan splitting and glTF instancing, which
//! multiplies a mesh by the nodes that place it) by [`LoadOptions::max_triangles`], checked before
//! the triangles are allocated.

#![warn(missing_docs)]

mod error;
mod gltf;
mod obj;
mod off;
mod ply;
mod stl;

use core::fmt;
pub use error::MeshError;
/// The mesh type every loader returns (the core's, so a loaded mesh goes straight to a scene).
pub use raytrail_core::scene::Mesh;
use std::io::{self, BufRead, Read, Write};
use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

/// How a file is loaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// Fail on the first element that is not a triangle or polygon, instead of skipping it.
    pub strict: bool,
    /// Fill [`LoadReport::sources`]: where in the file each kept triangle comes from.
    pub sources: bool,
    /// Largest size a gzip-compressed file may inflate to, in bytes; past it loading fails with
    /// an error saying so (a few megabytes of gzip can claim gigabytes).
    pub max_inflated: u64,
    /// Most triangles a file may make, counted after polygons are split into fans and after glTF
    /// instancing (a node placing a mesh copies it); past it loading fails before the triangles
    /// are allocated, with an error saying so (a 1 MB glTF that places one mesh 20,000 times makes
    /// over a hundred million). glTF's placed vertices are held to three per allowed triangle.
    pub max_triangles: u64,
}

impl Default for LoadOptions {
    /// [`LoadOptions::LENIENT`].
    fn default() -> Self {
        LoadOptions::LENIENT
    }
}

impl LoadOptions {
    /// The default policy: skip elements that are not triangles or polygons, no source map.
    pub const LENIENT: LoadOptions = LoadOptions {
        strict: false,
        sources: false,
        max_inflated: LoadOptions::DEFAULT_MAX_INFLATED,
        max_triangles: LoadOptions::DEFAULT_MAX_TRIANGLES,
    };
    /// Fail on elements that are not triangles or polygons.
    pub const STRICT: LoadOptions = LoadOptions { strict: true, ..LoadOptions::LENIENT };
    /// The default [`LoadOptions::max_inflated`]: 512 MiB, far beyond any mesh the tests or
    /// benches read (the full dragon inflates to 30 MB), and reached by a gzip bomb in well under a
    /// second (a 3 MB file that claims 3 GB is stopped there).
    pub const DEFAULT_MAX_INFLATED: u64 = 512 << 20;
    /// The default [`LoadOptions::max_triangles`]: 2^26 (67 million), 77 times the full dragon;
    /// at the limit a mesh holds about 0.8 GiB of triangles and up to 2.3 GiB of vertices.
    pub const DEFAULT_MAX_TRIANGLES: u64 = 1 << 26;
}

/// `Err` naming the limit when `count` triangles (what `what` makes: "the faces make") pass
/// [`LoadOptions::max_triangles`]; checked before the triangles are allocated.
fn check_triangles(count: u64, what: &str, options: &LoadOptions) -> Result<(), String> {
    let max = options.max_triangles;
    if count > max {
        return Err(std::format!(
            "{what} {count} triangles, more than the limit of {max} (LoadOptions::max_triangles; the CLI's --max-triangles)"
        ));
    }
    Ok(())
}

/// What loading a file skipped, and where the triangles came from.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LoadReport {
    /// Elements skipped because they are not triangles or polygons.
    pub skipped: usize,
    /// The first of them.
    pub first_skipped: Option<Skipped>,
    /// Per primitive id, where the triangle came from; empty unless [`LoadOptions::sources`].
    pub sources: Vec<Source>,
}

/// An element that loading skipped: where it is, and what it is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Skipped {
    /// Where in the file: `line 7`, `face 12 (line 30)`, `mesh 2 primitive 0 (node 5)`.
    pub location: String,
    /// What it is: `a face with 2 vertices`, `a polyline (l)`, `a primitive in LINES mode`.
    pub what: String,
}

/// Where in its file a triangle came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// The 1-based line of its OBJ `f` statement.
    Line(u64),
    /// The 0-based index of its face element (PLY, OFF).
    Face(u64),
    /// The 0-based index of its STL facet (counted across solids).
    Facet(u64),
    /// glTF: the node that places it, its mesh, the primitive in the mesh, and the triangle in the
    /// primitive (after strip and fan conversion); all 0-based.
    Gltf {
        /// Node index.
        node: u32,
        /// Mesh index.
        mesh: u32,
        /// Primitive index within the mesh.
        primitive: u32,
        /// Triangle index within the primitive.
        triangle: u32,
    },
}

impl Source {
    /// The CSV column names of this kind of source.
    pub fn columns(&self) -> &'static str {
        match self {
            Source::Line(_) => "line",
            Source::Face(_) => "face",
            Source::Facet(_) => "facet",
            Source::Gltf { .. } => "node,mesh,primitive,triangle",
        }
    }
}

/// The values, comma-separated, in the order of [`Source::columns`].
impl fmt::Display for Source {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Source::Line(v) | Source::Face(v) | Source::Facet(v) => write!(f, "{v}"),
            Source::Gltf { node, mesh, primitive, triangle } => write!(f, "{node},{mesh},{primitive},{triangle}"),
        }
    }
}

impl LoadReport {
    /// Counts a skipped element, keeping the first one's description.
    pub(crate) fn skip(&mut self, location: impl FnOnce() -> String, what: impl FnOnce() -> String) {
        self.skipped += 1;
        if self.first_skipped.is_none() {
            self.first_skipped = Some(Skipped { location: location(), what: what() });
        }
    }

    /// One line saying what was skipped in `file`, or `None` when nothing was: `a.obj: skipped 3
    /// elements that are not triangles or polygons, the first at line 7: a face with 2 vertices`.
    pub fn summary(&self, file: &str) -> Option<String> {
        let first = self.first_skipped.as_ref()?;
        let (n, Skipped { location, what }) = (self.skipped, first);
        Some(if n == 1 {
            std::format!("{file}: skipped 1 element that is not a triangle or polygon, at {location}: {what}")
        } else {
            std::format!(
                "{file}: skipped {n} elements that are not triangles or polygons, the first at {location}: {what}"
            )
        })
    }
}

/// Writes the primitive-id map of [`LoadReport::sources`] as CSV: a header `prim,file,<columns>`
/// ([`Source::columns`]), then one row per triangle, `file` quoted where CSV needs it.
pub fn write_sources_csv(out: &mut impl Write, file: &str, sources: &[Source]) -> io::Result<()> {
    let columns = sources.first().map_or("source", Source::columns);
    let file = if file.contains([',', '"', '\n', '\r']) {
        std::format!("\"{}\"", file.replace('"', "\"\""))
    } else {
        file.to_string()
    };
    writeln!(out, "prim,file,{columns}")?;
    for (prim, source) in sources.iter().enumerate() {
        writeln!(out, "{prim},{file},{source}")?;
    }
    Ok(())
}

/// Loads a mesh file with the default (lenient) policy; see [`load_with`].
pub fn load(path: &Path) -> Result<Mesh, MeshError> {
    load_with(path, &LoadOptions::default()).map(|(mesh, _)| mesh)
}

/// Loads a mesh file: `.obj`, `.ply`, `.off`, `.stl`, `.gltf`, `.glb`, each optionally gzip
/// compressed (`.obj.gz`, ...).
///
/// Gzip is recognised by its magic bytes, whatever the name; the format then comes from the
/// extension (after any `.gz`), or from the content for other names (PLY, OFF, GLB and glTF JSON
/// by their first bytes; STL by its `solid` keyword or its size; OBJ, which has no magic, by a
/// first statement of OBJ's where the name has no extension at all). A `.gltf` file's external buffers are read from the file's folder.
/// A path that is a pipe (`<(zcat mesh.obj.gz)`) is read as a stream, up to
/// [`LoadOptions::max_inflated`] bytes.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<(Mesh, LoadReport), MeshError> {
    let name = path.display().to_string();
    let data = read_input(path, options.max_inflated).map_err(|e| MeshError::io(&name, "cannot read file", e))?;
    let dir = path.parent().map(|d| if d.as_os_str().is_empty() { Path::new(".") } else { d });
    load_data(&data, &name, dir, options)
}

/// Loads a mesh from file contents held in memory with the default (lenient) policy; see
/// [`load_bytes_with`].
pub fn load_bytes(data: &[u8], name: &str) -> Result<Mesh, MeshError> {
    load_bytes_with(data, name, &LoadOptions::default()).map(|(mesh, _)| mesh)
}

/// Loads a mesh from file contents held in memory; `name` is used for the format (as in
/// [`load_with`]) and in errors. A glTF file's buffers must be in the data (GLB, `data:` URIs):
/// no other file is read.
pub fn load_bytes_with(data: &[u8], name: &str, options: &LoadOptions) -> Result<(Mesh, LoadReport), MeshError> {
    load_data(data, name, None, options)
}

/// Parses an OBJ file from a reader with the default (lenient) policy; `name` is used in errors.
/// Materials are ignored.
pub fn load_obj(mut reader: impl BufRead, name: &str) -> Result<Mesh, MeshError> {
    let mut data = Vec::new();
    reader.read_to_end(&mut data).map_err(|e| MeshError::io(name, "read failed", e))?;
    obj::parse(&data, name, &LoadOptions::default()).map(|(mesh, _)| mesh)
}

/// Parses a PLY file (ASCII, binary little- or big-endian) from a reader with the default
/// (lenient) policy; `name` is used in errors. Takes vertex `x`, `y`, `z` and the face list
/// `vertex_indices` (or `vertex_index`).
pub fn load_ply(mut reader: impl BufRead, name: &str) -> Result<Mesh, MeshError> {
    let mut data = Vec::new();
    reader.read_to_end(&mut data).map_err(|e| MeshError::io(name, "read failed", e))?;
    ply::parse(&data, name, &LoadOptions::default()).map(|(mesh, _)| mesh)
}

/// The bytes of `path`: a file whole, a stream (a pipe, `<(zcat mesh.obj.gz)`) up to `max`
/// bytes, past which it is an error (a stream says nothing of its size, and `<(yes)` never ends).
fn read_input(path: &Path, max: u64) -> io::Result<Vec<u8>> {
    let file = std::fs::File::open(path)?;
    if file.metadata()?.is_file() {
        return std::fs::read(path);
    }
    let mut data = Vec::new();
    file.take(max.saturating_add(1)).read_to_end(&mut data)?;
    if data.len() as u64 > max {
        return Err(io::Error::other(std::format!(
            "a stream longer than {max} bytes, the limit for meshes read from a pipe (LoadOptions::max_inflated; the CLI's --max-mesh-bytes)"
        )));
    }
    Ok(data)
}

const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

fn load_data(
    data: &[u8],
    name: &str,
    dir: Option<&Path>,
    options: &LoadOptions,
) -> Result<(Mesh, LoadReport), MeshError> {
    if data.is_empty() {
        return Err(MeshError::new(name, "file is empty"));
    }
    let stem = strip_suffix_ignore_case(name, ".gz");
    if data.starts_with(&GZIP_MAGIC) {
        let raw = gunzip(data, name, options.max_inflated)?;
        if raw.is_empty() {
            return Err(MeshError::new(name, "file is empty after gzip decompression"));
        }
        return parse(&raw, name, stem.unwrap_or(name), dir, options);
    }
    if stem.is_some() {
        return Err(MeshError::new(name, "named .gz but not gzip data (no 1f 8b magic)"));
    }
    parse(data, name, name, dir, options)
}

/// The formats, as [`parse`] tells them apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Obj,
    Ply,
    Off,
    Stl,
    /// glTF JSON or GLB: the loader tells them apart by the GLB magic.
    Gltf,
}

fn format_of(format_name: &str, data: &[u8]) -> Option<Format> {
    const EXTENSIONS: [(&str, Format); 6] = [
        (".obj", Format::Obj),
        (".ply", Format::Ply),
        (".off", Format::Off),
        (".stl", Format::Stl),
        (".gltf", Format::Gltf),
        (".glb", Format::Gltf),
    ];
    if let Some(&(_, format)) = EXTENSIONS.iter().find(|(ext, _)| strip_suffix_ignore_case(format_name, ext).is_some())
    {
        return Some(format);
    }
    if ply::has_magic(data) {
        Some(Format::Ply)
    } else if gltf::has_magic(data) {
        Some(Format::Gltf)
    } else if off::has_magic(data) {
        Some(Format::Off)
    } else if stl::has_magic(data) {
        Some(Format::Stl)
    } else if !format_name.rsplit('/').next().unwrap_or(format_name).contains('.') && obj::has_magic(data) {
        // Only for a name without an extension (a pipe: `/dev/fd/63`, `/dev/stdin`): a file
        // named `.3ds` holding OBJ-like text is more likely misnamed than OBJ.
        Some(Format::Obj)
    } else {
        None
    }
}

/// Picks the format by `format_name`'s extension, else by content.
fn parse(
    data: &[u8],
    name: &str,
    format_name: &str,
    dir: Option<&Path>,
    options: &LoadOptions,
) -> Result<(Mesh, LoadReport), MeshError> {
    match format_of(format_name, data) {
        Some(Format::Obj) => obj::parse(data, name, options),
        Some(Format::Ply) => ply::parse(data, name, options),
        Some(Format::Off) => off::parse(data, name, options),
        Some(Format::Stl) => stl::parse(data, name, options),
        Some(Format::Gltf) => gltf::parse(data, name, dir, options),
        None => Err(MeshError::new(
            name,
            "unknown mesh format: expected .obj, .ply, .off, .stl, .gltf or .glb (optionally .gz)",
        )),
    }
}

/// Inflates `data`, at most `max` bytes of it, growing the buffer by fallible reservations: a
/// file that inflates further, or beyond what memory can hold, is an error rather than an abort.
fn gunzip(data: &[u8], name: &str, max: u64) -> Result<Vec<u8>, MeshError> {
    let mut raw: Vec<u8> = Vec::new();
    // Multi-member: `cat a.gz b.gz` is valid gzip and some tools write it.
    let mut decoder = flate2::read::MultiGzDecoder::new(data);
    let mut chunk = [0u8; 1 << 16];
    loop {
        let n = match decoder.read(&mut chunk) {
            Ok(0) => return Ok(raw),
            Ok(n) => n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(MeshError::io(name, "gzip data is corrupt or truncated", e)),
        };
        if (raw.len() + n) as u64 > max {
            return Err(MeshError::new(
                name,
                std::format!("inflates to more than {max} bytes, the limit for decompressed meshes (LoadOptions::max_inflated; the CLI's --max-mesh-bytes)"),
            ));
        }
        // Doubling, as `Vec` grows, but asking first.
        if raw.capacity() - raw.len() < n {
            let room = usize::try_from(max).unwrap_or(usize::MAX) - raw.len();
            let want = raw.capacity().max(n).min(room);
            raw.try_reserve(want).map_err(|_| {
                MeshError::new(
                    name,
                    std::format!("cannot hold {} bytes of decompressed data in memory", raw.len() + want),
                )
            })?;
        }
        raw.extend_from_slice(&chunk[..n]);
    }
}

fn strip_suffix_ignore_case<'a>(s: &'a str, suffix: &str) -> Option<&'a str> {
    let cut = s.len().checked_sub(suffix.len())?;
    let (head, tail) = (s.get(..cut)?, s.get(cut..)?);
    tail.eq_ignore_ascii_case(suffix).then_some(head)
}

/// The words of a line of text, split at ASCII whitespace.
fn words(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(u8::is_ascii_whitespace).filter(|w| !w.is_empty())
}

/// A byte string for messages, shortened.
fn show(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(bytes);
    match text.char_indices().nth(40) {
        Some((cut, _)) => std::format!("{}...", &text[..cut]),
        None => text.into_owned(),
    }
}

/// The message of a caught panic.
fn panic_message(payload: std::boxed::Box<dyn std::any::Any + Send>) -> String {
    match payload.downcast::<String>() {
        Ok(s) => *s,
        Err(payload) => payload.downcast_ref::<&str>().map_or_else(|| String::from("unknown panic"), |s| (*s).into()),
    }
}

/// The most vertices a mesh may have: indices are `u32`.
const MAX_VERTICES: u64 = 1 << 32;

/// The most triangles a mesh may have: primitive ids are `u32`, and `u32::MAX` marks a miss.
const MAX_TRIANGLES: u64 = u32::MAX as u64;

#[cfg(test)]
mod tests {
    use super::*;
    use std::format;
    use std::io::Write;

    fn gzip(data: &[u8]) -> Vec<u8> {
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        enc.write_all(data).unwrap();
        enc.finish().unwrap()
    }

    const QUAD_OBJ: &[u8] = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    const TRI_PLY: &[u8] = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    const TRI_OFF: &[u8] = b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    const TRI_STL: &[u8] = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n\
endloop\nendfacet\nendsolid t\n";

    #[test]
    fn a_gzip_that_inflates_past_the_limit_is_an_error() {
        let big = std::vec![b'#'; 3 << 20];
        let small = gzip(&big);
        assert!(small.len() < 64 << 10, "{} bytes of gzip", small.len());
        let options = LoadOptions { max_inflated: 1 << 20, ..LoadOptions::default() };
        let err = load_bytes_with(&small, "bomb.obj.gz", &options).unwrap_err().to_string();
        assert!(err.contains("inflates to more than 1048576 bytes"), "{err}");
        // Under the default limit the same file inflates (and is an OBJ of comments: no triangles).
        assert!(load_bytes(&small, "bomb.obj.gz").map(|m| m.triangles.is_empty()).unwrap_or(true));
    }

    #[test]
    fn obj_without_a_name_to_go_by_is_known_by_its_statements() {
        for text in [
            &b"# a comment\n\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"[..],
            b"mtllib a.mtl\no x\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        ] {
            assert_eq!(load_bytes(text, "/dev/fd/63").map(|m| m.triangles.len()).map_err(|e| e.to_string()), Ok(1));
        }
        let err = load_bytes(b"hello\nv 0 0 0\n", "/dev/fd/63").unwrap_err().to_string();
        assert!(err.contains("unknown mesh format"), "{err}");
    }

    #[test]
    fn every_format_refuses_triangles_past_the_limit() {
        let quad_ply = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
        let quad_off = b"OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
        let quad_stl = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\n\
vertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        let mut binary_stl = std::vec![0u8; 80];
        binary_stl.extend(2u32.to_le_bytes());
        binary_stl.extend(std::vec![0u8; 100]);
        let files: [(&str, &[u8]); 5] = [
            ("q.obj", QUAD_OBJ),
            ("q.ply", quad_ply),
            ("q.off", quad_off),
            ("q.stl", quad_stl),
            ("b.stl", &binary_stl),
        ];
        for (name, data) in files {
            // Each file makes two triangles (a quad split in two, or two binary facets).
            let at = |max| load_bytes_with(data, name, &LoadOptions { max_triangles: max, ..LoadOptions::default() });
            assert_eq!(at(2).map(|(m, _)| m.triangles.len()).map_err(|e| e.to_string()), Ok(2), "{name}");
            let err = at(1).unwrap_err().to_string();
            assert!(err.contains("2 triangles, more than the limit of 1 (LoadOptions::max_triangles"), "{name}: {err}");
        }
    }

    #[test]
    fn dispatch_by_extension_and_gzip_magic() {
        assert_eq!(load_bytes(QUAD_OBJ, "a.obj").unwrap().triangles, [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(load_bytes(&gzip(QUAD_OBJ), "a.OBJ.GZ").unwrap().triangles.len(), 2);
        // Gzip is sniffed whatever the name says.
        assert_eq!(load_bytes(&gzip(QUAD_OBJ), "a.obj").unwrap().triangles.len(), 2);
        assert_eq!(load_bytes(&gzip(TRI_PLY), "a.ply.gz").unwrap().triangles, [[0, 1, 2]]);
        assert_eq!(load_bytes(TRI_PLY, "no_extension").unwrap().triangles, [[0, 1, 2]]);
        assert_eq!(load_bytes(TRI_OFF, "a.Off").unwrap().triangles, [[0, 1, 2]]);
        assert_eq!(load_bytes(&gzip(TRI_STL), "a.stl.gz").unwrap().triangles, [[0, 1, 2]]);
    }

    #[test]
    fn dispatch_by_content() {
        assert_eq!(load_bytes(TRI_OFF, "mesh.data").unwrap().triangles, [[0, 1, 2]]);
        assert_eq!(load_bytes(TRI_STL, "mesh.data").unwrap().triangles, [[0, 1, 2]]);
        let gltf = br#"{"asset":{"version":"2.0"}}"#;
        assert_eq!(load_bytes(gltf, "mesh.data").unwrap(), Mesh::default());
        assert_eq!(format_of("x", b"glTF\x02\0\0\0"), Some(Format::Gltf));
        assert_eq!(format_of("x", b"\xef\xbb\xbf {\"asset\""), Some(Format::Gltf));
        // A binary STL whose size matches its count, with no `solid` keyword.
        let mut bin = std::vec![0u8; 84 + 50];
        bin[80] = 1;
        assert_eq!(format_of("x", &bin), Some(Format::Stl));
        // OBJ, which has no magic, by its statements, but only without an extension to go by.
        assert_eq!(format_of("x", QUAD_OBJ), Some(Format::Obj));
        assert_eq!(format_of("/dev/fd/63", QUAD_OBJ), Some(Format::Obj));
        assert_eq!(format_of("mesh.data", QUAD_OBJ), None);
    }

    #[test]
    fn dispatch_errors_name_the_file() {
        let e = load_bytes(b"", "empty.obj").unwrap_err();
        assert_eq!(format!("{e}"), "empty.obj: file is empty");
        let e = load_bytes(QUAD_OBJ, "plain.obj.gz").unwrap_err();
        assert!(format!("{e}").starts_with("plain.obj.gz: named .gz"), "{e}");
        let e = load_bytes(QUAD_OBJ, "mesh.3ds").unwrap_err();
        assert!(format!("{e}").starts_with("mesh.3ds: unknown mesh format"), "{e}");
        let e = load_bytes(&gzip(b""), "nothing.ply.gz").unwrap_err();
        assert!(format!("{e}").contains("empty after gzip"), "{e}");
    }

    #[test]
    fn missing_file_names_the_file() {
        let e = load(Path::new("/nonexistent/dir/x.obj")).unwrap_err();
        let text = format!("{e}");
        assert!(text.starts_with("/nonexistent/dir/x.obj: cannot read file: "), "{text}");
        assert!(std::error::Error::source(&e).is_some());
    }

    #[test]
    fn corrupt_gzip_is_an_error() {
        let mut gz = gzip(TRI_PLY);
        let mid = gz.len() / 2;
        gz[mid..].iter_mut().for_each(|b| *b ^= 0x5a);
        let e = load_bytes(&gz, "bad.ply.gz").unwrap_err();
        assert!(format!("{e}").starts_with("bad.ply.gz: gzip data is corrupt"), "{e}");
        // Truncated stream too.
        let gz = gzip(TRI_PLY);
        let e = load_bytes(&gz[..gz.len() - 10], "short.ply.gz").unwrap_err();
        assert!(format!("{e}").starts_with("short.ply.gz: gzip"), "{e}");
    }

    #[test]
    fn readers_parse_from_memory() {
        assert_eq!(load_obj(QUAD_OBJ, "q.obj").unwrap().positions.len(), 4);
        assert_eq!(load_ply(TRI_PLY, "t.ply").unwrap().positions.len(), 3);
    }

    #[test]
    fn report_summary_and_csv() {
        let mut report = LoadReport::default();
        assert_eq!(report.summary("a.obj"), None);
        report.skip(|| "line 7".into(), || "a face with 2 vertices".into());
        assert_eq!(
            report.summary("a.obj").unwrap(),
            "a.obj: skipped 1 element that is not a triangle or polygon, at line 7: a face with 2 vertices"
        );
        report.skip(|| "line 9".into(), || "a polyline (l)".into());
        assert_eq!(
            report.summary("a.obj").unwrap(),
            "a.obj: skipped 2 elements that are not triangles or polygons, the first at line 7: a face with 2 vertices"
        );
        let mut csv = Vec::new();
        write_sources_csv(&mut csv, "a,b.obj", &[Source::Line(3), Source::Line(3), Source::Line(5)]).unwrap();
        assert_eq!(
            String::from_utf8(csv).unwrap(),
            "prim,file,line\n0,\"a,b.obj\",3\n1,\"a,b.obj\",3\n2,\"a,b.obj\",5\n"
        );
        let mut csv = Vec::new();
        let g = Source::Gltf { node: 1, mesh: 2, primitive: 3, triangle: 4 };
        write_sources_csv(&mut csv, "m.glb", &[g]).unwrap();
        assert_eq!(String::from_utf8(csv).unwrap(), "prim,file,node,mesh,primitive,triangle\n0,m.glb,1,2,3,4\n");
    }
}
