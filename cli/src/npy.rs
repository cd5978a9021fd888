//! NumPy `.npy` files of rays and hits, the CLI's exchange format (docs/ARCHITECTURE.md, "File formats").
//!
//! - Rays: a float32 array of shape `(N, 8)`, one row per ray: origin xyz, tmin, direction xyz,
//!   tmax (the memory layout of [`Ray`]).
//! - Hits: a structured array of shape `(N,)` with the fields `t <f4, prim <u4, u <f4, v <f4` (the
//!   memory layout of [`Hit`]); a miss has `t = +inf` and `prim = 0xFFFFFFFF`.
//!
//! The format is small enough to write by hand: the magic string `\x93NUMPY`, a two-byte version,
//! the header length (two bytes little-endian in version 1.0, four in 2.0 and 3.0), a Python dict
//! literal with the keys `descr`, `fortran_order` and `shape`, padded with spaces and a final
//! newline so the data starts at a multiple of 64 bytes, then the raw elements in C order.
//!
//! Writers produce version 1.0 (2.0 only if a header ever outgrew 64 KiB) with little-endian data:
//! the same bytes as `numpy.save` (checked against NumPy 2.4, which also leaves spare room in the
//! header for the first extent to grow). Readers accept versions 1.0, 2.0 and 3.0, either byte
//! order, and ignore anything after the array's data (as NumPy does). Every problem with the input
//! is an [`NpyError`] that names the file and what is wrong; nothing here panics on bad input, and
//! no allocation is sized from the header before the data backing it has been read.
//!
//! Why by hand and not through a crate (measured, not assumed): `npyz` 0.9.1 was put behind
//! these same functions and failed 5 of the 10 tests below. A shape such as
//! `(4611686018427387904, 8)` panics on overflow in its element count. A version 2.0 header
//! claiming 4 GiB gets a 4 GiB buffer before anything is read. Its errors are strings inside
//! `io::Error`, so the kinds below could only be guessed from message text, and truncation loses
//! the part and the sizes. It accepts extra and duplicate keys and rejects Python 2 `5L` shapes.
//! Its headers are not byte-identical to `numpy.save`'s. It was also slower on 10M rays through a
//! file: reading took 0.39–0.43 s against 0.20–0.25 s, and writing 0.51–0.54 s against
//! 0.21–0.23 s. Reading from memory it was faster, 0.14 s against 0.19 s. `ndarray-npy` 0.10
//! has no structured dtypes. A 74-byte file claiming `(1000000000, 8)` makes it allocate the
//! 32 GB up front, and the process aborts.

use raytrail::core::{Hit, Ray};
use std::fmt;
use std::fs::File;
use std::io::{self, BufReader, BufWriter, Read, Write};
use std::path::Path;

/// The first six bytes of every `.npy` file.
const MAGIC: &[u8; 6] = b"\x93NUMPY";
/// Data starts at a multiple of this many bytes (NumPy's `ARRAY_ALIGN`).
const ALIGN: usize = 64;
/// Largest header accepted; ours are under 128 bytes, NumPy itself refuses more than 10 000 by
/// default. Bounds the allocation a hostile header length can cause.
const MAX_HEADER_LEN: u64 = 1 << 20;
/// Digits NumPy reserves in the header for the first extent (`GROWTH_AXIS_MAX_DIGITS`).
const GROWTH_AXIS_MAX_DIGITS: usize = 21;
/// Bytes converted per step when streaming data in or out.
const CHUNK_BYTES: usize = 1 << 20;
/// Nesting bound of the header parser, so a hostile header cannot exhaust the stack.
const MAX_NESTING: u32 = 16;
/// What in-memory readers and writers call their source in errors (see [`NpyError::with_file`]).
const STREAM_NAME: &str = "<stream>";

/// The `descr` of a hit file, as `numpy.save` writes it.
pub const HIT_DESCR: &str = "[('t', '<f4'), ('prim', '<u4'), ('u', '<f4'), ('v', '<f4')]";
/// The `descr` of an all-hits file (`trace --all`): each hit with the index of its ray.
pub const LISTED_HIT_DESCR: &str = "[('ray', '<u4'), ('t', '<f4'), ('prim', '<u4'), ('u', '<f4'), ('v', '<f4')]";
/// The `descr` of a hit file of an instanced scene: each hit with its instance's id (a miss has
/// the id `0xFFFFFFFF`).
pub const INSTANCE_HIT_DESCR: &str = "[('t', '<f4'), ('prim', '<u4'), ('u', '<f4'), ('v', '<f4'), ('instance', '<u4')]";
/// Bytes per ray row.
const RAY_BYTES: usize = 32;
/// Bytes per hit record.
const HIT_BYTES: usize = 16;
/// Bytes per all-hits record.
const LISTED_HIT_BYTES: usize = 20;
/// Bytes per instanced hit record.
const INSTANCE_HIT_BYTES: usize = 20;

/// A failed `.npy` read or write: which file, and what is wrong with it.
#[derive(Debug)]
pub struct NpyError {
    file: String,
    kind: NpyErrorKind,
}

/// What went wrong with a `.npy` file.
#[derive(Debug)]
#[non_exhaustive]
pub enum NpyErrorKind {
    /// The operating system reported an error (opening, reading or writing).
    Io(io::Error),
    /// The file does not start with the `.npy` magic string.
    NotNpy {
        /// The first bytes found (up to six).
        found: Vec<u8>,
    },
    /// A format version other than 1.0, 2.0 or 3.0.
    UnsupportedVersion {
        /// Major version byte.
        major: u8,
        /// Minor version byte.
        minor: u8,
    },
    /// The header length field is implausibly large.
    HeaderTooLong {
        /// The length the file claims.
        len: u64,
    },
    /// The header is not the dict literal the format prescribes.
    MalformedHeader(String),
    /// The array is stored in Fortran (column-major) order.
    FortranOrder,
    /// The element type is not one this file kind allows.
    WrongDtype {
        /// The `descr` found, as written in the header.
        found: String,
        /// What is accepted.
        expected: &'static str,
    },
    /// The array has the wrong number of dimensions or extents.
    WrongShape {
        /// The shape found.
        found: Vec<u64>,
        /// What is accepted.
        expected: &'static str,
    },
    /// The array's byte size does not fit this machine's address space.
    TooLarge {
        /// The shape found.
        shape: Vec<u64>,
    },
    /// An element's value is outside what it stands for (a 64-bit mask above 32 bits).
    OutOfRange {
        /// The element's index.
        index: u64,
        /// Its value.
        value: u64,
        /// What it must fit in.
        limit: &'static str,
    },
    /// The file ends early.
    Truncated {
        /// Which part is cut short: `"preamble"` (magic, version, header length), `"header"`
        /// or `"data"`.
        part: &'static str,
        /// Bytes that part should have.
        expected: u64,
        /// Bytes present.
        found: u64,
    },
}

impl NpyError {
    fn new(file: &Path, kind: NpyErrorKind) -> Self {
        Self { file: file.display().to_string(), kind }
    }

    fn stream(kind: NpyErrorKind) -> Self {
        Self { file: STREAM_NAME.into(), kind }
    }

    /// The file (or `<stream>` for the in-memory readers and writers) the error is about.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// What is wrong.
    pub fn kind(&self) -> &NpyErrorKind {
        &self.kind
    }

    /// The same error, naming `file` instead: for callers of the in-memory variants that know
    /// better what the stream is (`<stdin>`, an archive member, …).
    pub fn with_file(mut self, file: impl Into<String>) -> Self {
        self.file = file.into();
        self
    }
}

impl fmt::Display for NpyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.file, self.kind)
    }
}

impl std::error::Error for NpyError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            NpyErrorKind::Io(e) => Some(e),
            _ => None,
        }
    }
}

impl fmt::Display for NpyErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NpyErrorKind::Io(e) => write!(f, "I/O error: {e}"),
            NpyErrorKind::NotNpy { found } => {
                write!(f, "not a .npy file: it starts with bytes {found:02x?}, not the magic string \\x93NUMPY")
            }
            NpyErrorKind::UnsupportedVersion { major, minor } => {
                write!(f, "unsupported .npy format version {major}.{minor} (1.0, 2.0 and 3.0 are supported)")
            }
            NpyErrorKind::HeaderTooLong { len } => {
                write!(f, "the header claims {len} bytes, more than the {MAX_HEADER_LEN} accepted")
            }
            NpyErrorKind::MalformedHeader(why) => write!(f, "malformed header: {why}"),
            NpyErrorKind::FortranOrder => write!(
                f,
                "the array is in Fortran (column-major) order; only C order is supported \
                 (save it with numpy.ascontiguousarray)"
            ),
            NpyErrorKind::WrongDtype { found, expected } => {
                write!(f, "dtype {found} is not supported; expected {expected}")
            }
            NpyErrorKind::WrongShape { found, expected } => {
                write!(f, "shape {} is not supported; expected {expected}", ShapeDisplay(found))
            }
            NpyErrorKind::TooLarge { shape } => {
                write!(f, "an array of shape {} is too large for this machine", ShapeDisplay(shape))
            }
            NpyErrorKind::OutOfRange { index, value, limit } => {
                write!(f, "element {index} is {value}, which does not fit in {limit}")
            }
            NpyErrorKind::Truncated { part, expected, found } => {
                write!(f, "truncated {part}: expected {expected} bytes, found {found}")
            }
        }
    }
}

/// A shape as Python writes a tuple: `(3, 8)`, `(5,)`, `()`.
struct ShapeDisplay<'a>(&'a [u64]);

impl fmt::Display for ShapeDisplay<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            [] => write!(f, "()"),
            [n] => write!(f, "({n},)"),
            [first, rest @ ..] => {
                write!(f, "({first}")?;
                for n in rest {
                    write!(f, ", {n}")?;
                }
                write!(f, ")")
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Public entry points.

/// Reads rays from the `.npy` file at `path`.
///
/// Accepts a float array of shape `(N, 8)` in C order, one ray per row (origin xyz, tmin, direction
/// xyz, tmax): `<f4` or `>f4` (big-endian data is converted), and also float64 (`<f8` or `>f8`),
/// whose values are rounded to the nearest float32 (values beyond the float32 range become
/// infinite). Rays with NaN components are passed through unchanged: tracing treats them as misses.
pub fn read_rays(path: impl AsRef<Path>) -> Result<Vec<Ray>, NpyError> {
    let path = path.as_ref();
    let file = File::open(path).map_err(|e| NpyError::new(path, NpyErrorKind::Io(e)))?;
    read_rays_impl(&mut BufReader::new(file)).map_err(|k| NpyError::new(path, k))
}

/// Reads rays in `.npy` format from `reader`, as [`read_rays`] does; errors name the source
/// `<stream>` (rename it with [`NpyError::with_file`]).
pub fn read_rays_from(mut reader: impl Read) -> Result<Vec<Ray>, NpyError> {
    read_rays_impl(&mut reader).map_err(NpyError::stream)
}

/// Reads query points from the `.npy` file at `path`: a float array of shape `(N, 3)`, one point
/// per row, of the dtypes [`read_rays`] takes.
pub fn read_points(path: impl AsRef<Path>) -> Result<Vec<[f32; 3]>, NpyError> {
    let path = path.as_ref();
    let file = File::open(path).map_err(|e| NpyError::new(path, NpyErrorKind::Io(e)))?;
    read_float_rows::<3>(&mut BufReader::new(file), "(N, 3)").map_err(|k| NpyError::new(path, k))
}

/// Reads ray masks from the `.npy` file at `path` (`trace --masks`): an unsigned integer array of
/// shape `(N,)` (`<u4`, `>u4`, or `u1`, `u2`, `u8` whose values fit in 32 bits), one mask per ray.
pub fn read_masks(path: impl AsRef<Path>) -> Result<Vec<u32>, NpyError> {
    let path = path.as_ref();
    let file = File::open(path).map_err(|e| NpyError::new(path, NpyErrorKind::Io(e)))?;
    read_masks_impl(&mut BufReader::new(file)).map_err(|k| NpyError::new(path, k))
}

fn read_masks_impl(r: &mut impl Read) -> Result<Vec<u32>, NpyErrorKind> {
    const EXPECTED_DTYPE: &str = "an unsigned integer ('u1', '<u2', '<u4' or '<u8', either byte order)";
    let header = read_header(r)?;
    let wrong = || NpyErrorKind::WrongDtype { found: header.descr.to_string(), expected: EXPECTED_DTYPE };
    let Value::Str(descr) = &header.descr else {
        return Err(wrong());
    };
    let scalar = parse_scalar(descr).filter(|s| s.kind == b'u' && [1, 2, 4, 8].contains(&s.size)).ok_or_else(wrong)?;
    let n = match header.shape[..] {
        [n] => n,
        _ => return Err(NpyErrorKind::WrongShape { found: header.shape, expected: "(N,)" }),
    };
    check_order(&header)?;
    let total = byte_size(&header.shape, scalar.size)?;
    let values = read_records(r, n, scalar.size, total, |b| match scalar.size {
        1 => u64::from(b[0]),
        2 if scalar.big_endian => u64::from(u16::from_be_bytes([b[0], b[1]])),
        2 => u64::from(u16::from_le_bytes([b[0], b[1]])),
        4 => u64::from(u32_at(b, 0, scalar.big_endian)),
        _ => u64_at(b, 0, scalar.big_endian),
    })?;
    values
        .into_iter()
        .enumerate()
        .map(|(i, m)| {
            u32::try_from(m).map_err(|_| NpyErrorKind::OutOfRange { index: i as u64, value: m, limit: "32 bits" })
        })
        .collect()
}

/// The `descr` of a nearest-point file (`raytrail nearest`).
pub const NEAREST_DESCR: &str =
    "[('prim', '<u4'), ('distance', '<f4'), ('x', '<f4'), ('y', '<f4'), ('z', '<f4'), ('u', '<f4'), ('v', '<f4')]";

/// Writes the nearest points to `path` as a `.npy` structured array of shape `(N,)` with the dtype
/// [`NEAREST_DESCR`]; where there is none, `prim = 0xFFFFFFFF`, `distance = inf`, `x y z` NaN and
/// `u v` 0.
pub fn write_nearest(path: impl AsRef<Path>, found: &[Option<raytrail::NearestPoint>]) -> Result<(), NpyError> {
    let path = path.as_ref();
    write_file(path, |w| {
        write_header(w, NEAREST_DESCR, &[found.len()])?;
        write_records(w, found, 28, |f, out| {
            let (prim, d, p, u, v) = match f {
                Some(f) => (f.prim, f.distance, f.point, f.u, f.v),
                None => (Hit::NO_PRIM, f32::INFINITY, [f32::NAN; 3], 0.0, 0.0),
            };
            out.extend_from_slice(&prim.to_le_bytes());
            out.extend_from_slice(&d.to_le_bytes());
            for x in p.iter().chain([u, v].iter()) {
                out.extend_from_slice(&x.to_le_bytes());
            }
        })
    })
}

/// Writes `rays` to `path` as a little-endian float32 `.npy` array of shape `(N, 8)`, replacing
/// any existing file only once the new one is complete.
pub fn write_rays(path: impl AsRef<Path>, rays: &[Ray]) -> Result<(), NpyError> {
    let path = path.as_ref();
    write_file(path, |w| write_rays_impl(w, rays))
}

/// Writes `rays` in `.npy` format to `writer`, as [`write_rays`] does. The writer is not flushed.
pub fn write_rays_to(mut writer: impl Write, rays: &[Ray]) -> Result<(), NpyError> {
    write_rays_impl(&mut writer, rays).map_err(|e| NpyError::stream(NpyErrorKind::Io(e)))
}

/// Reads hits from the `.npy` file at `path`.
///
/// Accepts a structured array of shape `(N,)` whose dtype has exactly the fields `t` (float32),
/// `prim` (uint32), `u` (float32), `v` (float32) in that order, packed, each in either byte order
/// (see [`HIT_DESCR`]).
pub fn read_hits(path: impl AsRef<Path>) -> Result<Vec<Hit>, NpyError> {
    let path = path.as_ref();
    let file = File::open(path).map_err(|e| NpyError::new(path, NpyErrorKind::Io(e)))?;
    read_hits_impl(&mut BufReader::new(file)).map_err(|k| NpyError::new(path, k))
}

/// Reads hits in `.npy` format from `reader`, as [`read_hits`] does; errors name the source
/// `<stream>` (rename it with [`NpyError::with_file`]).
pub fn read_hits_from(mut reader: impl Read) -> Result<Vec<Hit>, NpyError> {
    read_hits_impl(&mut reader).map_err(NpyError::stream)
}

/// Writes `hits` to `path` as a `.npy` structured array of shape `(N,)` with the dtype
/// [`HIT_DESCR`] (little-endian), replacing any existing file only once the new one is complete. Misses are written as they are
/// ([`Hit::MISS`]: `t = +inf`, `prim = 0xFFFFFFFF`).
pub fn write_hits(path: impl AsRef<Path>, hits: &[Hit]) -> Result<(), NpyError> {
    let path = path.as_ref();
    write_file(path, |w| write_hits_impl(w, hits))
}

/// Writes the hit lists of `lists` to `path` as a `.npy` structured array of shape `(H,)`, one
/// record per hit with the dtype [`LISTED_HIT_DESCR`]: the rays' lists one after another, each in
/// order of `t`. Ray indices past `u32::MAX` are an error (the CLI's rays stay far below).
pub fn write_hit_lists(path: impl AsRef<Path>, lists: &raytrail::AllHits) -> Result<(), NpyError> {
    let path = path.as_ref();
    if lists.len() > u32::MAX as usize + 1 {
        let e = io::Error::new(io::ErrorKind::InvalidInput, "more rays than a u32 ray index can name");
        return Err(NpyError::new(path, NpyErrorKind::Io(e)));
    }
    write_file(path, |w| {
        write_header(w, LISTED_HIT_DESCR, &[lists.hits().len()])?;
        let records: Vec<(u32, Hit)> =
            lists.iter().enumerate().flat_map(|(i, l)| l.iter().map(move |h| (i as u32, *h))).collect();
        write_records(w, &records, LISTED_HIT_BYTES, |(ray, hit), out| {
            out.extend_from_slice(&ray.to_le_bytes());
            out.extend_from_slice(&hit.t.to_le_bytes());
            out.extend_from_slice(&hit.prim.to_le_bytes());
            out.extend_from_slice(&hit.u.to_le_bytes());
            out.extend_from_slice(&hit.v.to_le_bytes());
        })
    })
}

/// Writes the hits of an instanced scene to `path` as a `.npy` structured array of shape `(N,)`
/// with the dtype [`INSTANCE_HIT_DESCR`], atomically as [`write_hits`] does.
pub fn write_instance_hits(path: impl AsRef<Path>, hits: &[raytrail::InstanceHit]) -> Result<(), NpyError> {
    write_file(path.as_ref(), |w| {
        write_header(w, INSTANCE_HIT_DESCR, &[hits.len()])?;
        write_records(w, hits, INSTANCE_HIT_BYTES, |hit, out| {
            for word in [hit.t.to_bits(), hit.prim, hit.u.to_bits(), hit.v.to_bits(), hit.instance] {
                out.extend_from_slice(&word.to_le_bytes());
            }
        })
    })
}

/// Writes `hits` in `.npy` format to `writer`, as [`write_hits`] does. The writer is not flushed.
pub fn write_hits_to(mut writer: impl Write, hits: &[Hit]) -> Result<(), NpyError> {
    write_hits_impl(&mut writer, hits).map_err(|e| NpyError::stream(NpyErrorKind::Io(e)))
}

// ---------------------------------------------------------------------------------------------
// Rays and hits over the generic machinery.

fn read_rays_impl(r: &mut impl Read) -> Result<Vec<Ray>, NpyErrorKind> {
    let rows = read_float_rows::<8>(r, "(N, 8)")?;
    Ok(rows
        .into_iter()
        .map(|f| Ray { origin: [f[0], f[1], f[2]], tmin: f[3], dir: [f[4], f[5], f[6]], tmax: f[7] })
        .collect())
}

/// The rows of a float array of shape `(N, C)` in C order (`<f4`, `>f4`, or `<f8`/`>f8` rounded to
/// float32, beyond its range to infinity; NaN stays NaN); `shape` names the expected shape in
/// errors.
fn read_float_rows<const C: usize>(r: &mut impl Read, shape: &'static str) -> Result<Vec<[f32; C]>, NpyErrorKind> {
    const EXPECTED_DTYPE: &str = "float32 ('<f4' or '>f4') or float64 ('<f8' or '>f8')";
    let header = read_header(r)?;
    let Value::Str(descr) = &header.descr else {
        return Err(NpyErrorKind::WrongDtype { found: header.descr.to_string(), expected: EXPECTED_DTYPE });
    };
    let scalar = parse_scalar(descr)
        .filter(|s| s.kind == b'f' && (s.size == 4 || s.size == 8))
        .ok_or_else(|| NpyErrorKind::WrongDtype { found: header.descr.to_string(), expected: EXPECTED_DTYPE })?;
    let n = match header.shape[..] {
        [n, c] if c == C as u64 => n,
        _ => return Err(NpyErrorKind::WrongShape { found: header.shape, expected: shape }),
    };
    check_order(&header)?;
    let row_bytes = C * scalar.size;
    let total = byte_size(&header.shape, row_bytes)?;
    read_records(r, n, row_bytes, total, |row| {
        let mut f = [0.0f32; C];
        for (i, x) in f.iter_mut().enumerate() {
            *x = if scalar.size == 4 {
                f32::from_bits(u32_at(row, 4 * i, scalar.big_endian))
            } else {
                // Rounds to nearest, overflowing to ±inf; NaN stays NaN.
                f64::from_bits(u64_at(row, 8 * i, scalar.big_endian)) as f32
            };
        }
        f
    })
}

fn read_hits_impl(r: &mut impl Read) -> Result<Vec<Hit>, NpyErrorKind> {
    let header = read_header(r)?;
    let endian = hit_fields(&header.descr)
        .ok_or_else(|| NpyErrorKind::WrongDtype { found: header.descr.to_string(), expected: HIT_DESCR })?;
    let n = match header.shape[..] {
        [n] => n,
        _ => return Err(NpyErrorKind::WrongShape { found: header.shape, expected: "(N,)" }),
    };
    // A one-dimensional array reads the same in either order, as NumPy itself treats it.
    let total = byte_size(&header.shape, HIT_BYTES)?;
    read_records(r, n, HIT_BYTES, total, |rec| Hit {
        t: f32::from_bits(u32_at(rec, 0, endian[0])),
        prim: u32_at(rec, 4, endian[1]),
        u: f32::from_bits(u32_at(rec, 8, endian[2])),
        v: f32::from_bits(u32_at(rec, 12, endian[3])),
    })
}

/// The byte order of each field if `descr` is the hit dtype (in any byte orders), else `None`.
fn hit_fields(descr: &Value) -> Option<[bool; 4]> {
    const FIELDS: [(&str, u8); 4] = [("t", b'f'), ("prim", b'u'), ("u", b'f'), ("v", b'f')];
    let Value::List(fields) = descr else { return None };
    if fields.len() != FIELDS.len() {
        return None;
    }
    let mut big_endian = [false; 4];
    for ((field, (name, kind)), big) in fields.iter().zip(FIELDS).zip(&mut big_endian) {
        let Value::Tuple(parts) = field else { return None };
        let [Value::Str(n), Value::Str(ty)] = &parts[..] else { return None };
        let s = parse_scalar(ty)?;
        if n != name || s.kind != kind || s.size != 4 {
            return None;
        }
        *big = s.big_endian;
    }
    Some(big_endian)
}

fn write_rays_impl(w: &mut impl Write, rays: &[Ray]) -> io::Result<()> {
    write_header(w, "'<f4'", &[rays.len(), 8])?;
    write_records(w, rays, RAY_BYTES, |ray, out| {
        let row = [ray.origin[0], ray.origin[1], ray.origin[2], ray.tmin, ray.dir[0], ray.dir[1], ray.dir[2], ray.tmax];
        for x in row {
            out.extend_from_slice(&x.to_le_bytes());
        }
    })
}

fn write_hits_impl(w: &mut impl Write, hits: &[Hit]) -> io::Result<()> {
    write_header(w, HIT_DESCR, &[hits.len()])?;
    write_records(w, hits, HIT_BYTES, |hit, out| {
        out.extend_from_slice(&hit.t.to_le_bytes());
        out.extend_from_slice(&hit.prim.to_le_bytes());
        out.extend_from_slice(&hit.u.to_le_bytes());
        out.extend_from_slice(&hit.v.to_le_bytes());
    })
}

/// Writes `path` atomically ([`crate::write::write_atomically`]): a failed write leaves any
/// previous file untouched.
fn write_file(path: &Path, body: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>) -> Result<(), NpyError> {
    crate::write::write_atomically(path, body).map_err(|e| NpyError::new(path, NpyErrorKind::Io(e)))
}

// ---------------------------------------------------------------------------------------------
// The format itself.

/// The three header entries.
struct Header {
    descr: Value,
    fortran_order: bool,
    shape: Vec<u64>,
}

fn check_order(header: &Header) -> Result<(), NpyErrorKind> {
    if header.fortran_order {
        Err(NpyErrorKind::FortranOrder)
    } else {
        Ok(())
    }
}

/// Bytes of data in an array of `shape` whose first-axis entries (a ray row, a hit record) take
/// `unit_bytes` each, checked against overflow and this machine's address space.
fn byte_size(shape: &[u64], unit_bytes: usize) -> Result<u64, NpyErrorKind> {
    let units = shape.first().copied().unwrap_or(1);
    units
        .checked_mul(unit_bytes as u64)
        .filter(|&b| usize::try_from(b).is_ok())
        .ok_or_else(|| NpyErrorKind::TooLarge { shape: shape.to_vec() })
}

/// Reads as many bytes as `buf` holds unless the stream ends first; returns how many were read.
fn fill(r: &mut impl Read, buf: &mut [u8]) -> Result<usize, NpyErrorKind> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(NpyErrorKind::Io(e)),
        }
    }
    Ok(got)
}

fn read_header(r: &mut impl Read) -> Result<Header, NpyErrorKind> {
    let mut pre = [0u8; 8];
    let got = fill(r, &mut pre)?;
    let magic_len = got.min(MAGIC.len());
    if pre[..magic_len] != MAGIC[..magic_len] {
        return Err(NpyErrorKind::NotNpy { found: pre[..magic_len].to_vec() });
    }
    if got < pre.len() {
        return Err(NpyErrorKind::Truncated { part: "preamble", expected: 10, found: got as u64 });
    }
    let (major, minor) = (pre[6], pre[7]);
    let len_bytes = match (major, minor) {
        (1, 0) => 2,
        (2, 0) | (3, 0) => 4,
        _ => return Err(NpyErrorKind::UnsupportedVersion { major, minor }),
    };
    let mut len_buf = [0u8; 4];
    let got = fill(r, &mut len_buf[..len_bytes])?;
    if got < len_bytes {
        return Err(NpyErrorKind::Truncated {
            part: "preamble",
            expected: 8 + len_bytes as u64,
            found: 8 + got as u64,
        });
    }
    let len = u64::from(u32::from_le_bytes(len_buf));
    if len > MAX_HEADER_LEN {
        return Err(NpyErrorKind::HeaderTooLong { len });
    }
    let mut raw = vec![0u8; len as usize];
    let got = fill(r, &mut raw)?;
    if got < raw.len() {
        return Err(NpyErrorKind::Truncated { part: "header", expected: len, found: got as u64 });
    }
    // Versions 1 and 2 store the header in latin-1, version 3 in UTF-8.
    let text: String = if major == 3 {
        String::from_utf8(raw).map_err(|_| NpyErrorKind::MalformedHeader("a version 3.0 header is not UTF-8".into()))?
    } else {
        raw.iter().map(|&b| char::from(b)).collect()
    };
    parse_header(&text).map_err(NpyErrorKind::MalformedHeader)
}

fn parse_header(text: &str) -> Result<Header, String> {
    let chars: Vec<char> = text.chars().collect();
    let mut p = Parser { s: &chars, i: 0 };
    let value = p.value(0)?;
    p.skip_ws();
    if p.i != chars.len() {
        return Err(format!("unexpected {:?} after the dict", p.s[p.i]));
    }
    let Value::Dict(entries) = value else {
        return Err(format!("expected a dict, found {value}"));
    };
    let (mut descr, mut fortran_order, mut shape) = (None, None, None);
    for (key, value) in entries {
        let slot = match &key {
            Value::Str(k) if k == "descr" => &mut descr,
            Value::Str(k) if k == "fortran_order" => &mut fortran_order,
            Value::Str(k) if k == "shape" => &mut shape,
            _ => return Err(format!("unexpected key {key} (only 'descr', 'fortran_order' and 'shape' belong there)")),
        };
        if slot.replace(value).is_some() {
            return Err(format!("key {key} appears twice"));
        }
    }
    let missing = |k: &str| format!("the key '{k}' is missing");
    let descr = descr.ok_or_else(|| missing("descr"))?;
    let fortran_order = match fortran_order.ok_or_else(|| missing("fortran_order"))? {
        Value::Bool(b) => b,
        v => return Err(format!("'fortran_order' is {v}, not True or False")),
    };
    let shape = match shape.ok_or_else(|| missing("shape"))? {
        Value::Tuple(items) => items
            .iter()
            .map(|v| match v {
                Value::Int(n) => Ok(*n),
                v => Err(format!("shape entry {v} is not a non-negative integer")),
            })
            .collect::<Result<Vec<u64>, String>>()?,
        v => return Err(format!("'shape' is {v}, not a tuple")),
    };
    Ok(Header { descr, fortran_order, shape })
}

/// A scalar dtype string such as `'<f4'`.
#[derive(Clone, Copy)]
struct Scalar {
    big_endian: bool,
    kind: u8,
    size: usize,
}

/// Parses `[<>=|]?` + kind letter + size in bytes; `=` and no prefix mean this machine's order.
fn parse_scalar(s: &str) -> Option<Scalar> {
    let b = s.as_bytes();
    let (big_endian, rest) = match b.first()? {
        b'<' => (false, &b[1..]),
        b'>' => (true, &b[1..]),
        b'=' => (cfg!(target_endian = "big"), &b[1..]),
        b'|' => (false, &b[1..]),
        _ => (cfg!(target_endian = "big"), b),
    };
    let (&kind, digits) = rest.split_first()?;
    if digits.is_empty() || digits.len() > 2 || !digits.iter().all(u8::is_ascii_digit) {
        return None;
    }
    let size = digits.iter().fold(0usize, |n, d| n * 10 + usize::from(d - b'0'));
    // `|` (byte order not applicable) only makes sense for one-byte types.
    if b[0] == b'|' && size != 1 {
        return None;
    }
    Some(Scalar { big_endian, kind, size })
}

#[inline]
fn u32_at(b: &[u8], at: usize, big_endian: bool) -> u32 {
    let bytes = [b[at], b[at + 1], b[at + 2], b[at + 3]];
    if big_endian {
        u32::from_be_bytes(bytes)
    } else {
        u32::from_le_bytes(bytes)
    }
}

#[inline]
fn u64_at(b: &[u8], at: usize, big_endian: bool) -> u64 {
    let mut bytes = [0u8; 8];
    bytes.copy_from_slice(&b[at..at + 8]);
    if big_endian {
        u64::from_be_bytes(bytes)
    } else {
        u64::from_le_bytes(bytes)
    }
}

/// Reads `count` records of `size` bytes (`total` bytes in all) in chunks, decoding each. The
/// output grows only as data arrives, so a header claiming a huge shape over a short file costs
/// nothing but the error.
fn read_records<T>(
    r: &mut impl Read,
    count: u64,
    size: usize,
    total: u64,
    mut decode: impl FnMut(&[u8]) -> T,
) -> Result<Vec<T>, NpyErrorKind> {
    let per_chunk = (CHUNK_BYTES / size).max(1);
    let mut out = Vec::with_capacity(count.min(per_chunk as u64) as usize);
    let mut buf = vec![0u8; count.min(per_chunk as u64) as usize * size];
    let (mut remaining, mut read) = (count, 0u64);
    while remaining > 0 {
        let want = remaining.min(per_chunk as u64) as usize * size;
        let got = fill(r, &mut buf[..want])?;
        read += got as u64;
        if got < want {
            return Err(NpyErrorKind::Truncated { part: "data", expected: total, found: read });
        }
        // Fallible: a file of real data larger than the memory is an error, not an abort.
        out.try_reserve(want / size).map_err(|_| NpyErrorKind::TooLarge { shape: vec![count] })?;
        out.extend(buf[..want].chunks_exact(size).map(&mut decode));
        remaining -= (want / size) as u64;
    }
    Ok(out)
}

/// Writes the preamble and the header dict (`descr` is a Python literal), padded with spaces and
/// a newline so that the data starts at a multiple of [`ALIGN`] bytes.
fn write_header(w: &mut impl Write, descr: &str, shape: &[usize]) -> io::Result<()> {
    let shape_u64: Vec<u64> = shape.iter().map(|&n| n as u64).collect();
    let mut dict = format!("{{'descr': {descr}, 'fortran_order': False, 'shape': {}, }}", ShapeDisplay(&shape_u64));
    // NumPy leaves room for the first extent to grow to 21 digits in place; doing the same makes
    // the files byte-identical to `numpy.save`'s.
    if let Some(n) = shape.first() {
        let digits = n.to_string().len();
        dict.extend(std::iter::repeat_n(' ', GROWTH_AXIS_MAX_DIGITS.saturating_sub(digits)));
    }
    // Version 1.0 (two length bytes) whenever the header fits, as NumPy does.
    let (version, len_bytes) = if 10 + dict.len() < usize::from(u16::MAX) - ALIGN { (1u8, 2) } else { (2u8, 4) };
    let preamble = MAGIC.len() + 2 + len_bytes;
    // Spaces up to the alignment, then the newline; NumPy pads a whole extra 64 bytes where no
    // space would be needed, and so do we.
    let header_len = dict.len() + 1 + ALIGN - (preamble + dict.len() + 1) % ALIGN;
    let mut out = Vec::with_capacity(preamble + header_len);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[version, 0]);
    if len_bytes == 2 {
        out.extend_from_slice(&(header_len as u16).to_le_bytes());
    } else {
        let len = u32::try_from(header_len).map_err(|_| io::Error::other("npy header longer than 4 GiB"))?;
        out.extend_from_slice(&len.to_le_bytes());
    }
    out.extend_from_slice(dict.as_bytes());
    out.resize(preamble + header_len - 1, b' ');
    out.push(b'\n');
    w.write_all(&out)
}

/// Encodes `items` little-endian in chunks of about [`CHUNK_BYTES`] and writes them.
fn write_records<T>(w: &mut impl Write, items: &[T], size: usize, encode: impl Fn(&T, &mut Vec<u8>)) -> io::Result<()> {
    let per_chunk = (CHUNK_BYTES / size).max(1);
    let mut buf = Vec::with_capacity(per_chunk.min(items.len()) * size);
    for chunk in items.chunks(per_chunk) {
        buf.clear();
        for item in chunk {
            encode(item, &mut buf);
        }
        w.write_all(&buf)?;
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// A parser for the subset of Python literals a header uses.

/// A Python literal.
enum Value {
    Str(String),
    Int(u64),
    Bool(bool),
    None,
    Tuple(Vec<Value>),
    List(Vec<Value>),
    Dict(Vec<(Value, Value)>),
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fn seq(f: &mut fmt::Formatter<'_>, items: &[Value], open: &str, close: &str) -> fmt::Result {
            write!(f, "{open}")?;
            for (i, v) in items.iter().enumerate() {
                if i > 0 {
                    write!(f, ", ")?;
                }
                write!(f, "{v}")?;
            }
            if open == "(" && items.len() == 1 {
                write!(f, ",")?;
            }
            write!(f, "{close}")
        }
        match self {
            Value::Str(s) => write!(f, "'{s}'"),
            Value::Int(n) => write!(f, "{n}"),
            Value::Bool(b) => write!(f, "{}", if *b { "True" } else { "False" }),
            Value::None => write!(f, "None"),
            Value::Tuple(items) => seq(f, items, "(", ")"),
            Value::List(items) => seq(f, items, "[", "]"),
            Value::Dict(entries) => {
                write!(f, "{{")?;
                for (i, (k, v)) in entries.iter().enumerate() {
                    if i > 0 {
                        write!(f, ", ")?;
                    }
                    write!(f, "{k}: {v}")?;
                }
                write!(f, "}}")
            }
        }
    }
}

struct Parser<'a> {
    s: &'a [char],
    i: usize,
}

impl Parser<'_> {
    fn skip_ws(&mut self) {
        while self.s.get(self.i).is_some_and(|c| c.is_whitespace()) {
            self.i += 1;
        }
    }

    fn peek(&mut self) -> Option<char> {
        self.skip_ws();
        self.s.get(self.i).copied()
    }

    fn unexpected(&self, wanted: &str) -> String {
        match self.s.get(self.i) {
            Some(c) => format!("expected {wanted}, found {c:?} at offset {}", self.i),
            None => format!("expected {wanted}, found the end of the header"),
        }
    }

    fn value(&mut self, depth: u32) -> Result<Value, String> {
        if depth > MAX_NESTING {
            return Err("nested too deeply".into());
        }
        match self.peek() {
            Some(q @ ('\'' | '"')) => self.string(q),
            Some('(') => self.sequence(')', depth).map(|(items, trailing_comma)| {
                // `(x)` is just x in Python; `(x,)` is a tuple.
                if items.len() == 1 && !trailing_comma {
                    items.into_iter().next().unwrap_or(Value::None)
                } else {
                    Value::Tuple(items)
                }
            }),
            Some('[') => self.sequence(']', depth).map(|(items, _)| Value::List(items)),
            Some('{') => self.dict(depth),
            Some(c) if c.is_ascii_digit() => self.int(),
            Some(c) if c.is_alphabetic() => {
                let start = self.i;
                while self.s.get(self.i).is_some_and(|c| c.is_alphanumeric() || *c == '_') {
                    self.i += 1;
                }
                let word: String = self.s[start..self.i].iter().collect();
                match word.as_str() {
                    "True" => Ok(Value::Bool(true)),
                    "False" => Ok(Value::Bool(false)),
                    "None" => Ok(Value::None),
                    _ => Err(format!("unexpected name {word:?} at offset {start}")),
                }
            }
            _ => Err(self.unexpected("a value")),
        }
    }

    fn string(&mut self, quote: char) -> Result<Value, String> {
        let start = self.i;
        self.i += 1;
        let mut out = String::new();
        loop {
            match self.s.get(self.i) {
                None => return Err(format!("string starting at offset {start} is not closed")),
                Some(&c) if c == quote => {
                    self.i += 1;
                    return Ok(Value::Str(out));
                }
                Some('\\') => {
                    // Dtype strings hold no escapes worth decoding; keep the escaped character.
                    let c = *self
                        .s
                        .get(self.i + 1)
                        .ok_or_else(|| format!("string starting at offset {start} is not closed"))?;
                    out.push(c);
                    self.i += 2;
                }
                Some(&c) => {
                    out.push(c);
                    self.i += 1;
                }
            }
        }
    }

    fn int(&mut self) -> Result<Value, String> {
        let start = self.i;
        let mut n: u64 = 0;
        while let Some(d) = self.s.get(self.i).and_then(|c| c.to_digit(10)) {
            n = n
                .checked_mul(10)
                .and_then(|n| n.checked_add(u64::from(d)))
                .ok_or_else(|| format!("integer at offset {start} does not fit 64 bits"))?;
            self.i += 1;
        }
        // Python 2 wrote long integers with an `L` suffix.
        if self.s.get(self.i).is_some_and(|c| *c == 'L' || *c == 'l') {
            self.i += 1;
        }
        Ok(Value::Int(n))
    }

    /// Items up to `close`, and whether a comma followed the last one.
    fn sequence(&mut self, close: char, depth: u32) -> Result<(Vec<Value>, bool), String> {
        self.i += 1;
        let mut items = Vec::new();
        let mut trailing_comma = false;
        loop {
            if self.peek() == Some(close) {
                self.i += 1;
                return Ok((items, trailing_comma));
            }
            if !items.is_empty() && !trailing_comma {
                return Err(self.unexpected(&format!("',' or {close:?}")));
            }
            items.push(self.value(depth + 1)?);
            trailing_comma = self.peek() == Some(',');
            if trailing_comma {
                self.i += 1;
            }
        }
    }

    fn dict(&mut self, depth: u32) -> Result<Value, String> {
        self.i += 1;
        let mut entries = Vec::new();
        let mut comma = true;
        loop {
            if self.peek() == Some('}') {
                self.i += 1;
                return Ok(Value::Dict(entries));
            }
            if !comma {
                return Err(self.unexpected("',' or '}'"));
            }
            let key = self.value(depth + 1)?;
            if self.peek() != Some(':') {
                return Err(self.unexpected("':'"));
            }
            self.i += 1;
            let value = self.value(depth + 1)?;
            entries.push((key, value));
            comma = self.peek() == Some(',');
            if comma {
                self.i += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn rays() -> Vec<Ray> {
        let mut v: Vec<Ray> = (0..1000)
            .map(|i| {
                let f = i as f32;
                Ray { origin: [f, -f * 0.5, 1e-30 * f], tmin: 0.0, dir: [1.0, f.sin(), -0.0], tmax: f32::INFINITY }
            })
            .collect();
        v.push(Ray { origin: [f32::NAN; 3], tmin: 2.0, dir: [0.0; 3], tmax: 1.0 });
        v.push(Ray {
            origin: [f32::MAX, f32::MIN_POSITIVE, -f32::INFINITY],
            tmin: -0.0,
            dir: [1e-45, 0.0, 0.0],
            tmax: 0.0,
        });
        v
    }

    fn hits() -> Vec<Hit> {
        let mut v: Vec<Hit> = (0..777).map(|i| Hit { t: i as f32 * 0.25, prim: i * 3, u: 0.125, v: 0.5 }).collect();
        v.push(Hit::MISS);
        v.push(Hit { t: -0.0, prim: 0, u: f32::NAN, v: 1.0 });
        v
    }

    fn bits<T: bytemuck::Pod>(v: &[T]) -> &[u8] {
        bytemuck::cast_slice(v)
    }

    fn ray_bytes(rays: &[Ray]) -> Vec<u8> {
        let mut out = Vec::new();
        write_rays_to(&mut out, rays).unwrap();
        out
    }

    /// A file with the given header dict text (padded as NumPy pads) and data.
    fn npy(version: u8, dict: &str, data: &[u8]) -> Vec<u8> {
        let len_bytes = if version == 1 { 2 } else { 4 };
        let pre = 8 + len_bytes;
        let hlen = (pre + dict.len() + 1).next_multiple_of(64) - pre;
        let mut out = MAGIC.to_vec();
        out.extend_from_slice(&[version, 0]);
        if version == 1 {
            out.extend_from_slice(&(hlen as u16).to_le_bytes());
        } else {
            out.extend_from_slice(&(hlen as u32).to_le_bytes());
        }
        out.extend_from_slice(dict.as_bytes());
        out.resize(pre + hlen - 1, b' ');
        out.push(b'\n');
        out.extend_from_slice(data);
        out
    }

    /// Whether an error kind is the one expected.
    type KindCheck = fn(&NpyErrorKind) -> bool;

    fn ray_err(bytes: &[u8]) -> NpyErrorKind {
        read_rays_from(bytes).unwrap_err().kind
    }

    fn temp_path(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("raytrail-npy-{}-{name}", std::process::id()))
    }

    #[test]
    fn rays_round_trip_bit_for_bit() {
        let rays = rays();
        let back = read_rays_from(Cursor::new(ray_bytes(&rays))).unwrap();
        assert_eq!(bits(&back), bits(&rays));
        assert!(read_rays_from(Cursor::new(ray_bytes(&[]))).unwrap().is_empty());
    }

    #[test]
    fn hits_round_trip_bit_for_bit() {
        let hits = hits();
        let mut buf = Vec::new();
        write_hits_to(&mut buf, &hits).unwrap();
        let back = read_hits_from(&buf[..]).unwrap();
        assert_eq!(bits(&back), bits(&hits));
        assert_eq!(back[777], Hit::MISS);
    }

    #[test]
    fn files_round_trip() {
        let (rp, hp) = (temp_path("rays.npy"), temp_path("hits.npy"));
        write_rays(&rp, &rays()).unwrap();
        write_hits(&hp, &hits()).unwrap();
        assert_eq!(bits(&read_rays(&rp).unwrap()), bits(&rays()));
        assert_eq!(bits(&read_hits(&hp).unwrap()), bits(&hits()));
        // A hit file is not a ray file, and the message says which file and why.
        let e = read_rays(&hp).unwrap_err();
        assert!(matches!(e.kind(), NpyErrorKind::WrongDtype { .. }));
        assert!(e.to_string().starts_with(&hp.display().to_string()), "{e}");
        std::fs::remove_file(&rp).unwrap();
        std::fs::remove_file(&hp).unwrap();
    }

    #[test]
    fn headers_are_the_ones_numpy_writes() {
        // What `np.save` (NumPy 2.4) writes for a (2, 8) float32 array and for 3 hits.
        let b = ray_bytes(&rays()[..2]);
        assert_eq!(&b[..10], b"\x93NUMPY\x01\x00\x76\x00");
        let text = std::str::from_utf8(&b[10..128]).unwrap();
        assert_eq!(text.trim_end(), "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 8), }");
        assert!(text.ends_with('\n'));
        assert_eq!(b.len(), 128 + 2 * 32);
        let mut h = Vec::new();
        write_hits_to(&mut h, &hits()[..3]).unwrap();
        // NumPy's spare room for the first extent pushes this header to the next 64 bytes.
        assert_eq!(&h[..10], b"\x93NUMPY\x01\x00\xb6\x00");
        let newline = h.iter().position(|&b| b == b'\n').unwrap();
        let text = std::str::from_utf8(&h[10..newline]).unwrap();
        assert_eq!(text.trim_end(), format!("{{'descr': {HIT_DESCR}, 'fortran_order': False, 'shape': (3,), }}"));
        assert_eq!((10 + text.len() + 1) % 64, 0);
        assert_eq!(h.len(), 10 + text.len() + 1 + 3 * 16);
    }

    #[test]
    fn other_versions_byte_orders_and_float64_are_read() {
        let rays = &rays()[..5];
        let le: Vec<u8> = bits(rays).to_vec();
        let be: Vec<u8> = le.chunks(4).flat_map(|c| [c[3], c[2], c[1], c[0]]).collect();
        for (version, descr, data) in [(1, "'<f4'", &le), (2, "'<f4'", &le), (3, "'<f4'", &le), (1, "'>f4'", &be)] {
            let dict = format!("{{'descr': {descr}, 'fortran_order': False, 'shape': (5, 8), }}");
            let back = read_rays_from(&npy(version, &dict, data)[..]).unwrap();
            assert_eq!(bits(&back), bits(rays), "version {version} {descr}");
        }
        // Double quotes, no trailing comma, other key order, extra blanks, a Python 2 long.
        let dict = "{ \"shape\" : ( 5L ,8 ) , \"fortran_order\":False,\"descr\":\"<f4\"}";
        assert_eq!(bits(&read_rays_from(&npy(1, dict, &le)[..]).unwrap()), bits(rays));
        // float64, both byte orders, rounded to float32.
        let f: Vec<f64> = vec![0.1, 1e300, -1e-300, f64::NAN, f64::INFINITY, 2.5, -0.0, 3.0];
        for (descr, data) in [
            ("'<f8'", f.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>()),
            ("'>f8'", f.iter().flat_map(|x| x.to_be_bytes()).collect()),
        ] {
            let dict = format!("{{'descr': {descr}, 'fortran_order': False, 'shape': (1, 8), }}");
            let r = read_rays_from(&npy(1, &dict, &data)[..]).unwrap()[0];
            assert_eq!(r.origin, [0.1f32, f32::INFINITY, -0.0]);
            assert!(r.tmin.is_nan());
            assert_eq!((r.dir, r.tmax), ([f32::INFINITY, 2.5, -0.0], 3.0));
            assert!(r.origin[2].is_sign_negative());
        }
        // Big-endian hit fields.
        let hits = &hits()[..4];
        let be: Vec<u8> = bits(hits).chunks(4).flat_map(|c| [c[3], c[2], c[1], c[0]]).collect();
        let dict = format!("{{'descr': {}, 'fortran_order': False, 'shape': (4,), }}", HIT_DESCR.replace('<', ">"));
        assert_eq!(bits(&read_hits_from(&npy(1, &dict, &be)[..]).unwrap()), bits(hits));
        // Trailing bytes after the data are ignored, as NumPy does.
        let mut b = ray_bytes(rays);
        b.extend_from_slice(b"trailing");
        assert_eq!(read_rays_from(&b[..]).unwrap().len(), 5);
    }

    #[test]
    fn malformed_headers_are_errors() {
        let data = vec![0u8; 64];
        let dict = |descr: &str, fortran: &str, shape: &str| {
            format!("{{'descr': {descr}, 'fortran_order': {fortran}, 'shape': {shape}, }}")
        };
        let cases: Vec<(String, KindCheck)> = vec![
            (dict("'<f4'", "True", "(2, 8)"), |k| matches!(k, NpyErrorKind::FortranOrder)),
            (dict("'<f4'", "False", "(2, 7)"), |k| matches!(k, NpyErrorKind::WrongShape { .. })),
            (dict("'<f4'", "False", "(16,)"), |k| matches!(k, NpyErrorKind::WrongShape { .. })),
            (dict("'<f4'", "False", "(2, 8, 1)"), |k| matches!(k, NpyErrorKind::WrongShape { .. })),
            (dict("'<f4'", "False", "()"), |k| matches!(k, NpyErrorKind::WrongShape { .. })),
            (dict("'<i4'", "False", "(2, 8)"), |k| matches!(k, NpyErrorKind::WrongDtype { .. })),
            (dict("'<f2'", "False", "(2, 8)"), |k| matches!(k, NpyErrorKind::WrongDtype { .. })),
            (dict("'|f4'", "False", "(2, 8)"), |k| matches!(k, NpyErrorKind::WrongDtype { .. })),
            (dict("'<f16'", "False", "(2, 8)"), |k| matches!(k, NpyErrorKind::WrongDtype { .. })),
            (dict(HIT_DESCR, "False", "(2, 8)"), |k| matches!(k, NpyErrorKind::WrongDtype { .. })),
            (dict("'<f4'", "0", "(2, 8)"), |k| matches!(k, NpyErrorKind::MalformedHeader(_))),
            (dict("'<f4'", "False", "[2, 8]"), |k| matches!(k, NpyErrorKind::MalformedHeader(_))),
            (dict("'<f4'", "False", "('2', 8)"), |k| matches!(k, NpyErrorKind::MalformedHeader(_))),
            (dict("'<f4'", "False", "(-2, 8)"), |k| matches!(k, NpyErrorKind::MalformedHeader(_))),
            (dict("'<f4'", "False", "(99999999999999999999, 8)"), |k| matches!(k, NpyErrorKind::MalformedHeader(_))),
            (dict("'<f4'", "False", "(4611686018427387904, 8)"), |k| matches!(k, NpyErrorKind::TooLarge { .. })),
            ("{'descr': '<f4', 'shape': (2, 8)}".into(), |k| matches!(k, NpyErrorKind::MalformedHeader(_))),
            ("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 8), 'x': 1}".into(), |k| {
                matches!(k, NpyErrorKind::MalformedHeader(_))
            }),
            ("{'descr': '<f4', 'descr': '<f4', 'fortran_order': False, 'shape': (2, 8)}".into(), |k| {
                matches!(k, NpyErrorKind::MalformedHeader(_))
            }),
            ("{'descr': '<f4' 'fortran_order': False, 'shape': (2, 8)}".into(), |k| {
                matches!(k, NpyErrorKind::MalformedHeader(_))
            }),
            ("{'descr': '<f4', 'fortran_order': False, 'shape': (2 8)}".into(), |k| {
                matches!(k, NpyErrorKind::MalformedHeader(_))
            }),
            ("{'descr': '<f4, 'fortran_order': False, 'shape': (2, 8)}".into(), |k| {
                matches!(k, NpyErrorKind::MalformedHeader(_))
            }),
            ("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 8)".into(), |k| {
                matches!(k, NpyErrorKind::MalformedHeader(_))
            }),
            ("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 8)} x".into(), |k| {
                matches!(k, NpyErrorKind::MalformedHeader(_))
            }),
            ("[1, 2]".into(), |k| matches!(k, NpyErrorKind::MalformedHeader(_))),
            ("".into(), |k| matches!(k, NpyErrorKind::MalformedHeader(_))),
            (format!("{}{}", "(".repeat(10_000), ")".repeat(10_000)), |k| {
                matches!(k, NpyErrorKind::MalformedHeader(_))
            }),
        ];
        for (text, expected) in &cases {
            let kind = ray_err(&npy(1, text, &data));
            assert!(expected(&kind), "{text}: got {kind}");
            // Every message reads as a sentence naming the problem.
            assert!(!kind.to_string().is_empty());
        }
        // Hits: wrong field names, types, count or shape.
        for (descr, shape) in [
            ("[('t', '<f4'), ('prim', '<i4'), ('u', '<f4'), ('v', '<f4')]", "(2,)"),
            ("[('t', '<f4'), ('id', '<u4'), ('u', '<f4'), ('v', '<f4')]", "(2,)"),
            ("[('t', '<f4'), ('prim', '<u4'), ('u', '<f4')]", "(2,)"),
            ("[('t', '<f4', (2,)), ('prim', '<u4'), ('u', '<f4'), ('v', '<f4')]", "(2,)"),
            ("'<f4'", "(2,)"),
            (HIT_DESCR, "(2, 1)"),
        ] {
            let b = npy(1, &dict(descr, "False", shape), &data);
            let kind = read_hits_from(&b[..]).unwrap_err().kind;
            assert!(
                matches!(kind, NpyErrorKind::WrongDtype { .. } | NpyErrorKind::WrongShape { .. }),
                "{descr}: {kind}"
            );
        }
    }

    #[test]
    fn bad_preambles_are_errors() {
        let good = ray_bytes(&rays()[..2]);
        assert!(matches!(ray_err(b"PK\x03\x04 not numpy at all"), NpyErrorKind::NotNpy { .. }));
        assert!(matches!(ray_err(b""), NpyErrorKind::Truncated { part: "preamble", found: 0, .. }));
        for (major, minor) in [(0, 0), (1, 1), (4, 0), (255, 255)] {
            let mut b = good.clone();
            b[6..8].copy_from_slice(&[major, minor]);
            assert!(matches!(ray_err(&b), NpyErrorKind::UnsupportedVersion { .. }), "{major}.{minor}");
        }
        let mut b = npy(2, "{}", &[]);
        b[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(matches!(ray_err(&b), NpyErrorKind::HeaderTooLong { .. }));
        let mut b = npy(3, "{'descr': '<f4', 'fortran_order': False, 'shape': (0, 8), }", &[]);
        b[20] = 0xff;
        assert!(matches!(ray_err(&b), NpyErrorKind::MalformedHeader(_)));
    }

    #[test]
    fn every_truncation_is_an_error_naming_the_part() {
        let good = ray_bytes(&rays()[..3]);
        for len in 0..good.len() {
            let kind = ray_err(&good[..len]);
            let part = if len < 10 {
                "preamble"
            } else if len < 128 {
                "header"
            } else {
                "data"
            };
            assert!(matches!(kind, NpyErrorKind::Truncated { part: p, .. } if p == part), "{len}: {kind}");
        }
        let kind = ray_err(&good[..good.len() - 1]);
        assert_eq!(kind.to_string(), "truncated data: expected 96 bytes, found 95");
        let mut h = Vec::new();
        write_hits_to(&mut h, &hits()).unwrap();
        assert!(matches!(read_hits_from(&h[..h.len() - 16]).unwrap_err().kind, NpyErrorKind::Truncated { .. }));
        // A header claiming a huge array over a few bytes of data fails without allocating it.
        let b = npy(1, "{'descr': '<f4', 'fortran_order': False, 'shape': (100000000000, 8), }", &[0; 40]);
        assert!(matches!(ray_err(&b), NpyErrorKind::Truncated { part: "data", found: 40, .. }));
    }

    #[test]
    fn corrupted_bytes_never_panic() {
        // Flip each header byte through a few values: every outcome is a result, never a panic.
        let good = ray_bytes(&rays()[..2]);
        for i in 0..128 {
            for x in [0u8, b'(', b')', b'\'', b',', b'9', 0xff] {
                let mut b = good.clone();
                b[i] = x;
                let _ = read_rays_from(&b[..]);
                let _ = read_hits_from(&b[..]);
            }
        }
    }

    #[test]
    fn errors_name_the_file_and_keep_the_io_cause() {
        let path = temp_path("does-not-exist.npy");
        let e = read_rays(&path).unwrap_err();
        assert!(matches!(e.kind(), NpyErrorKind::Io(_)));
        assert!(std::error::Error::source(&e).is_some());
        assert!(e.to_string().contains("does-not-exist.npy"), "{e}");
        let e = read_hits_from(&b"junk"[..]).unwrap_err();
        assert!(e.to_string().starts_with("<stream>: not a .npy file"), "{e}");
        assert!(e.with_file("<stdin>").to_string().starts_with("<stdin>: "));
        let dir = std::env::temp_dir().join("raytrail-npy-no-such-dir").join("x.npy");
        assert!(matches!(write_hits(&dir, &hits()).unwrap_err().kind(), NpyErrorKind::Io(_)));
    }
}
