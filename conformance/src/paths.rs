//! Where the real meshes live, and loading them as scenes.
//!
//! The two small meshes the tests need ship in the crate (`scenes/`, with their sources and
//! licences in `scenes/SOURCES.md`); the large ones are read from [`scenes_dir`]. A test whose
//! large mesh is missing prints one line saying so and passes ([`find_mesh`]), unless
//! [`REQUIRE_SCENES`] is 1, as CI sets it: then a missing mesh fails the test.

use crate::scenes::NamedScene;
use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Environment variable that overrides [`scenes_dir`].
pub const SCENES_ENV: &str = "RAYTRAIL_SCENES";

/// Set to 1 to make a missing mesh fail its test instead of skipping it (CI sets it, after
/// fetching the scenes).
pub const REQUIRE_SCENES: &str = "RAYTRAIL_REQUIRE_SCENES";

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

/// The mesh files of [`MESH_FILES`] that ship in this crate ([`bundled_dir`]).
pub const BUNDLED_FILES: &[&str] = &["cornell_box.obj", "teapot.obj"];

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

/// The folder of the meshes that ship in this crate ([`BUNDLED_FILES`]).
pub fn bundled_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

/// Path of a mesh file: in [`scenes_dir`] when there, else the crate's own copy of a
/// [`BUNDLED_FILES`] mesh, else where [`scenes_dir`] would have it (a path that does not exist).
/// A path with a folder is taken as it is.
pub fn mesh_path(file: &str) -> PathBuf {
    let path = scenes_dir().join(file);
    if path.is_file() || Path::new(file).parent().is_some_and(|p| !p.as_os_str().is_empty()) {
        return path;
    }
    let bundled = bundled_dir().join(file);
    if BUNDLED_FILES.contains(&file) && bundled.is_file() {
        bundled
    } else {
        path
    }
}

/// The files of [`MESH_FILES`] present (in [`scenes_dir`] or bundled), in the same order.
pub fn available_mesh_files() -> Vec<&'static str> {
    MESH_FILES.iter().copied().filter(|f| mesh_path(f).is_file()).collect()
}

/// Whether [`REQUIRE_SCENES`] is 1.
pub fn scenes_required() -> bool {
    std::env::var(REQUIRE_SCENES).as_deref() == Ok("1")
}

/// Prints one line saying what a test skipped and why, on the process's standard error itself, so
/// that the test harness (which captures `println!` and `eprintln!` of passing tests) shows it.
pub fn say_skipped(what: &str, why: &str) {
    let _ = writeln!(std::io::stderr(), "SKIPPED {what}: {why} (set {REQUIRE_SCENES}=1 to make this a failure)");
}

/// The path of mesh `file` ([`mesh_path`]) when it exists. When it does not: with
/// [`REQUIRE_SCENES`] set to 1, panics naming it and where it was looked for; otherwise prints one
/// line saying so ([`say_skipped`]) and returns `None`, for the caller to skip.
pub fn find_mesh(file: &str) -> Option<PathBuf> {
    let path = mesh_path(file);
    if path.is_file() {
        return Some(path);
    }
    let why = format!(
        "{} not found (point {SCENES_ENV} at the scenes folder, or run scripts/fetch_scenes.sh)",
        path.display()
    );
    assert!(!scenes_required(), "missing mesh {file}: {why}");
    say_skipped(file, &why);
    None
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

/// A mesh file that could not be made a scene.
#[derive(Debug)]
pub enum SceneFileError {
    /// The file could not be read or parsed (the error names the file).
    Load(raytrail_mesh::MeshError),
    /// The file loaded, but its mesh is no valid scene (no triangles, a NaN coordinate, ...).
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong with its mesh.
        error: raytrail_core::Error,
    },
}

impl fmt::Display for SceneFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SceneFileError::Load(e) => write!(f, "cannot load mesh {e}"),
            SceneFileError::Invalid { path, error } => write!(f, "invalid mesh {}: {error}", path.display()),
        }
    }
}

impl std::error::Error for SceneFileError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SceneFileError::Load(e) => Some(e),
            SceneFileError::Invalid { error, .. } => Some(error),
        }
    }
}

/// Loads `file` (a name in [`scenes_dir`] or bundled, or a path) as a scene named by
/// [`mesh_scene_name`]. The error names the file's full path and says what failed (reading,
/// parsing, or an invalid mesh such as one without triangles).
pub fn load_mesh_scene(file: &str) -> Result<NamedScene, SceneFileError> {
    let path = mesh_path(file);
    let mesh = raytrail_mesh::load(&path).map_err(SceneFileError::Load)?;
    let scene = mesh.to_scene().map_err(|error| SceneFileError::Invalid { path, error })?;
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
        let err = load_mesh_scene("no_such_mesh_file.obj").unwrap_err().to_string();
        assert!(err.contains("no_such_mesh_file.obj"), "{err}");
    }

    #[test]
    fn small_meshes_load() {
        // They ship in the crate: found with no scenes folder at all.
        for &file in BUNDLED_FILES {
            assert!(mesh_path(file).is_file(), "{file} ships in the crate");
            let s = load_mesh_scene(file).unwrap();
            let expected = if file == "teapot.obj" { 6_320 } else { 36 };
            assert_eq!(s.scene.triangles().len(), expected, "{file}");
        }
    }
}
