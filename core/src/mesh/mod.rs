//! Mesh files: OBJ (through tobj) and PLY (ASCII and binary, optionally gzip).
//!
//! Every loader returns a [`Mesh`] whose primitive id is the triangle index in file order, with
//! polygons split as fans `(v0, vi, vi+1)`. Every failure is a [`MeshError`] naming the file and,
//! where there is one, the line (text) or byte offset (binary PLY).

mod error;
mod obj;
mod ply;

pub use error::MeshError;

use crate::scene::Mesh;
use std::io::{BufRead, Read};
use std::path::Path;
use std::string::ToString;
use std::vec::Vec;

/// Loads a mesh file: `.obj`, `.ply`, and either of them gzip-compressed (`.obj.gz`, `.ply.gz`).
///
/// Gzip is recognised by its magic bytes, whatever the name; the format then comes from the
/// extension (after any `.gz`), or from the content for other names (`ply` magic, else an error).
pub fn load(path: &Path) -> Result<Mesh, MeshError> {
    let name = path.display().to_string();
    let data = std::fs::read(path).map_err(|e| MeshError::io(&name, "cannot read file", e))?;
    load_bytes(&data, &name)
}

/// Loads a mesh from file contents held in memory; `name` is used for the format (as in
/// [`load`]) and in errors.
pub fn load_bytes(data: &[u8], name: &str) -> Result<Mesh, MeshError> {
    if data.is_empty() {
        return Err(MeshError::new(name, "file is empty"));
    }
    let stem = strip_suffix_ignore_case(name, ".gz");
    if data.starts_with(&GZIP_MAGIC) {
        let raw = gunzip(data, name)?;
        if raw.is_empty() {
            return Err(MeshError::new(name, "file is empty after gzip decompression"));
        }
        return parse(&raw, name, stem.unwrap_or(name));
    }
    if stem.is_some() {
        return Err(MeshError::new(name, "named .gz but not gzip data (no 1f 8b magic)"));
    }
    parse(data, name, name)
}

/// Parses an OBJ file from a reader; `name` is used in errors. Materials are ignored.
pub fn load_obj(mut reader: impl BufRead, name: &str) -> Result<Mesh, MeshError> {
    let mut data = Vec::new();
    reader.read_to_end(&mut data).map_err(|e| MeshError::io(name, "read failed", e))?;
    obj::parse(&data, name)
}

/// Parses a PLY file (ASCII, binary little- or big-endian) from a reader; `name` is used in
/// errors. Takes vertex `x`, `y`, `z` and the face list `vertex_indices` (or `vertex_index`).
pub fn load_ply(mut reader: impl BufRead, name: &str) -> Result<Mesh, MeshError> {
    let mut data = Vec::new();
    reader.read_to_end(&mut data).map_err(|e| MeshError::io(name, "read failed", e))?;
    ply::parse(&data, name)
}

const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// Picks the format by `format_name`'s extension, else by content.
fn parse(data: &[u8], name: &str, format_name: &str) -> Result<Mesh, MeshError> {
    if strip_suffix_ignore_case(format_name, ".obj").is_some() {
        obj::parse(data, name)
    } else if strip_suffix_ignore_case(format_name, ".ply").is_some() || ply::has_magic(data) {
        ply::parse(data, name)
    } else {
        Err(MeshError::new(name, "unknown mesh format: expected .obj or .ply (optionally .gz)"))
    }
}

fn gunzip(data: &[u8], name: &str) -> Result<Vec<u8>, MeshError> {
    let mut raw = Vec::new();
    // Multi-member: `cat a.gz b.gz` is valid gzip and some tools write it.
    flate2::read::MultiGzDecoder::new(data)
        .read_to_end(&mut raw)
        .map_err(|e| MeshError::io(name, "gzip data is corrupt or truncated", e))?;
    Ok(raw)
}

fn strip_suffix_ignore_case<'a>(s: &'a str, suffix: &str) -> Option<&'a str> {
    let cut = s.len().checked_sub(suffix.len())?;
    let (head, tail) = (s.get(..cut)?, s.get(cut..)?);
    tail.eq_ignore_ascii_case(suffix).then_some(head)
}

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

    #[test]
    fn dispatch_by_extension_and_gzip_magic() {
        assert_eq!(load_bytes(QUAD_OBJ, "a.obj").unwrap().triangles, [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(load_bytes(&gzip(QUAD_OBJ), "a.OBJ.GZ").unwrap().triangles.len(), 2);
        // Gzip is sniffed whatever the name says.
        assert_eq!(load_bytes(&gzip(QUAD_OBJ), "a.obj").unwrap().triangles.len(), 2);
        assert_eq!(load_bytes(&gzip(TRI_PLY), "a.ply.gz").unwrap().triangles, [[0, 1, 2]]);
        assert_eq!(load_bytes(TRI_PLY, "no_extension").unwrap().triangles, [[0, 1, 2]]);
    }

    #[test]
    fn dispatch_errors_name_the_file() {
        let e = load_bytes(b"", "empty.obj").unwrap_err();
        assert_eq!(format!("{e}"), "empty.obj: file is empty");
        let e = load_bytes(QUAD_OBJ, "plain.obj.gz").unwrap_err();
        assert!(format!("{e}").starts_with("plain.obj.gz: named .gz"), "{e}");
        let e = load_bytes(QUAD_OBJ, "mesh.stl").unwrap_err();
        assert!(format!("{e}").starts_with("mesh.stl: unknown mesh format"), "{e}");
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
}
