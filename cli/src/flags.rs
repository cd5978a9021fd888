//! Names and flags that several commands' arguments share: the built-in scene, the mesh loading
//! flags, the builder and method names and `auto`.

use clap::builder::PossibleValuesParser;
use raytrail::core::method::Method;
use raytrail::mesh::LoadOptions;
use raytrail::Builder;

/// The `--scene` name of the built-in scene: the conformance suite's sphereflake (25,220
/// triangles), generated, so that the main job needs no file.
pub const BUILTIN_SCENE: &str = "builtin";

/// The switch that makes mesh loading strict (`run`, `trace`, `rays`, `bench`, `render`): an
/// element that is not a triangle or polygon (a face of fewer than three vertices, an OBJ line or
/// point, a glTF line or point primitive) fails the load instead of being skipped with a warning.
pub const STRICT: &str = "strict";

/// The mesh loading flags.
#[derive(clap::Args, Debug, Clone, PartialEq, Eq)]
pub struct LoadFlags {
    /// Fail on mesh elements that are not triangles or polygons instead of skipping them
    #[arg(long)]
    pub strict: bool,
    /// Largest size a gzip-compressed mesh may inflate to, in bytes
    #[arg(long, value_name = "BYTES", default_value_t = LoadOptions::DEFAULT_MAX_INFLATED)]
    pub max_mesh_bytes: u64,
    /// Most triangles a mesh may make (after polygons are split and glTF nodes place their meshes)
    #[arg(long, value_name = "N", default_value_t = LoadOptions::DEFAULT_MAX_TRIANGLES)]
    pub max_triangles: u64,
}

impl Default for LoadFlags {
    /// The defaults the command line has.
    fn default() -> Self {
        LoadFlags {
            strict: false,
            max_mesh_bytes: LoadOptions::DEFAULT_MAX_INFLATED,
            max_triangles: LoadOptions::DEFAULT_MAX_TRIANGLES,
        }
    }
}

impl LoadFlags {
    /// The mesh loading policy of [`STRICT`].
    pub fn load_options(&self) -> LoadOptions {
        LoadOptions {
            strict: self.strict,
            max_inflated: self.max_mesh_bytes,
            max_triangles: self.max_triangles,
            ..LoadOptions::default()
        }
    }
}

/// The BVH2 builders by command-line name.
pub const BUILDERS: [&str; 4] =
    [Builder::ALL[0].name(), Builder::ALL[1].name(), Builder::ALL[2].name(), Builder::ALL[3].name()];

/// The name that asks for the method to be chosen by timing candidates on a sample of the rays
/// (`raytrail::analysis`).
pub const AUTO: &str = "auto";

/// The method names and [`AUTO`], for `--method` where a method can be chosen.
pub fn method_names_or_auto() -> PossibleValuesParser {
    PossibleValuesParser::new(std::iter::once(AUTO).chain(Method::ALL.map(Method::name)))
}

/// A `--method` value: a fixed method, or `None` for [`AUTO`].
pub fn method_or_auto(name: &str) -> Option<Method> {
    (name != AUTO).then(|| method(name))
}

/// The builder of a name that clap has checked.
pub fn builder(name: &str) -> Builder {
    Builder::from_name(name).unwrap_or_default()
}

/// The method of a name that clap has checked.
pub fn method(name: &str) -> Method {
    Method::from_name(name).expect("clap checks the method name")
}
