//! Where the real meshes live, and loading them as scenes.

use crate::scenes::NamedScene;
use std::path::{Path, PathBuf};

/// Environment variable that overrides [`scenes_dir`].
pub const SCENES_ENV: &str = "RAYTRAIL_SCENES";

/// The mesh files of the suite, smallest first (see `SOURCES.md` in [`scenes_dir`]).
pub const MESH_FILES: &[&str] = &[
    "cornell_box.obj",
    "teapot.obj",
    "kitchen.obj",
    "sponza.obj",
    "bunny.obj",
    "dragon_vrip_res2.ply.gz",
    "dragon_vrip.ply.gz",
];

/// The folder of the mesh files: `$RAYTRAIL_SCENES` when set and non-empty, else `shared/scenes`
/// beside the checkout (`<conformance crate>/../../shared/scenes`), canonicalized when it exists.
pub fn scenes_dir() -> PathBuf {
    match std::env::var_os(SCENES_ENV) {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir),
        _ => {
            let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/scenes");
            dir.canonicalize().unwrap_or(dir)
        }
    }
}

/// Path of a mesh file in [`scenes_dir`].
pub fn mesh_path(file: &str) -> PathBuf {
    scenes_dir().join(file)
}

/// The files of [`MESH_FILES`] present in [`scenes_dir`], in the same order.
pub fn available_mesh_files() -> Vec<&'static str> {
    MESH_FILES.iter().copied().filter(|f| mesh_path(f).is_file()).collect()
}

/// Name a mesh scene is reported under: the file name without `.gz` and the format extension.
pub fn mesh_scene_name(file: &str) -> String {
    let name = Path::new(file).file_name().and_then(|n| n.to_str()).unwrap_or(file);
    let name = name.strip_suffix(".gz").unwrap_or(name);
    match name.rsplit_once('.') {
        Some((stem, _ext)) if !stem.is_empty() => stem.to_string(),
        _ => name.to_string(),
    }
}

/// Loads `file` (a name in [`scenes_dir`], or a path) as a scene named by [`mesh_scene_name`].
///
/// The error message names the file's full path and says what failed (reading, parsing, or an
/// invalid mesh such as one without triangles).
pub fn load_mesh_scene(file: &str) -> Result<NamedScene, String> {
    let path = mesh_path(file);
    let mesh = raytrail_core::mesh::load(&path).map_err(|e| format!("cannot load mesh {}: {e}", path.display()))?;
    let scene = mesh.to_scene().map_err(|e| format!("invalid mesh {}: {e}", path.display()))?;
    Ok(NamedScene::new(mesh_scene_name(file), scene))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_drop_extensions() {
        assert_eq!(mesh_scene_name("dragon_vrip_res2.ply.gz"), "dragon_vrip_res2");
        assert_eq!(mesh_scene_name("cornell_box.obj"), "cornell_box");
        assert_eq!(mesh_scene_name("/a/b/teapot.obj"), "teapot");
        assert_eq!(mesh_scene_name("noext"), "noext");
    }

    #[test]
    fn default_dir_holds_the_meshes() {
        // Only meaningful where the shared scenes are checked out beside the repository.
        if std::env::var_os(SCENES_ENV).is_none() && scenes_dir().is_dir() {
            assert_eq!(available_mesh_files(), MESH_FILES);
        }
    }

    #[test]
    fn missing_file_error_names_it() {
        let err = load_mesh_scene("no_such_mesh_file.obj").unwrap_err();
        assert!(err.contains("no_such_mesh_file.obj"), "{err}");
    }

    #[test]
    fn small_meshes_load() {
        for file in ["cornell_box.obj", "teapot.obj"] {
            if !mesh_path(file).is_file() {
                continue;
            }
            let s = load_mesh_scene(file).unwrap();
            let expected = if file == "teapot.obj" { 6_320 } else { 36 };
            assert_eq!(s.scene.triangles().len(), expected, "{file}");
        }
    }
}
