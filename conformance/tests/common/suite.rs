//! The suite's scenes as a list of tests, written once and instantiated by every backend's test
//! file with its own check (`check(&scene, bvh, ray_set_size)`).

/// Defines one `#[test]` per scene of the suite, each calling `$check`.
#[macro_export]
macro_rules! conformance_suite {
    ($check:path) => {
        use raytrail_conformance::rays::RaySetSize;
        use raytrail_conformance::scenes::{generated, tiny_cases};
        use raytrail_conformance::NamedScene;
        use raytrail_core::bvh2::SahBuilder;
        use raytrail_core::key::KeyWidth;

        const MESH_RAYS: RaySetSize = RaySetSize { width: 64, height: 48, uniform_count: 4096 };
        const GENERATED_RAYS: RaySetSize = RaySetSize { width: 96, height: 72, uniform_count: 8192 };

        fn generated_scene(name: &str) -> NamedScene {
            generated().into_iter().find(|s| s.name == name).unwrap_or_else(|| panic!("no generated scene {name}"))
        }

        fn sah(named: &NamedScene, size: RaySetSize) {
            $check(named, SahBuilder::default().build(named.scene.triangles()).expect("build"), size);
        }

        fn ploc(named: &NamedScene, size: RaySetSize) {
            $check(named, raytrail_cpu::ploc::build_ploc(named.scene.triangles(), 63).expect("build"), size);
        }

        #[test]
        fn shared_edge_grid() {
            sah(&generated_scene("shared_edge_grid"), GENERATED_RAYS);
        }

        #[test]
        fn sphereflake() {
            let s = generated_scene("sphereflake");
            sah(&s, GENERATED_RAYS);
            ploc(&s, GENERATED_RAYS);
        }

        #[test]
        fn triangle_soup() {
            let s = generated_scene("triangle_soup");
            sah(&s, GENERATED_RAYS);
            ploc(&s, GENERATED_RAYS);
        }

        #[test]
        fn degenerate_stack_needs_and_uses_64_bit_keys() {
            let s = generated_scene("degenerate_stack");
            let bvh = SahBuilder::default().build(s.scene.triangles()).expect("build");
            assert_eq!(bvh.stats().key_width, KeyWidth::W64, "depth {} should need 64-bit keys", bvh.stats().depth);
            $check(&s, bvh, GENERATED_RAYS);
        }

        #[test]
        fn far_from_origin() {
            sah(&generated_scene("far_from_origin"), GENERATED_RAYS);
        }

        #[test]
        fn tiny_cases_all() {
            for s in tiny_cases() {
                sah(&s, RaySetSize { width: 16, height: 16, uniform_count: 512 });
            }
        }

        $crate::mesh_test!(cornell_box, "cornell_box.obj", sah, MESH_RAYS);
        $crate::mesh_test!(teapot, "teapot.obj", sah, MESH_RAYS);
        $crate::mesh_test!(kitchen, "kitchen.obj", sah, MESH_RAYS);
        $crate::mesh_test!(sponza, "sponza.obj", sah, MESH_RAYS);
        $crate::mesh_test!(bunny, "bunny.obj", sah, MESH_RAYS);
        $crate::mesh_test!(dragon_res2, "dragon_vrip_res2.ply.gz", sah, MESH_RAYS);
        $crate::mesh_test!(dragon_full, "dragon_vrip.ply.gz", sah, MESH_RAYS);
        $crate::mesh_test!(bunny_with_ploc, "bunny.obj", ploc, MESH_RAYS);
    };
}

/// One test over a mesh of `../shared/scenes` (see `common::mesh` for a missing folder).
#[macro_export]
macro_rules! mesh_test {
    ($name:ident, $file:expr, $build:ident, $size:expr) => {
        #[test]
        fn $name() {
            if let Some(s) = common::mesh($file) {
                $build(&s, $size);
            }
        }
    };
}
