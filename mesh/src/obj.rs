//! OBJ through tobj, with the line numbers and guarantees tobj does not give.
//!
//! What tobj does, checked against tobj 4.0: with `triangulate` it splits quads as `(a,b,c),(a,c,d)`
//! and larger polygons as fans `(v0, vi, vi+1)`; models come out in file order (a new model at each
//! `o`, `g` or material change) and faces keep their order inside a model. Concatenating the models
//! therefore gives primitive ids in file order. What it does not do, and this module adds:
//! - Errors carry no position: a [`Tracked`] reader remembers how far tobj read.
//! - Index range errors surface only when tobj closes a model (next `o`/`g`/`usemtl` or end of
//!   file): [`locate_bad_reference`] rescans to find the face that caused them.
//! - It reads `l` (polyline) statements as faces, so `l 1 2 3` would become a triangle: such lines
//!   are turned into comments before tobj sees them.
//! - It silently turns faces of one or two vertices into degenerate triangles (or drops them): by
//!   the loading policy ([`super::LoadOptions`]) these are commented out too and counted, or with
//!   `strict` rejected, like `l` and `p` statements.
//! - Arithmetic on hostile indices can overflow inside tobj (a panic with overflow checks on): the
//!   call is guarded and the panic reported as an error.
//!
//! The source of each triangle ([`Source::Line`]) comes from the same pre-scan: tobj keeps file
//! order and splits an `f` of `n` vertices into `n - 2` triangles, so the kept `f` lines, each
//! repeated `n - 2` times, line up with its triangles (checked against the count it returns).

use super::{LoadOptions, LoadReport, MeshError, Source};
use glam::Vec3;
use raytrail_core::scene::Mesh;
use std::borrow::Cow;
use std::format;
use std::io::{self, BufRead, Read};
use std::panic::{self, AssertUnwindSafe};
use std::string::String;
use std::vec::Vec;

/// Whether `data` reads as OBJ text, for data without a file name to go by (a pipe): its first
/// statement (past blank lines and `#` comments, within the first 64 KiB) is one of OBJ's
/// (`v`, `vt`, `vn`, `f`, `o`, `g`, `s`, `l`, `p`, `mtllib`, `usemtl`). OBJ has no magic number,
/// so this is tried after every format that has one, and only for a name without an extension.
pub(super) fn has_magic(data: &[u8]) -> bool {
    const STATEMENTS: [&[u8]; 11] = [b"v", b"vt", b"vn", b"f", b"o", b"g", b"s", b"l", b"p", b"mtllib", b"usemtl"];
    let head = &data[..data.len().min(1 << 16)];
    head.split(|&b| b == b'\n')
        .map(|line| line.trim_ascii())
        .find(|line| !line.is_empty() && !line.starts_with(b"#"))
        .and_then(|line| super::words(line).next())
        .is_some_and(|w| STATEMENTS.contains(&w))
}

/// Parses OBJ text; `name` is used in errors.
pub(super) fn parse(data: &[u8], name: &str, options: &LoadOptions) -> Result<(Mesh, LoadReport), MeshError> {
    let mut scan = prescan(data, options);
    // Before tobj allocates them: its triangle count is the pre-scan's (see the module comment).
    super::check_triangles(scan.triangles, "the `f` lines make", options).map_err(|e| MeshError::new(name, e))?;
    let text: Cow<[u8]> = if scan.comment_out.is_empty() {
        Cow::Borrowed(data)
    } else {
        let mut owned = data.to_vec();
        for &at in &scan.comment_out {
            owned[at] = b'#';
        }
        Cow::Owned(owned)
    };

    // A relative reference out of range makes tobj's index arithmetic overflow (a panic with
    // overflow checks on, caught below but printed by the panic hook): such files are checked
    // first, which costs a pass only where a face has a `-` in it.
    if scan.relative {
        if let Some((line, why)) = locate_bad_reference(&text) {
            return Err(MeshError::at_line(name, line, why));
        }
    }
    let mut reader = Tracked { data: &text, pos: 0 };
    let tobj_options = tobj::LoadOptions {
        triangulate: true,
        // Separate position indices: positions are not duplicated per normal/texcoord.
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // Materials are not needed; a failing loader only records the failure in tobj's result.
    let result = panic::catch_unwind(AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut reader, &tobj_options, |_| Err(tobj::LoadError::OpenFileFailed))
    }));
    let tobj_line = reader.line();

    let failure = match result {
        Ok(Ok((models, _materials))) => {
            if let Some((line, msg)) = scan.strict_error {
                return Err(MeshError::at_line(name, line, msg));
            }
            let mesh = concat(models, name)?;
            if options.sources && scan.report.sources.len() != mesh.triangles.len() {
                let msg = format!(
                    "tobj returned {} triangles where the `f` lines make {}",
                    mesh.triangles.len(),
                    scan.report.sources.len()
                );
                return Err(MeshError::new(name, msg));
            }
            return Ok((mesh, scan.report));
        }
        Ok(Err(err)) => (err, None),
        Err(payload) => (tobj::LoadError::GenericFailure, Some(super::panic_message(payload))),
    };
    Err(locate_failure(&text, name, tobj_line, failure, scan.strict_error.take()))
}

/// The first problem tobj ran into, positioned; an element that strict loading rejects wins if
/// it comes first.
fn locate_failure(
    text: &[u8],
    name: &str,
    tobj_line: usize,
    (err, panic_msg): (tobj::LoadError, Option<String>),
    strict: Option<(usize, String)>,
) -> MeshError {
    use tobj::LoadError as E;
    let deferred = panic_msg.is_some()
        || matches!(
            err,
            E::FaceVertexOutOfBounds
                | E::FaceTexCoordOutOfBounds
                | E::FaceNormalOutOfBounds
                | E::FaceColorOutOfBounds
                | E::InvalidPolygon
        );
    let what = match &panic_msg {
        Some(msg) => format!("tobj panicked ({msg})"),
        None => format!("{err}"),
    };
    let mut found = match deferred.then(|| locate_bad_reference(text)).flatten() {
        Some((line, why)) => MeshError::at_line(name, line, format!("{why} ({what})")),
        None if deferred => MeshError::at_line(name, tobj_line, format!("{what} in the object ending here")),
        None => MeshError::at_line(name, tobj_line, format!("{what}: {}", quote_line(text, tobj_line))),
    };
    if let Some((line, msg)) = strict {
        if found.line.is_none_or(|l| line <= l) {
            found = MeshError::at_line(name, line, msg);
        }
    }
    found
}

/// Appends tobj's models in order, offsetting each model's indices past the positions before it.
fn concat(models: Vec<tobj::Model>, name: &str) -> Result<Mesh, MeshError> {
    let mut mesh = Mesh::default();
    mesh.positions.reserve(models.iter().map(|m| m.mesh.positions.len() / 3).sum());
    mesh.triangles.reserve(models.iter().map(|m| m.mesh.indices.len() / 3).sum());
    for model in models {
        let (positions, indices) = (&model.mesh.positions, &model.mesh.indices);
        if positions.len() % 3 != 0 || indices.len() % 3 != 0 {
            return Err(MeshError::new(name, "tobj returned a malformed mesh"));
        }
        let base = u32::try_from(mesh.positions.len())
            .ok()
            .filter(|b| b.checked_add((positions.len() / 3) as u32).is_some())
            .ok_or_else(|| MeshError::new(name, "more than 2^32 vertices"))?;
        mesh.positions.extend(positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])));
        mesh.triangles.extend(indices.chunks_exact(3).map(|t| [base + t[0], base + t[1], base + t[2]]));
    }
    Ok(mesh)
}

/// What a quick pass over the text finds before tobj runs.
struct Prescan {
    /// Byte offsets of the keywords of statements to turn into comments: `l` always (tobj would
    /// read it as a face), and faces of fewer than 3 vertices when not strict.
    comment_out: Vec<usize>,
    /// With strict loading, the first element that is not a triangle or polygon: its line and
    /// the error.
    strict_error: Option<(usize, String)>,
    /// Elements skipped, and the sources of the triangles of the kept faces.
    report: LoadReport,
    /// Triangles the kept faces make (`n - 2` for a face of `n` vertices).
    triangles: u64,
    /// Whether some face has a relative (negative) reference, which tobj resolves with
    /// arithmetic that overflows on a hostile one.
    relative: bool,
}

fn prescan(data: &[u8], options: &LoadOptions) -> Prescan {
    let mut scan = Prescan {
        comment_out: Vec::new(),
        strict_error: None,
        report: LoadReport::default(),
        triangles: 0,
        relative: false,
    };
    for (i, (start, line)) in lines(data).enumerate() {
        let line_no = i + 1;
        // Words as tobj splits them (Unicode whitespace) where the line is text it can read.
        let (keyword, count) = match std::str::from_utf8(line) {
            Ok(text) => {
                let mut w = text.split_whitespace();
                (w.next().map(str::as_bytes), w.count())
            }
            Err(_) => {
                let mut w = words(line);
                (w.next(), w.count())
            }
        };
        let keyword_at = start + first_word_offset(line);
        let skipped = match keyword {
            Some(b"l") => {
                scan.comment_out.push(keyword_at);
                Some(("a polyline (l)".into(), "a polyline (l) is not a triangle or polygon".into()))
            }
            Some(b"p") => Some(("points (p)".into(), "points (p) are not triangles or polygons".into())),
            Some(b"f") if count < 3 => {
                if !options.strict {
                    scan.comment_out.push(keyword_at);
                }
                let what = format!("a face with {count} vertices");
                Some((what, format!("face has {count} vertices; a face needs at least 3")))
            }
            Some(b"f") => {
                scan.triangles += (count - 2) as u64;
                scan.relative |= line.contains(&b'-');
                // Sources only while within the limit: past it the load fails before tobj runs.
                if options.sources && scan.triangles <= options.max_triangles {
                    let n = count - 2;
                    scan.report.sources.extend(core::iter::repeat_n(Source::Line(line_no as u64), n));
                }
                None
            }
            _ => None,
        };
        if let Some((what, error)) = skipped {
            if options.strict {
                if scan.strict_error.is_none() {
                    scan.strict_error = Some((line_no, error));
                }
            } else {
                scan.report.skip(|| format!("line {line_no}"), || what);
            }
        }
    }
    scan
}

/// Finds the first face whose vertex, texcoord or normal reference is out of range, resolving
/// relative (negative) indices as tobj does: against the counts at the face.
fn locate_bad_reference(data: &[u8]) -> Option<(usize, String)> {
    const KINDS: [(&str, &str); 3] =
        [("vertex", "vertices"), ("texture coordinate", "texture coordinates"), ("normal", "normals")];
    // Defined vertices, texcoords, normals, and vertices carrying a color.
    let mut defined = [0i64; 3];
    let mut colored = 0i64;
    for (i, (_, line)) in lines(data).enumerate() {
        let mut words = tobj_words(line).into_iter();
        match words.next() {
            Some(b"v") => {
                defined[0] += 1;
                colored += i64::from(words.count() == 6);
            }
            Some(b"vt") => defined[1] += 1,
            Some(b"vn") => defined[2] += 1,
            Some(b"f") => {
                for word in words {
                    for (k, part) in word.split(|&b| b == b'/').enumerate().take(3) {
                        let Some(x) = std::str::from_utf8(part).ok().and_then(|s| s.parse::<i64>().ok()) else {
                            continue;
                        };
                        let resolved = if x < 0 { defined[k] + x } else { x - 1 };
                        // A texcoord or normal index of 0 means "none" to tobj; a vertex one is invalid.
                        let missing_ok = k > 0 && x == 0;
                        // tobj ignores texcoord and normal references while none are defined, but
                        // it resolves a relative one at the face and uses it once the file has
                        // defined some: before any, `-4` resolves below zero and overflows there.
                        let checked = k == 0 || defined[k] > 0 || x < 0;
                        if checked && !missing_ok && !(0..defined[k]).contains(&resolved) {
                            let (one, many) = KINDS[k];
                            let why =
                                format!("face refers to {one} {x}, but {} {many} are defined before it", defined[k]);
                            return Some((i + 1, why));
                        }
                        if k == 0 && colored > 0 && resolved >= colored {
                            let why = format!("face uses vertex {x}, which has no color while others do");
                            return Some((i + 1, why));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}

/// Lines as tobj sees them (split at `\n`), with the byte offset where each starts.
/// The words of a line as tobj splits them: at Unicode whitespace where the line is UTF-8 (a
/// vertical tab separates words there, not in `u8::is_ascii_whitespace`'s sense: a reference
/// ending in one was read as no number and escaped the pre-check), at ASCII whitespace otherwise.
fn tobj_words(line: &[u8]) -> Vec<&[u8]> {
    match std::str::from_utf8(line) {
        Ok(text) => text.split_whitespace().map(str::as_bytes).collect(),
        Err(_) => words(line).collect(),
    }
}

fn lines(data: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    let mut start = 0;
    data.split(|&b| b == b'\n').map(move |line| {
        let at = start;
        start += line.len() + 1;
        (at, line)
    })
}

fn words(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(u8::is_ascii_whitespace).filter(|w| !w.is_empty())
}

fn first_word_offset(line: &[u8]) -> usize {
    line.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(0)
}

/// The text of a 1-based line, shortened, for error messages.
fn quote_line(data: &[u8], line: usize) -> String {
    let text = lines(data).nth(line.saturating_sub(1)).map(|(_, l)| l).unwrap_or_default();
    let text = String::from_utf8_lossy(text);
    let text = text.trim();
    match text.char_indices().nth(60) {
        Some((cut, _)) => format!("{:?}...", &text[..cut]),
        None => format!("{text:?}"),
    }
}

/// A reader over the text that remembers how far it has been consumed, so that tobj's position
/// is known when it fails. Newlines are counted only then, keeping the hot path a pointer bump.
struct Tracked<'a> {
    data: &'a [u8],
    pos: usize,
}

impl Tracked<'_> {
    /// The 1-based line last handed out: tobj reads whole lines, so this is the one it was on.
    fn line(&self) -> usize {
        let read = &self.data[..self.pos];
        let newlines = read.iter().filter(|&&b| b == b'\n').count();
        match read.last() {
            Some(b'\n') => newlines,
            _ => newlines + 1,
        }
    }
}

impl Read for Tracked<'_> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = (&self.data[self.pos..]).read(buf)?;
        self.pos += n;
        Ok(n)
    }
}

impl BufRead for Tracked<'_> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        Ok(&self.data[self.pos..])
    }

    fn consume(&mut self, amt: usize) {
        self.pos = (self.pos + amt).min(self.data.len());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::string::ToString;

    /// The error of strict loading.
    fn err(text: &str) -> String {
        parse(text.as_bytes(), "t.obj", &LoadOptions::STRICT).unwrap_err().to_string()
    }

    fn load(text: &str) -> Mesh {
        lenient(text).0
    }

    fn lenient(text: &str) -> (Mesh, LoadReport) {
        parse(text.as_bytes(), "t.obj", &LoadOptions { strict: false, sources: true, ..LoadOptions::default() })
            .unwrap()
    }

    #[test]
    fn fans_in_file_order_across_objects() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 2 0\no a\nf 1 2 3 4 5\ng b\nf 3 2 1\no a\nf -1 -2 -3\n";
        let m = load(text);
        let tris: Vec<[Vec3; 3]> = m.triangles.iter().map(|t| t.map(|i| m.positions[i as usize])).collect();
        let v = |i: usize| [Vec3::ZERO, Vec3::X, Vec3::new(1., 1., 0.), Vec3::Y, Vec3::new(2., 2., 0.)][i - 1];
        let want = [[1, 2, 3], [1, 3, 4], [1, 4, 5], [3, 2, 1], [5, 4, 3]].map(|t| t.map(v));
        assert_eq!(tris, want);
    }

    #[test]
    fn quads_and_texcoord_normal_forms() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3//1 4/1\n";
        let m = load(text);
        assert_eq!(m.triangles.len(), 2);
        assert_eq!(m.triangles[1].map(|i| m.positions[i as usize]), [Vec3::ZERO, Vec3::new(1., 1., 0.), Vec3::Y]);
    }

    #[test]
    fn sources_are_the_f_lines() {
        let text =
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 2 0\no a\nf 1 2 3 4 5\ng b\n\nf 3 2 1\nusemtl x\nf 1\u{a0}2 3 4\n";
        let (m, report) = lenient(text);
        assert_eq!(m.triangles.len(), 6);
        assert_eq!(report.sources, [7, 7, 7, 10, 12, 12].map(Source::Line));
        assert_eq!(report.skipped, 0);
        // Without the option, no map.
        let (_, report) = parse(text.as_bytes(), "t.obj", &LoadOptions::default()).unwrap();
        assert!(report.sources.is_empty());
    }

    #[test]
    fn short_faces_lines_and_points_are_skipped_and_counted() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2\nf 1 2 3\nl 1 2 3\np 1\nf 3\nf\nf 3 2 1\n";
        let (m, report) = lenient(text);
        assert_eq!(m.triangles, [[0, 1, 2], [2, 1, 0]]);
        assert_eq!(report.sources, [Source::Line(5), Source::Line(10)]);
        assert_eq!(report.skipped, 5);
        let first = report.first_skipped.unwrap();
        assert_eq!((first.location.as_str(), first.what.as_str()), ("line 4", "a face with 2 vertices"));
        // Strict: the first of them, with the message of before.
        assert_eq!(err(text), "t.obj:4: face has 2 vertices; a face needs at least 3");
        assert_eq!(err("v 0 0 0\nl 1 1\nf 1 2\n"), "t.obj:2: a polyline (l) is not a triangle or polygon");
        assert_eq!(err("v 0 0 0\n  p 1\n"), "t.obj:2: points (p) are not triangles or polygons");
        // A skipped face's references are not checked.
        assert_eq!(load("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 99\nf 1 2 3\n").triangles.len(), 1);
    }

    #[test]
    fn polylines_are_not_triangles() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\n  l 1 2 3\nl 1 2\nf 1 2 3\n";
        assert_eq!(load(text).triangles.len(), 1);
    }

    #[test]
    fn materials_are_ignored() {
        let text = "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl red\nf 1 2 3\nusemtl blue\nf 3 2 1\n";
        assert_eq!(load(text).triangles.len(), 2);
    }

    #[test]
    fn errors_carry_the_line() {
        assert_eq!(err("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 x 3\n"), "t.obj:4: face parse error: \"f 1 x 3\"");
        assert_eq!(err("v 0 0 0\nv 1 0 0\nv 1"), "t.obj:3: position parse error: \"v 1\"");
        assert_eq!(err("v 0 0 0\r\nv 1 0 0\r\nv 1 zz 0\r\n"), "t.obj:3: position parse error: \"v 1 zz 0\"");
        assert!(err("v 0 0 0\nv 1 0 0\nf 1 2\nv 1 1 0\n").starts_with("t.obj:3: face has 2 vertices"));
        assert!(err("v 0 0 0\nf\n").starts_with("t.obj:2: face has 0 vertices"));
        // A short face after tobj's failure does not hide it.
        assert!(err("v 0 0 0\nv 1 q 0\nf 1 2\n").starts_with("t.obj:2: position"));
    }

    #[test]
    fn out_of_range_references_are_found() {
        let e = err("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 2 4\nf 1 2 3\n");
        assert!(e.starts_with("t.obj:5: face refers to vertex 4, but 3 vertices are"), "{e}");
        let e = err("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 2 -4\no next\nf 1 2 3\n");
        assert!(e.starts_with("t.obj:5: face refers to vertex -4"), "{e}");
        let e = err("v 0 0 0\nv 1 0 0\nv 1 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n");
        assert!(e.starts_with("t.obj:5: face refers to normal 2"), "{e}");
        let e = err("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 0 1 2\n");
        assert!(e.starts_with("t.obj:4: face refers to vertex 0"), "{e}");
    }

    #[test]
    fn panics_inside_tobj_become_errors() {
        // A relative texcoord index before the first texcoord: tobj computes 2 * (huge) + 1, which
        // overflows (a panic when overflow checks are on, an error otherwise).
        let e = err("v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nf 1/-9 2/1 3/1\n");
        assert!(e.starts_with("t.obj:5: face refers to texture coordinate -9"), "{e}");
    }

    #[test]
    fn hostile_relative_references_never_reach_tobj() {
        // The fuzzer's input of issue 55 (a normal -100 with two normals defined), and the one
        // above: refused by the pre-check, so tobj's arithmetic never overflows (its panic, though
        // caught, printed a backtrace in debug builds).
        let fuzzed = "| a\nv 0 0 00\nvn 0 00 0\nv0\nvn 0 0 1\nf 1/v00/0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvf 0 1\n\
f 1/1/1 2/1/  -1 \nf 1/1/1 2/1/1 3/1/-100 0\nvn -2 -3 0 0 1\nf 1/1\nf 1/v0000 0\nvn 0 0 1\nf 1/v0\nf \n1 2 3f 1 2 3";
        // The first campaign's crash: a relative normal ending in a vertical tab, a word separator
        // to tobj but not to `u8::is_ascii_whitespace`, so the pre-check saw no number.
        let tab = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//-10\x0b\n";
        // The third campaign's: a relative texcoord before any texcoord is defined (`?vt` is not
        // one), with one defined further on, where tobj resolves the face's `-4`.
        let before =
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n?vt 0 0\nf 1/1/1 2/1/1 3/1/1 4/-4 -3 -2\nvt 0 0\nf 1/1 2/1 3/1\n";
        for (text, line) in
            [(fuzzed, 13), ("v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nf 1/-9 2/1 3/1\n", 5), (tab, 5), (before, 6)]
        {
            let e = err(text);
            assert!(e.starts_with(&format!("t.obj:{line}: face refers to ")), "{e}");
            assert!(!e.contains("panicked"), "{e}");
        }
        // Relative references in range load as before.
        let m = parse(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n", "t.obj", &LoadOptions::default()).unwrap().0;
        assert_eq!(m.triangles, [[0, 1, 2]]);
    }

    #[test]
    fn invalid_utf8_is_an_error_at_its_line() {
        let e =
            parse(b"v 0 0 0\n\xff\xfe garbage\nv 1 1 1\n", "g.obj", &LoadOptions::default()).unwrap_err().to_string();
        assert!(e.starts_with("g.obj:2: read error"), "{e}");
    }

    #[test]
    fn tracked_reader_line() {
        let mut r = Tracked { data: b"a\nb\nc", pos: 0 };
        assert_eq!(r.line(), 1);
        let mut s = String::new();
        r.read_line(&mut s).unwrap();
        assert_eq!(r.line(), 1);
        r.read_line(&mut s).unwrap();
        r.read_line(&mut s).unwrap();
        assert_eq!(r.line(), 3);
    }
}
