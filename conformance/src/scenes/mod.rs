//! Generated test scenes: deterministic, a few thousand to some tens of thousands of triangles, each
//! aimed at one way traversal can go wrong.
//!
//! - [`shared_edge_grid`]: watertightness along shared edges and vertices.
//! - [`sphereflake`]: a deep, cluttered hierarchy of closed meshes at many scales.
//! - [`triangle_soup`]: overlapping, sliver and zero-area triangles.
//! - [`degenerate_stack`]: a tree deeper than 31 levels, so 64-bit keys.
//! - [`far_from_origin`]: coordinates around 1e5..1e6, where `f32` spacing is coarse.
//! - [`tiny_cases`]: one to a handful of triangles, for corner cases.
//! - [`breathing`]: any of them with its vertices moved, for the refit checks.

mod breathing;
mod far;
mod grid;
pub(crate) mod icosphere;
mod soup;
mod sphereflake;
mod stack;
mod tiny;

pub use breathing::breathing;
pub use far::{far_from_origin, FAR_CENTER};
pub use grid::shared_edge_grid;
pub use soup::triangle_soup;
pub use sphereflake::sphereflake;
pub use stack::{
    degenerate_stack, DEFAULT_LAYERS as DEGENERATE_STACK_LAYERS, MAX_LAYERS as DEGENERATE_STACK_MAX_LAYERS,
};
pub use tiny::tiny_cases;

use raytrail_core::geometry::Triangle;
use raytrail_core::scene::Scene;

/// A scene with the name the suite reports it under.
#[derive(Clone, Debug)]
pub struct NamedScene {
    /// Short name (a generator's name, or a mesh file's stem).
    pub name: String,
    /// The triangles.
    pub scene: Scene,
}

impl NamedScene {
    /// A named scene.
    pub fn new(name: impl Into<String>, scene: Scene) -> Self {
        Self { name: name.into(), scene }
    }
}

/// Seed of the generated scenes in [`generated`]; fixed so the suite is the same on every run.
pub const SCENE_SEED: u64 = 0x5ce7e;

/// Every generated scene at the size the suite uses.
pub fn generated() -> Vec<NamedScene> {
    vec![
        NamedScene::new("shared_edge_grid", shared_edge_grid(64)),
        NamedScene::new("sphereflake", sphereflake(3)),
        NamedScene::new("triangle_soup", triangle_soup(10_000, SCENE_SEED)),
        NamedScene::new("degenerate_stack", degenerate_stack(stack::DEFAULT_LAYERS, SCENE_SEED)),
        NamedScene::new("far_from_origin", far_from_origin()),
    ]
}

/// A scene of generated triangles; generators only make non-empty, finite geometry.
fn scene_of(triangles: Vec<Triangle>) -> Scene {
    Scene::new(triangles).expect("generated scenes are non-empty with finite vertices")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generated_scenes_are_deterministic_and_named() {
        let (a, b) = (generated(), generated());
        let names: Vec<&str> = a.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["shared_edge_grid", "sphereflake", "triangle_soup", "degenerate_stack", "far_from_origin"]);
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.scene, y.scene, "{}", x.name);
        }
    }
}
