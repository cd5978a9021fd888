//! glTF 2.0: `.gltf` (JSON, buffers in files beside it or in `data:` URIs) and `.glb` (binary
//! container), through the `gltf` crate's JSON model.
//!
//! The crate parses the JSON into its typed model (`gltf::json::Root`). Everything after that is
//! done here with checked lookups and arithmetic rather than through the crate's document and
//! reader API, which indexes and slices without checking (a hostile file panics it) and rejects a
//! whole file for a material or texture extension it does not know: the GLB container (the
//! crate's reader underflows on a length below 12), buffers, buffer views and accessors (every
//! offset, stride and count checked against the bytes there are, before any allocation), the node
//! hierarchy (which must be a tree: a cycle or a node with two parents is an error), and indices
//! (each checked against the vertex count).
//!
//! What is read: the default scene (`scene`, else the first of `scenes`, else every node that is
//! no node's child, in index order), its nodes depth first with their transforms (`matrix`, or
//! `translation` x `rotation` x `scale`) composed down the tree, and for each node with a mesh,
//! each primitive's `POSITION` (float, or integer under `KHR_mesh_quantization`; sparse
//! accessors applied) and `indices` (or none: vertices in order). Triangle strips and fans become
//! triangles as the specification numbers them: strip triangle `i` is `(v[i], v[i+1], v[i+2])`
//! for even `i` and `(v[i], v[i+2], v[i+1])` for odd `i`; fan triangle `i` is
//! `(v[i+1], v[i+2], v[0])`. Primitives in a point or line mode, and primitives without
//! `POSITION`, are skipped and counted (or rejected when loading is strict). Morph targets and
//! skins are not applied (the rest pose). Files that require Draco or meshopt compression or GPU
//! instancing are rejected; other extensions do not change the geometry and are ignored.
//!
//! A mesh used by several nodes is added once per node (its vertices transformed by each), so the
//! mesh can be larger than the file. Where no transform applies (the identity), positions are
//! copied bit for bit.
//!
//! Errors name the JSON path (`meshes[0].primitives[1].indices`) or, in a GLB's container, the
//! byte offset. The source of a triangle is its node, mesh, primitive and index in the primitive
//! ([`Source::Gltf`]).

use super::{LoadOptions, LoadReport, MeshError, Source, MAX_TRIANGLES, MAX_VERTICES};
use ::gltf::json;
use base64::Engine as _;
use glam::{Mat4, Quat, Vec3};
use json::accessor::{ComponentType, GenericComponentType, IndexComponentType, Type};
use json::mesh::{Mode, Semantic};
use json::validation::Checked;
use raytrail_core::scene::Mesh;
use std::borrow::Cow;
use std::format;
use std::io::Read;
use std::panic::{self, AssertUnwindSafe};
use std::path::{self, Path};
use std::string::{String, ToString};
use std::vec::Vec;

const GLB_MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = u32::from_le_bytes(*b"JSON");
const CHUNK_BIN: u32 = u32::from_le_bytes(*b"BIN\0");

/// Extensions that, when required, change the geometry in a way this loader does not follow.
const UNSUPPORTED_REQUIRED: [&str; 3] =
    ["KHR_draco_mesh_compression", "EXT_meshopt_compression", "EXT_mesh_gpu_instancing"];

/// Whether the data is a GLB, or JSON (an object, as a glTF file is).
pub(super) fn has_magic(data: &[u8]) -> bool {
    data.starts_with(GLB_MAGIC) || strip_bom(data).trim_ascii_start().starts_with(b"{")
}

fn strip_bom(data: &[u8]) -> &[u8] {
    data.strip_prefix(b"\xef\xbb\xbf").unwrap_or(data)
}

/// Parses a glTF or GLB file held in memory; external buffers are read from `dir` (none when
/// `None`); `name` is used in errors.
pub(super) fn parse(
    data: &[u8],
    name: &str,
    dir: Option<&Path>,
    options: &LoadOptions,
) -> Result<(Mesh, LoadReport), MeshError> {
    // Every access below is checked; a panic would be a bug here or in serde_json, and is
    // reported as an error rather than taking the caller down.
    panic::catch_unwind(AssertUnwindSafe(|| parse_checked(data, name, dir, options))).unwrap_or_else(|payload| {
        Err(MeshError::new(name, format!("glTF loader panicked ({})", super::panic_message(payload))))
    })
}

fn parse_checked(
    data: &[u8],
    name: &str,
    dir: Option<&Path>,
    options: &LoadOptions,
) -> Result<(Mesh, LoadReport), MeshError> {
    let (json_bytes, json_at, bin) = if data.starts_with(GLB_MAGIC) {
        let glb = glb(data, name)?;
        (glb.json, Some(glb.json_at), glb.bin)
    } else {
        (data, None, None)
    };
    let root: json::Root = json::deserialize::from_slice(strip_bom(json_bytes)).map_err(|e| match json_at {
        // The JSON chunk of a GLB: the chunk's offset, and the line in the chunk.
        Some(at) => MeshError::at_offset(name, at as u64, format!("JSON chunk: invalid glTF JSON: {e}")),
        None if e.line() > 0 => MeshError::at_line(name, e.line(), format!("invalid glTF JSON: {e}")),
        None => MeshError::new(name, format!("invalid glTF JSON: {e}")),
    })?;
    let err = |msg: String| MeshError::new(name, msg);
    for (i, ext) in root.extensions_required.iter().enumerate() {
        if UNSUPPORTED_REQUIRED.contains(&ext.as_str()) {
            return Err(err(format!("extensionsRequired[{i}]: {ext} is not supported")));
        }
    }
    let mut loader = Loader {
        root: &root,
        buffers: Buffers { root: &root, bin, dir, data: (0..root.buffers.len()).map(|_| None).collect() },
        mesh: Mesh::default(),
        report: LoadReport::default(),
        options,
    };
    // Each mesh decoded once, and the placed totals checked against the limit as they grow, before
    // any copy is made: instancing multiplies a file's triangles by its node count. Checked after
    // each placement, so the decoded meshes held (each placed at least once) stay within the
    // limit too, however many meshes share one accessor.
    let placements = instances(&root).map_err(err)?;
    let mut decoded: Vec<Option<Decoded>> = (0..root.meshes.len()).map(|_| None).collect();
    let (mut vertices, mut triangles) = (0u64, 0u64);
    let max_vertices = options.max_triangles.saturating_mul(3);
    for &(_, m, _) in &placements {
        if decoded[m].is_none() {
            decoded[m] = Some(loader.decode(m).map_err(err)?);
        }
        let (v, t) = decoded[m].as_ref().map_or((0, 0), Decoded::size);
        (vertices, triangles) = (vertices.saturating_add(v), triangles.saturating_add(t));
        super::check_triangles(triangles, "the scene's nodes place at least", options).map_err(err)?;
        if vertices > max_vertices {
            return Err(err(format!(
                "the scene's nodes place at least {vertices} vertices, more than three per allowed triangle ({max_vertices}; LoadOptions::max_triangles, the CLI's --max-triangles)"
            )));
        }
    }
    loader.reserve(vertices, triangles).map_err(err)?;
    for (node, m, world) in placements {
        if let Some(mesh) = &decoded[m] {
            loader.place(node, m, mesh, &world).map_err(err)?;
        }
    }
    Ok((loader.mesh, loader.report))
}

/// A GLB's chunks.
struct Glb<'a> {
    json: &'a [u8],
    /// Byte offset of the JSON chunk's data.
    json_at: usize,
    bin: Option<&'a [u8]>,
}

/// The GLB container: the JSON chunk, its byte offset, and the BIN chunk if there is one.
fn glb<'a>(data: &'a [u8], name: &str) -> Result<Glb<'a>, MeshError> {
    let u32_at = |at: usize| data.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    let (Some(version), Some(length)) = (u32_at(4), u32_at(8)) else {
        let msg = format!("GLB of {} bytes: shorter than its 12-byte header", data.len());
        return Err(MeshError::at_offset(name, 0, msg));
    };
    if version != 2 {
        return Err(MeshError::at_offset(name, 4, format!("GLB version {version}: only version 2 is read")));
    }
    if length as usize != data.len() {
        let msg = format!("the header gives the file's length as {length} bytes; it has {}", data.len());
        return Err(MeshError::at_offset(name, 8, msg));
    }
    let (mut json, mut bin) = (None, None);
    let mut at = 12;
    for k in 0.. {
        if at == data.len() {
            break;
        }
        let (Some(len), Some(kind)) = (u32_at(at), u32_at(at + 4)) else {
            let msg = format!("file ends inside the header of chunk {k}");
            return Err(MeshError::at_offset(name, at as u64, msg));
        };
        let body = at + 8;
        let Some(chunk) = data.get(body..body + len as usize) else {
            let msg =
                format!("chunk {k} of {len} bytes runs past the end of the file ({} bytes left)", data.len() - body);
            return Err(MeshError::at_offset(name, at as u64, msg));
        };
        match (k, kind) {
            (0, CHUNK_JSON) => json = Some((chunk, body)),
            (0, _) => return Err(MeshError::at_offset(name, at as u64, "the first chunk is not JSON")),
            (1, CHUNK_BIN) => bin = Some(chunk),
            (_, CHUNK_JSON | CHUNK_BIN) => {
                let msg = format!("chunk {k}: a second JSON chunk, or a BIN chunk that is not the second");
                return Err(MeshError::at_offset(name, at as u64, msg));
            }
            // Unknown chunk types are to be ignored.
            _ => {}
        }
        at = body + len as usize;
    }
    let (json, json_at) = json.ok_or_else(|| MeshError::at_offset(name, 12, "GLB without a JSON chunk"))?;
    Ok(Glb { json, json_at, bin })
}

/// The nodes with a mesh, depth first from the default scene's roots, with their world transforms.
fn instances(root: &json::Root) -> Result<Vec<(usize, usize, Mat4)>, String> {
    let n = root.nodes.len();
    let roots: Vec<(usize, String)> = match root.scene.map(|s| s.value()).or((!root.scenes.is_empty()).then_some(0)) {
        Some(s) => {
            let scene = root
                .scenes
                .get(s)
                .ok_or_else(|| format!("scene: scene {s} does not exist ({} scenes)", root.scenes.len()))?;
            scene.nodes.iter().enumerate().map(|(k, i)| (i.value(), format!("scenes[{s}].nodes[{k}]"))).collect()
        }
        None => {
            let mut is_child = std::vec![false; n];
            for node in &root.nodes {
                for c in node.children.iter().flatten() {
                    if let Some(flag) = is_child.get_mut(c.value()) {
                        *flag = true;
                    }
                }
            }
            (0..n).filter(|&i| !is_child[i]).map(|i| (i, String::new())).collect()
        }
    };
    let mut visited = std::vec![false; n];
    let mut out = Vec::new();
    // Depth first, a node before its children, children in order: a stack of (node, parent's
    // transform, where it is referenced).
    let mut stack: Vec<(usize, Mat4, String)> =
        roots.into_iter().rev().map(|(i, at)| (i, Mat4::IDENTITY, at)).collect();
    while let Some((i, parent, at)) = stack.pop() {
        let node = root.nodes.get(i).ok_or_else(|| format!("{at}: node {i} does not exist ({n} nodes)"))?;
        if std::mem::replace(&mut visited[i], true) {
            return Err(format!(
                "{at}: node {i} is reached twice: the nodes must form trees (no cycles, one parent each)"
            ));
        }
        let world = parent * local_transform(node);
        if let Some(m) = node.mesh {
            let m = m.value();
            if m >= root.meshes.len() {
                return Err(format!("nodes[{i}].mesh: mesh {m} does not exist ({} meshes)", root.meshes.len()));
            }
            out.push((i, m, world));
        }
        for (k, c) in node.children.as_deref().unwrap_or_default().iter().enumerate().rev() {
            stack.push((c.value(), world, format!("nodes[{i}].children[{k}]")));
        }
    }
    Ok(out)
}

fn local_transform(node: &json::Node) -> Mat4 {
    if let Some(m) = node.matrix {
        return Mat4::from_cols_array(&m);
    }
    let t = Vec3::from_array(node.translation.unwrap_or([0.0; 3]));
    let r = Quat::from_array(node.rotation.map_or([0.0, 0.0, 0.0, 1.0], |q| q.0));
    let s = Vec3::from_array(node.scale.unwrap_or([1.0; 3]));
    Mat4::from_scale_rotation_translation(s, r, t)
}

struct Loader<'a> {
    root: &'a json::Root,
    buffers: Buffers<'a>,
    mesh: Mesh,
    report: LoadReport,
    options: &'a LoadOptions,
}

/// A mesh's primitives, decoded once however many nodes place it.
struct Decoded {
    primitives: Vec<Primitive>,
}

/// One primitive of a decoded mesh.
enum Primitive {
    /// Not triangles (a line or point mode, or no POSITION), counted in the report per placement.
    Skipped(String),
    /// Its vertices and triangles (indices into its own vertices).
    Triangles { positions: Vec<Vec3>, triangles: Vec<[u32; 3]> },
}

impl Decoded {
    /// Vertices and triangles one placement of the mesh adds.
    fn size(&self) -> (u64, u64) {
        self.primitives.iter().fold((0, 0), |(v, t), p| match p {
            Primitive::Skipped(_) => (v, t),
            Primitive::Triangles { positions, triangles } => (v + positions.len() as u64, t + triangles.len() as u64),
        })
    }
}

impl Loader<'_> {
    /// Decodes every primitive of mesh `m`: its vertices and triangles, or why it is skipped.
    fn decode(&mut self, m: usize) -> Result<Decoded, String> {
        let root = self.root;
        let mut primitives = Vec::new();
        for (p, primitive) in root.meshes[m].primitives.iter().enumerate() {
            let path = format!("meshes[{m}].primitives[{p}]");
            let mode = match primitive.mode {
                Checked::Valid(mode) => mode,
                Checked::Invalid => return Err(format!("{path}.mode: not a primitive mode")),
            };
            let line_mode = match mode {
                Mode::Points => Some("POINTS"),
                Mode::Lines => Some("LINES"),
                Mode::LineLoop => Some("LINE_LOOP"),
                Mode::LineStrip => Some("LINE_STRIP"),
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan => None,
            };
            let position = primitive.attributes.iter().find_map(|(k, v)| match k {
                Checked::Valid(Semantic::Positions) => Some(v.value()),
                _ => None,
            });
            let problem = match (line_mode, position) {
                (Some(mode), _) => Some(format!("a primitive in {mode} mode")),
                (None, None) => Some("a primitive without POSITION".to_string()),
                (None, Some(_)) => None,
            };
            if let Some(what) = problem {
                if self.options.strict {
                    return Err(format!("{path}: {what} is not triangles"));
                }
                primitives.push(Primitive::Skipped(what));
                continue;
            }
            let Some(position) = position else { continue };
            let positions = self.buffers.positions(position).map_err(|e| format!("{path}.attributes.POSITION: {e}"))?;
            let indices: Vec<u32> = match primitive.indices {
                Some(a) => {
                    let indices = self.buffers.indices(a.value()).map_err(|e| format!("{path}.indices: {e}"))?;
                    if let Some((k, &v)) = indices.iter().enumerate().find(|(_, &v)| v as usize >= positions.len()) {
                        return Err(format!(
                            "{path}.indices: index {k} is {v}, but POSITION has {} vertices",
                            positions.len()
                        ));
                    }
                    indices
                }
                None => {
                    let n = u32::try_from(positions.len()).map_err(|_| format!("{path}: more than 2^32 vertices"))?;
                    (0..n).collect()
                }
            };
            let triangles = triangles(mode, &indices).map_err(|e| format!("{path}: {e}"))?;
            primitives.push(Primitive::Triangles { positions, triangles });
        }
        Ok(Decoded { primitives })
    }

    /// Appends every primitive of mesh `m` (decoded as `mesh`), placed by node `node`'s transform.
    fn place(&mut self, node: usize, m: usize, mesh: &Decoded, world: &Mat4) -> Result<(), String> {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let (positions, triangles) = match primitive {
                Primitive::Skipped(what) => {
                    self.report.skip(|| format!("mesh {m} primitive {p} (node {node})"), || what.clone());
                    continue;
                }
                Primitive::Triangles { positions, triangles } => (positions, triangles),
            };
            let base = self.mesh.positions.len() as u64;
            if base + positions.len() as u64 > MAX_VERTICES
                || (self.mesh.triangles.len() + triangles.len()) as u64 > MAX_TRIANGLES
            {
                return Err(format!(
                    "meshes[{m}].primitives[{p}] (node {node}): the mesh would have more than 2^32 vertices or triangles"
                ));
            }
            if *world == Mat4::IDENTITY {
                self.mesh.positions.extend_from_slice(positions);
            } else {
                self.mesh.positions.extend(positions.iter().map(|&v| world.transform_point3(v)));
            }
            let base = base as u32;
            self.mesh.triangles.extend(triangles.iter().map(|t| t.map(|i| base + i)));
            if self.options.sources {
                let (node, mesh, primitive) = (node as u32, m as u32, p as u32);
                let n = triangles.len() as u32;
                self.report.sources.extend((0..n).map(|triangle| Source::Gltf { node, mesh, primitive, triangle }));
            }
        }
        Ok(())
    }

    /// Reserves room for `vertices` and `triangles` (and their sources) up front, failing with an
    /// error rather than aborting when the memory is not there.
    fn reserve(&mut self, vertices: u64, triangles: u64) -> Result<(), String> {
        let cannot = |what: &str, n: u64| format!("cannot hold {n} {what} in memory");
        let v = usize::try_from(vertices).map_err(|_| cannot("vertices", vertices))?;
        let t = usize::try_from(triangles).map_err(|_| cannot("triangles", triangles))?;
        self.mesh.positions.try_reserve_exact(v).map_err(|_| cannot("vertices", vertices))?;
        self.mesh.triangles.try_reserve_exact(t).map_err(|_| cannot("triangles", triangles))?;
        if self.options.sources {
            self.report.sources.try_reserve_exact(t).map_err(|_| cannot("triangle sources", triangles))?;
        }
        Ok(())
    }
}

/// The triangles of a primitive's vertex sequence in a triangle mode.
fn triangles(mode: Mode, v: &[u32]) -> Result<Vec<[u32; 3]>, String> {
    let n = v.len();
    Ok(match mode {
        Mode::Triangles => {
            if n % 3 != 0 {
                return Err(format!("{n} vertices in TRIANGLES mode: not a multiple of 3"));
            }
            v.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
        }
        Mode::TriangleStrip => (0..n.saturating_sub(2))
            .map(|i| if i % 2 == 0 { [v[i], v[i + 1], v[i + 2]] } else { [v[i], v[i + 2], v[i + 1]] })
            .collect(),
        Mode::TriangleFan => (0..n.saturating_sub(2)).map(|i| [v[i + 1], v[i + 2], v[0]]).collect(),
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => Vec::new(),
    })
}

/// The file's buffers, each read when first needed.
struct Buffers<'a> {
    root: &'a json::Root,
    /// The GLB's BIN chunk.
    bin: Option<&'a [u8]>,
    /// Where external buffer files are; `None`: they may not be read.
    dir: Option<&'a Path>,
    data: Vec<Option<Cow<'a, [u8]>>>,
}

/// An accessor's elements, located and bounds-checked in their buffer.
struct Elements<'b> {
    /// From the first element's first byte to the last element's last.
    bytes: &'b [u8],
    stride: usize,
    count: usize,
    component: ComponentType,
}

impl Elements<'_> {
    /// Component `c` of element `k` (`k < count`, `c` below the element's component count), as
    /// stored.
    fn get(&self, k: usize, c: usize) -> Component {
        let at = k * self.stride + c * self.component.size();
        let b = &self.bytes[at..at + self.component.size()];
        match self.component {
            ComponentType::I8 => Component::Int(i8::from_le_bytes([b[0]]).into()),
            ComponentType::U8 => Component::Int(b[0].into()),
            ComponentType::I16 => Component::Int(i16::from_le_bytes([b[0], b[1]]).into()),
            ComponentType::U16 => Component::Int(u16::from_le_bytes([b[0], b[1]]).into()),
            ComponentType::U32 => Component::Int(u32::from_le_bytes([b[0], b[1], b[2], b[3]]).into()),
            ComponentType::F32 => Component::Float(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        }
    }
}

#[derive(Clone, Copy)]
enum Component {
    Int(i64),
    Float(f32),
}

impl Component {
    /// As a coordinate: floats as they are; integers (`KHR_mesh_quantization`) as they are, or
    /// mapped to [0, 1] or [-1, 1] when `normalized`.
    fn coordinate(self, component: ComponentType, normalized: bool) -> f32 {
        match self {
            Component::Float(v) => v,
            Component::Int(v) if !normalized => v as f32,
            Component::Int(v) => {
                let max = match component {
                    ComponentType::I8 => 127.0,
                    ComponentType::U8 => 255.0,
                    ComponentType::I16 => 32767.0,
                    ComponentType::U16 => 65535.0,
                    _ => 4294967295.0,
                };
                (v as f32 / max).max(-1.0)
            }
        }
    }
}

impl<'a> Buffers<'a> {
    /// Reads buffer `i` if it has not been.
    fn load(&mut self, i: usize) -> Result<(), String> {
        let buffer = self.root.buffers.get(i).ok_or_else(|| format!("buffer {i} does not exist"))?;
        if self.data[i].is_some() {
            return Ok(());
        }
        let here = |msg: String| format!("buffers[{i}]: {msg}");
        let length = buffer.byte_length.0;
        let bytes: Cow<'a, [u8]> = match buffer.uri.as_deref() {
            None => match self.bin {
                Some(bin) if i == 0 => Cow::Borrowed(bin),
                _ => return Err(here("no uri, and it is not the GLB's BIN chunk".into())),
            },
            Some(uri) if uri.starts_with("data:") => {
                let (_, payload) =
                    uri.split_once(";base64,").ok_or_else(|| here("a data: URI that is not base64".into()))?;
                let engine = base64::engine::GeneralPurpose::new(
                    &base64::alphabet::STANDARD,
                    base64::engine::GeneralPurposeConfig::new()
                        .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
                );
                Cow::Owned(engine.decode(payload).map_err(|e| here(format!("data: URI: {e}")))?)
            }
            Some(uri) => Cow::Owned(read_external(self.dir, uri, length).map_err(here)?),
        };
        if (bytes.len() as u64) < length {
            return Err(here(format!("byteLength is {length}, but the data has {} bytes", bytes.len())));
        }
        let bytes = match bytes {
            Cow::Borrowed(b) => Cow::Borrowed(&b[..length as usize]),
            Cow::Owned(mut b) => {
                b.truncate(length as usize);
                Cow::Owned(b)
            }
        };
        self.data[i] = Some(bytes);
        Ok(())
    }

    /// Locates `count` elements at `offset` in buffer view `v`, `dims` components of `component`
    /// each (the view's stride, else packed); the view's buffer must be loaded.
    fn elements(
        &self,
        v: usize,
        offset: u64,
        count: u64,
        component: ComponentType,
        dims: usize,
        strided: bool,
    ) -> Result<Elements<'_>, String> {
        let view = self.root.buffer_views.get(v).ok_or_else(|| format!("buffer view {v} does not exist"))?;
        let buffer = self.data.get(view.buffer.value()).and_then(|d| d.as_deref()).unwrap_or_default();
        let (start, length) = (view.byte_offset.map_or(0, |o| o.0), view.byte_length.0);
        let end = start.checked_add(length).filter(|&e| e <= buffer.len() as u64).ok_or_else(|| {
            format!("bufferViews[{v}]: bytes {start}..{start}+{length} run past its buffer's {} bytes", buffer.len())
        })?;
        let view_bytes = &buffer[start as usize..end as usize];
        let size = (component.size() * dims) as u64;
        let stride = match view.byte_stride {
            Some(s) if strided => s.0 as u64,
            _ => size,
        };
        if stride < size {
            return Err(format!("bufferViews[{v}]: byteStride {stride} is less than an element's {size} bytes"));
        }
        let needed = match count {
            0 => Some(0),
            _ => (count - 1).checked_mul(stride).and_then(|b| b.checked_add(size)).and_then(|b| b.checked_add(offset)),
        };
        let needed = needed.filter(|&n| n <= length).ok_or_else(|| {
            format!(
                "{count} elements of {size} bytes, {stride} apart, from byte {offset} do not fit in bufferViews[{v}] \
                 ({length} bytes)"
            )
        })?;
        let first = offset.min(needed) as usize;
        Ok(Elements {
            bytes: &view_bytes[first..needed as usize],
            stride: stride as usize,
            count: count as usize,
            component,
        })
    }

    /// The accessor's type and component type, checked against what is allowed.
    fn accessor(&self, a: usize, types: &[Type]) -> Result<(&'a json::Accessor, ComponentType, Type), String> {
        let accessor = self.root.accessors.get(a).ok_or_else(|| format!("accessor {a} does not exist"))?;
        let (Checked::Valid(GenericComponentType(component)), Checked::Valid(kind)) =
            (accessor.component_type, accessor.type_)
        else {
            return Err(format!("accessors[{a}]: invalid componentType or type"));
        };
        if !types.contains(&kind) {
            return Err(format!("accessors[{a}]: type {kind:?}, expected {types:?}"));
        }
        Ok((accessor, component, kind))
    }

    /// The buffer views an accessor reads, their buffers loaded.
    fn load_views(&mut self, views: &[usize]) -> Result<(), String> {
        for &v in views {
            let view = self.root.buffer_views.get(v).ok_or_else(|| format!("buffer view {v} does not exist"))?;
            self.load(view.buffer.value())?;
        }
        Ok(())
    }

    /// A `POSITION` accessor's vertices, sparse substitutions applied.
    fn positions(&mut self, a: usize) -> Result<Vec<Vec3>, String> {
        let (accessor, component, _) = self.accessor(a, &[Type::Vec3])?;
        let here = |msg: String| format!("accessors[{a}]: {msg}");
        let Some(view) = accessor.buffer_view.map(|v| v.value()) else {
            return Err(here("no bufferView: accessors of zeros (sparse only) are not read".into()));
        };
        let sparse = accessor.sparse.as_ref();
        let mut views = std::vec![view];
        views.extend(sparse.iter().flat_map(|s| [s.indices.buffer_view.value(), s.values.buffer_view.value()]));
        self.load_views(&views)?;
        let offset = accessor.byte_offset.map_or(0, |o| o.0);
        let elements = self.elements(view, offset, accessor.count.0, component, 3, true).map_err(here)?;
        let normalized = accessor.normalized;
        let vertex = |e: &Elements, k: usize| {
            Vec3::new(
                e.get(k, 0).coordinate(component, normalized),
                e.get(k, 1).coordinate(component, normalized),
                e.get(k, 2).coordinate(component, normalized),
            )
        };
        let mut out: Vec<Vec3> = (0..elements.count).map(|k| vertex(&elements, k)).collect();
        if let Some(sparse) = sparse {
            let here = |msg: String| format!("accessors[{a}].sparse: {msg}");
            let Checked::Valid(IndexComponentType(index_type)) = sparse.indices.component_type else {
                return Err(here("invalid index componentType".into()));
            };
            let n = sparse.count.0;
            let indices = self
                .elements(sparse.indices.buffer_view.value(), sparse.indices.byte_offset.0, n, index_type, 1, false)
                .map_err(|e| here(format!("indices: {e}")))?;
            let values = self
                .elements(sparse.values.buffer_view.value(), sparse.values.byte_offset.0, n, component, 3, false)
                .map_err(|e| here(format!("values: {e}")))?;
            for k in 0..indices.count {
                let i = match indices.get(k, 0) {
                    Component::Int(i) if (0..out.len() as i64).contains(&i) => i as usize,
                    Component::Int(i) => {
                        return Err(here(format!("index {k} is {i}, but the accessor has {} elements", out.len())));
                    }
                    Component::Float(_) => return Err(here("float indices".into())),
                };
                out[i] = vertex(&values, k);
            }
        }
        Ok(out)
    }

    /// An `indices` accessor's values.
    fn indices(&mut self, a: usize) -> Result<Vec<u32>, String> {
        let (accessor, component, _) = self.accessor(a, &[Type::Scalar])?;
        let here = |msg: String| format!("accessors[{a}]: {msg}");
        if !matches!(component, ComponentType::U8 | ComponentType::U16 | ComponentType::U32) {
            return Err(here(format!("indices of component type {component:?}: not an unsigned integer type")));
        }
        if accessor.sparse.is_some() {
            return Err(here("sparse indices".into()));
        }
        let Some(view) = accessor.buffer_view.map(|v| v.value()) else {
            return Err(here("indices without a bufferView".into()));
        };
        self.load_views(&[view])?;
        let offset = accessor.byte_offset.map_or(0, |o| o.0);
        let elements = self.elements(view, offset, accessor.count.0, component, 1, true).map_err(here)?;
        Ok((0..elements.count)
            .map(|k| match elements.get(k, 0) {
                Component::Int(i) => i as u32,
                Component::Float(_) => u32::MAX,
            })
            .collect())
    }
}

/// Reads at most `length` bytes of the external buffer file `uri` (relative to `dir`).
fn read_external(dir: Option<&Path>, uri: &str, length: u64) -> Result<Vec<u8>, String> {
    let Some(dir) = dir else {
        return Err(format!("the external file {uri:?} is not read when loading from memory"));
    };
    let relative = percent_decode(uri).ok_or_else(|| format!("{uri:?} is not a valid URI"))?;
    let path = Path::new(&relative);
    // A relative path inside the glTF's folder: no scheme, no absolute path, no `..`.
    if relative.contains(':')
        || !path.components().all(|c| matches!(c, path::Component::Normal(_) | path::Component::CurDir))
    {
        return Err(format!("{uri:?}: only relative paths inside the glTF file's folder are read"));
    }
    let path = dir.join(path);
    let meta = std::fs::metadata(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if !meta.is_file() {
        return Err(format!("{} is not a file", path.display()));
    }
    let file = std::fs::File::open(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let mut out = Vec::with_capacity(length.min(meta.len()) as usize);
    file.take(length).read_to_end(&mut out).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    Ok(out)
}

/// `%XX` escapes decoded; `None` if an escape is malformed or the result is not UTF-8.
fn percent_decode(s: &str) -> Option<String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = std::str::from_utf8(b.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(data: &[u8]) -> Result<(Mesh, LoadReport), String> {
        parse(data, "t.gltf", None, &LoadOptions { sources: true, ..LoadOptions::default() }).map_err(|e| e.to_string())
    }

    fn b64(bytes: &[u8]) -> String {
        base64::engine::general_purpose::STANDARD.encode(bytes)
    }

    /// A glTF with one buffer (a data: URI of `bin`) and the given JSON members.
    fn gltf(bin: &[u8], members: &str) -> Vec<u8> {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}],{members}}}"#,
            bin.len(),
            b64(bin)
        )
        .into_bytes()
    }

    fn floats(v: &[f32]) -> Vec<u8> {
        v.iter().flat_map(|f| f.to_le_bytes()).collect()
    }

    /// Four vertices of a unit square, and `indices` as u16 after them.
    fn square(indices: &[u16]) -> Vec<u8> {
        let mut bin = floats(&[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.]);
        bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
        bin
    }

    fn square_gltf(mode: u32, indices: &[u16], nodes: &str) -> Vec<u8> {
        let n = indices.len();
        gltf(
            &square(indices),
            &format!(
                r#""bufferViews":[{{"buffer":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":{}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"}},
{{"bufferView":1,"componentType":5123,"count":{n},"type":"SCALAR"}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"mode":{mode}}}]}}],{nodes}"#,
                2 * n
            ),
        )
    }

    /// One square (two triangles) placed by `nodes` nodes, each a root of the scene.
    fn square_placed(nodes: usize) -> Vec<u8> {
        let list: Vec<String> = (0..nodes).map(|_| r#"{"mesh":0}"#.to_string()).collect();
        let roots: Vec<String> = (0..nodes).map(|i| i.to_string()).collect();
        square_gltf(
            4,
            &[0, 1, 2, 0, 2, 3],
            &format!(r#""nodes":[{}],"scenes":[{{"nodes":[{}]}}]"#, list.join(","), roots.join(",")),
        )
    }

    #[test]
    fn instancing_past_the_triangle_limit_is_an_error_before_the_copies_are_made() {
        let options = |max| LoadOptions { max_triangles: max, ..LoadOptions::default() };
        let file = square_placed(1000);
        let (mesh, _) = parse(&file, "t.gltf", None, &options(2000)).unwrap();
        assert_eq!((mesh.triangles.len(), mesh.positions.len()), (2000, 4000));
        let err = parse(&file, "t.gltf", None, &options(1999)).unwrap_err().to_string();
        assert!(err.contains("the scene's nodes place at least 2000 triangles, more than the limit of 1999"), "{err}");
        assert!(err.contains("--max-triangles"), "{err}");
        // Placed vertices are held to three per allowed triangle: one triangle of the square's four
        // vertices, placed 1000 times, is 1000 triangles and 4000 vertices.
        let one = String::from_utf8(file).unwrap().replace(r#""count":6"#, r#""count":3"#).into_bytes();
        assert!(parse(&one, "t.gltf", None, &options(1334)).is_ok());
        let err = parse(&one, "t.gltf", None, &options(1333)).unwrap_err().to_string();
        assert!(err.contains("place at least 4000 vertices, more than three per allowed triangle (3999;"), "{err}");
    }

    #[test]
    fn meshes_sharing_one_accessor_count_as_their_placements() {
        // 1000 meshes, each the same square (one accessor pair), each placed once: decoded once
        // per mesh, and stopped by the limit as the decoded meshes add up.
        let meshes = vec![r#"{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}"#; 1000].join(",");
        let nodes: Vec<String> = (0..1000).map(|i| format!(r#"{{"mesh":{i}}}"#)).collect();
        let roots: Vec<String> = (0..1000).map(|i| i.to_string()).collect();
        let file = String::from_utf8(square_gltf(4, &[0, 1, 2, 0, 2, 3], r#""nodes":[]"#)).unwrap().replace(
            r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"mode":4}]}],"nodes":[]"#,
            &format!(
                r#""meshes":[{meshes}],"nodes":[{}],"scenes":[{{"nodes":[{}]}}]"#,
                nodes.join(","),
                roots.join(",")
            ),
        );
        let options = |max| LoadOptions { max_triangles: max, ..LoadOptions::default() };
        let (mesh, _) = parse(file.as_bytes(), "t.gltf", None, &options(2000)).unwrap();
        assert_eq!(mesh.triangles.len(), 2000);
        let err = parse(file.as_bytes(), "t.gltf", None, &options(999)).unwrap_err().to_string();
        assert!(err.contains("place at least 1000 triangles, more than the limit of 999"), "{err}");
    }

    #[test]
    fn an_instancing_bomb_is_refused_under_the_default_limit() {
        // The shape of the reported file: 20,000 nodes placing one mesh, here of 4,096 triangles
        // (82 million placed, past the default 2^26); refused before the copies, in a few
        // megabytes of memory rather than gigabytes.
        let k = 4096u32;
        let mut bin = floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0.]);
        bin.extend((0..3 * k).flat_map(|i| ((i % 3) as u16).to_le_bytes()));
        let nodes: Vec<String> = (0..20_000).map(|_| r#"{"mesh":0}"#.to_string()).collect();
        let roots: Vec<String> = (0..20_000).map(|i| i.to_string()).collect();
        let file = gltf(
            &bin,
            &format!(
                r#""bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":{}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}},
{{"bufferView":1,"componentType":5123,"count":{},"type":"SCALAR"}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"nodes":[{}],"scenes":[{{"nodes":[{}]}}]"#,
                6 * k,
                3 * k,
                nodes.join(","),
                roots.join(",")
            ),
        );
        assert!(file.len() < 1 << 20, "{} bytes", file.len());
        let err = load(&file).unwrap_err();
        // Stopped at the first placement past the limit: 16,385 of 4,096 triangles.
        assert!(
            err.contains("the scene's nodes place at least 67112960 triangles, more than the limit of 67108864"),
            "{err}"
        );
    }

    #[test]
    fn triangles_strips_and_fans() {
        let one = r#""nodes":[{"mesh":0}]"#;
        let (m, report) = load(&square_gltf(4, &[0, 1, 2, 0, 2, 3], one)).unwrap();
        assert_eq!(m.triangles, [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.positions[2], Vec3::new(1., 1., 0.));
        let g = |triangle| Source::Gltf { node: 0, mesh: 0, primitive: 0, triangle };
        assert_eq!(report.sources, [g(0), g(1)]);
        assert_eq!(load(&square_gltf(5, &[0, 1, 3, 2], one)).unwrap().0.triangles, [[0, 1, 3], [1, 2, 3]]);
        assert_eq!(load(&square_gltf(6, &[0, 1, 2, 3], one)).unwrap().0.triangles, [[1, 2, 0], [2, 3, 0]]);
        assert_eq!(triangles(Mode::TriangleStrip, &[0, 1]).unwrap(), Vec::<[u32; 3]>::new());
    }

    #[test]
    fn lines_and_points_are_skipped_and_counted() {
        let one = r#""nodes":[{"mesh":0}]"#;
        let (m, report) = load(&square_gltf(1, &[0, 1, 2, 3], one)).unwrap();
        assert_eq!((m.triangles.len(), report.skipped), (0, 1));
        let first = report.first_skipped.unwrap();
        assert_eq!(
            (first.location.as_str(), first.what.as_str()),
            ("mesh 0 primitive 0 (node 0)", "a primitive in LINES mode")
        );
        let e = parse(&square_gltf(0, &[0, 1], one), "t.gltf", None, &LoadOptions::STRICT).unwrap_err().to_string();
        assert_eq!(e, "t.gltf: meshes[0].primitives[0]: a primitive in POINTS mode is not triangles");
    }

    #[test]
    fn node_transforms_compose_down_the_tree() {
        // Node 0 moves by +10 x and has child 1, which scales by 2; node 2 (a second root)
        // uses the mesh untransformed. Order: 0, 1, 2.
        let nodes = r#""scene":0,"scenes":[{"nodes":[0,2]}],"nodes":[{"mesh":0,"translation":[10,0,0],"children":[1]},
{"mesh":0,"scale":[2,2,2]},{"mesh":0,"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]}]"#;
        let (m, report) = load(&square_gltf(4, &[0, 1, 2], nodes)).unwrap();
        assert_eq!(m.triangles, [[0, 1, 2], [4, 5, 6], [8, 9, 10]]);
        assert_eq!(m.positions[2], Vec3::new(11., 1., 0.));
        assert_eq!(m.positions[6], Vec3::new(12., 2., 0.));
        assert_eq!(m.positions[10], Vec3::new(1., 1., 0.));
        let nodes: Vec<u32> = report
            .sources
            .iter()
            .map(|s| match s {
                Source::Gltf { node, .. } => *node,
                _ => unreachable!(),
            })
            .collect();
        assert_eq!(nodes, [0, 1, 2]);
        // No scene: the root nodes in index order.
        let nodes = r#""nodes":[{"mesh":0,"translation":[0,0,5]},{"children":[0]},{"mesh":0}]"#;
        let m = load(&square_gltf(4, &[0, 1, 2], nodes)).unwrap().0;
        assert_eq!((m.positions[0], m.positions[4]), (Vec3::new(0., 0., 5.), Vec3::ZERO));
    }

    #[test]
    fn non_indexed_and_sparse() {
        let bin = {
            let mut b = floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0.]);
            b.extend(2u8.to_le_bytes());
            b.extend([0u8; 3]);
            b.extend(floats(&[5., 5., 5.]));
            b
        };
        let members = r#""bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":1},
{"buffer":0,"byteOffset":40,"byteLength":12}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
"sparse":{"count":1,"indices":{"bufferView":1,"componentType":5121},"values":{"bufferView":2}}}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}]"#;
        let m = load(&gltf(&bin, members)).unwrap().0;
        assert_eq!(m.triangles, [[0, 1, 2]]);
        assert_eq!(m.positions, [Vec3::ZERO, Vec3::X, Vec3::splat(5.)]);
    }

    #[test]
    fn quantized_positions() {
        // Normalized unsigned bytes, 4 bytes apart (byteStride).
        let bin = [0u8, 0, 0, 0, 255, 0, 0, 0, 0, 255, 0, 0];
        let members = r#""bufferViews":[{"buffer":0,"byteLength":12,"byteStride":4}],
"accessors":[{"bufferView":0,"componentType":5121,"normalized":true,"count":3,"type":"VEC3"}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}]"#;
        let m = load(&gltf(&bin, members)).unwrap().0;
        assert_eq!(m.positions, [Vec3::ZERO, Vec3::X, Vec3::Y]);
    }

    /// A GLB of the JSON and binary chunks.
    fn glb_of(json: &str, bin: &[u8]) -> Vec<u8> {
        let mut json = json.as_bytes().to_vec();
        json.resize(json.len().div_ceil(4) * 4, b' ');
        let mut bin = bin.to_vec();
        bin.resize(bin.len().div_ceil(4) * 4, 0);
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
        out.extend((json.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(&json);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(&bin);
        out
    }

    const GLB_JSON: &str = r#"{"asset":{"version":"2.0"},"buffers":[{"byteLength":36}],
"bufferViews":[{"buffer":0,"byteLength":36}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}]}"#;

    #[test]
    fn glb_container() {
        let bin = floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0.]);
        let data = glb_of(GLB_JSON, &bin);
        assert!(has_magic(&data));
        assert_eq!(load(&data).unwrap().0.triangles, [[0, 1, 2]]);
        let e = |data: &[u8]| load(data).unwrap_err();
        assert_eq!(e(&data[..8]), "t.gltf: byte 0: GLB of 8 bytes: shorter than its 12-byte header");
        assert_eq!(
            e(&data[..40]),
            format!("t.gltf: byte 8: the header gives the file's length as {} bytes; it has 40", data.len())
        );
        let mut v1 = data.clone();
        v1[4] = 1;
        assert_eq!(e(&v1), "t.gltf: byte 4: GLB version 1: only version 2 is read");
        let mut long_chunk = data.clone();
        long_chunk[12] = 0xff;
        assert!(e(&long_chunk).starts_with("t.gltf: byte 12: chunk 0 of "), "{}", e(&long_chunk));
        // A hostile length below the header's size: the gltf crate's own reader underflows here.
        let mut tiny = data.clone();
        tiny[8..12].copy_from_slice(&4u32.to_le_bytes());
        assert!(e(&tiny).starts_with("t.gltf: byte 8: the header gives the file's length as 4 bytes"));
        // The BIN chunk shorter than the buffer.
        let short = glb_of(&GLB_JSON.replace("\"byteLength\":36}]", "\"byteLength\":40}]"), &bin);
        assert!(e(&short).contains("buffers[0]: byteLength is 40, but the data has 36 bytes"), "{}", e(&short));
        // JSON errors are positioned in the chunk.
        let bad = glb_of("{\"asset\":{}}", &bin);
        assert!(
            e(&bad).starts_with("t.gltf: byte 20: JSON chunk: invalid glTF JSON: missing field `version`"),
            "{}",
            e(&bad)
        );
    }

    #[test]
    fn hostile_files_are_errors() {
        let one = r#""nodes":[{"mesh":0}]"#;
        let e = |data: &[u8]| load(data).unwrap_err();
        assert!(e(b"{\"asset\":").starts_with("t.gltf:1: invalid glTF JSON: EOF"), "{}", e(b"{\"asset\":"));
        // Out-of-range references.
        let bad_index = square_gltf(4, &[0, 1, 4], one);
        assert_eq!(e(&bad_index), "t.gltf: meshes[0].primitives[0].indices: index 2 is 4, but POSITION has 4 vertices");
        let data = square_gltf(4, &[0, 1, 2], r#""nodes":[{"mesh":3}]"#);
        assert_eq!(e(&data), "t.gltf: nodes[0].mesh: mesh 3 does not exist (1 meshes)");
        let data = square_gltf(4, &[0, 1, 2], r#""scenes":[{"nodes":[5]}]"#);
        assert_eq!(e(&data), "t.gltf: scenes[0].nodes[0]: node 5 does not exist (0 nodes)");
        // Cycles and shared children.
        let data =
            square_gltf(4, &[0, 1, 2], r#""scenes":[{"nodes":[0]}],"nodes":[{"children":[1]},{"children":[0]}]"#);
        assert!(e(&data).starts_with("t.gltf: nodes[1].children[0]: node 0 is reached twice"), "{}", e(&data));
        // Claimed counts beyond the data.
        let data =
            String::from_utf8(square_gltf(4, &[0, 1, 2], one)).unwrap().replace("\"count\":4", "\"count\":4000000000");
        assert!(e(data.as_bytes()).contains("4000000000 elements of 12 bytes"), "{}", e(data.as_bytes()));
        let data = String::from_utf8(square_gltf(4, &[0, 1, 2], one))
            .unwrap()
            .replace("\"byteLength\":48}", "\"byteLength\":18446744073709551615}");
        assert!(e(data.as_bytes()).contains("run past its buffer"), "{}", e(data.as_bytes()));
        let data = String::from_utf8(square_gltf(4, &[0, 1, 2], one))
            .unwrap()
            .replace("\"byteLength\":48}", "\"byteLength\":48,\"byteStride\":4}");
        assert!(
            e(data.as_bytes()).contains("byteStride 4 is less than an element's 12 bytes"),
            "{}",
            e(data.as_bytes())
        );
        // Unsupported required extensions; external files from memory.
        let data = String::from_utf8(square_gltf(4, &[0, 1, 2], one))
            .unwrap()
            .replace("\"asset\"", "\"extensionsRequired\":[\"KHR_draco_mesh_compression\"],\"asset\"");
        assert_eq!(e(data.as_bytes()), "t.gltf: extensionsRequired[0]: KHR_draco_mesh_compression is not supported");
        let data = r#"{"asset":{"version":"2.0"},"buffers":[{"byteLength":4,"uri":"mesh.bin"}],
"bufferViews":[{"buffer":0,"byteLength":4}],"accessors":[{"bufferView":0,"componentType":5126,"count":0,"type":"VEC3"}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}]}"#;
        assert!(e(data.as_bytes()).contains("the external file \"mesh.bin\" is not read when loading from memory"));
        let escape = data.replace("mesh.bin", "../secret.bin");
        let e2 = parse(escape.as_bytes(), "t.gltf", Some(Path::new(".")), &LoadOptions::default()).unwrap_err();
        assert!(e2.to_string().contains("only relative paths inside the glTF file's folder"), "{e2}");
        assert_eq!(percent_decode("a%20b.bin").as_deref(), Some("a b.bin"));
        assert_eq!(percent_decode("a%2"), None);
    }
}
