//! Scene files of instances: a small JSON file naming mesh files and where each is placed.
//!
//! ```json
//! {
//!   "meshes": ["bunny.obj", "builtin"],
//!   "instances": [
//!     { "mesh": 0 },
//!     { "mesh": 0, "transform": [[0.5, 0, 0, 2], [0, 0.5, 0, 0], [0, 0, 0.5, 0]], "id": 7, "mask": 2 },
//!     { "mesh": 1, "transform": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -3]] }
//!   ]
//! }
//! ```
//!
//! `meshes` are paths relative to the scene file's folder (or `builtin`), each loaded once.
//! An instance names a mesh by its index; `transform` is the 3x4 map `[A | b]` from the mesh's
//! frame to the world, row by row (the identity where left out); `id` is what its hits report
//! (its index where left out); `mask` is tested against each ray's mask (every bit where left
//! out). Unknown fields are errors, so a misspelt `trasform` is not silently the identity.

use crate::args::{is_builtin, load_scene, warn};
use crate::failure::Failure;
use raytrail::core::scene::Scene;
use raytrail::mesh::LoadOptions;
use raytrail::{Instance, Transform};
use serde::Deserialize;
use std::io::Read;
use std::path::{Path, PathBuf};

/// The largest scene file read, in bytes: about a million instances.
pub const MAX_SCENE_FILE_BYTES: u64 = 256 << 20;

/// Whether `path` names a scene file of instances (by its `.json` extension).
pub fn is_instance_file(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json"))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    meshes: Vec<String>,
    instances: Vec<Placement>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Placement {
    mesh: u32,
    #[serde(default)]
    transform: Option<[[f32; 4]; 3]>,
    #[serde(default)]
    id: Option<u32>,
    #[serde(default)]
    mask: Option<u32>,
}

/// A loaded scene file: its meshes (with the paths they came from) and its instances.
pub struct InstanceFile {
    pub meshes: Vec<Scene>,
    pub mesh_paths: Vec<PathBuf>,
    pub instances: Vec<Instance>,
}

impl InstanceFile {
    /// Triangles after instancing: what a flattened copy of the scene would hold.
    pub fn instanced_triangles(&self) -> u64 {
        self.instances.iter().map(|i| self.meshes[i.mesh as usize].triangles().len() as u64).sum()
    }
}

/// Reads the scene file `path` and loads its meshes with `options`. Errors name the file and
/// what is wrong: JSON that does not parse (with its line and column), an instance whose mesh
/// index is out of range, a mesh file that does not load.
pub fn load_instances(path: &Path, options: &LoadOptions) -> Result<InstanceFile, Failure> {
    let shown = path.display();
    let mut text = String::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_SCENE_FILE_BYTES + 1).read_to_string(&mut text))
        .map_err(|e| format!("{shown}: {e}"))?;
    if text.len() as u64 > MAX_SCENE_FILE_BYTES {
        return Err(format!("{shown}: a scene file larger than {MAX_SCENE_FILE_BYTES} bytes").into());
    }
    let file: File = serde_json::from_str(&text).map_err(|e| format!("{shown}: {e}"))?;
    if file.instances.is_empty() {
        return Err(format!("{shown}: no instances").into());
    }
    let mut instances = Vec::with_capacity(file.instances.len());
    for (i, p) in file.instances.iter().enumerate() {
        if p.mesh as usize >= file.meshes.len() {
            let n = file.meshes.len();
            return Err(format!("{shown}: instance {i} names mesh {}, but the file has {n} meshes", p.mesh).into());
        }
        let transform = p.transform.map_or(Transform::IDENTITY, Transform::from_rows);
        let instance = Instance::new(p.mesh, transform).with_id(p.id.unwrap_or(i as u32));
        instances.push(instance.with_mask(p.mask.unwrap_or(u32::MAX)));
    }
    let folder = path.parent().unwrap_or(Path::new(""));
    let mut meshes = Vec::with_capacity(file.meshes.len());
    let mut mesh_paths = Vec::with_capacity(file.meshes.len());
    for name in &file.meshes {
        let mesh_path = if is_builtin(Path::new(name)) { PathBuf::from(name) } else { folder.join(name) };
        let (named, _, warning) = load_scene(&mesh_path, options).map_err(|e| format!("{shown}: mesh {e}"))?;
        warn(&warning);
        meshes.push(named.scene);
        mesh_paths.push(mesh_path);
    }
    Ok(InstanceFile { meshes, mesh_paths, instances })
}
