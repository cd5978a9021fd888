//! The bodies of the fuzz targets (`fuzz/fuzz_targets/*.rs`, run by `cargo fuzz`), here so that
//! the corpus and every crash input replay as ordinary tests on the stable toolchain
//! (`cli/tests/fuzz_corpus.rs`). Each takes any bytes and returns only by deciding them: a panic,
//! an abort or a wrong answer is the finding. What each checks:
//! - [`mesh_file`]: a loader (by the name's extension, or by content, gzip included) answers any
//!   bytes with a mesh whose indices are in range or with an error, within small limits;
//! - [`npy_rays`]: the NumPy ray reader answers with rays or an error;
//! - [`trace`]: any triangles and rays read from the bytes trace to the same closest and any hits
//!   on the CPU backend's default walks as on the serial reference backend.

use crate::npy;
use raytrail::core::method::{Bvh2Method, Method, Query, WideMethod};
use raytrail::core::prepared::PreparedScene;
use raytrail::core::scene::Scene;
use raytrail::core::trace::{Trace, TraceOptions};
use raytrail::core::{Hit, Ray};
use raytrail::cpu::CpuBackend;
use raytrail::mesh::LoadOptions;
use raytrail::Builder;
use raytrail_conformance::SerialBackend;
use std::sync::Arc;

/// The names the mesh targets load their bytes under: one per format, and one without an
/// extension (the format from the content).
pub const MESH_NAMES: [&str; 8] = ["x.obj", "x.ply", "x.off", "x.stl", "x.gltf", "x.glb", "x.obj.gz", "x"];

/// Loads `data` as the mesh file `name` with limits a fuzzer cannot exhaust (16 MiB inflated,
/// 2^20 triangles); panics where the answer breaks the loaders' promise (an index out of range).
pub fn mesh_file(name: &str, data: &[u8]) {
    let options = LoadOptions { max_inflated: 16 << 20, max_triangles: 1 << 20, ..LoadOptions::default() };
    if let Ok((mesh, _)) = raytrail::mesh::load_bytes_with(data, name, &options) {
        let n = mesh.positions.len();
        assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n), "{name}: an index past the vertices");
        assert!(mesh.triangles.len() <= 1 << 20, "{name}: past the triangle limit");
        // A mesh that loads is a scene or a clear error.
        let _ = mesh.to_scene();
    }
}

/// Reads `data` as a NumPy ray file.
pub fn npy_rays(data: &[u8]) {
    if let Ok(rays) = npy::read_rays_from(data) {
        assert!(rays.len() * 32 <= data.len(), "more rays than bytes");
    }
}

/// The floats of `data`, four bytes each (the rest dropped).
fn floats(data: &[u8]) -> Vec<f32> {
    data.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

/// Traces rays through triangles, both read from `data`: its first byte is the number of
/// triangles (1 to 64), then nine floats a triangle, then eight floats a ray (at most 256). A
/// scene of non-finite vertices is an error and nothing more; otherwise every CPU default walk,
/// on the SAH tree and on the spatial-split tree, must answer as the serial backend's stack method
/// on the SAH tree, closest hits bit for bit and any hits by occlusion.
pub fn trace(data: &[u8]) {
    let Some((&count, rest)) = data.split_first() else { return };
    let f = floats(rest);
    let tris = (count as usize % 64 + 1).min(f.len() / 9);
    if tris == 0 {
        return;
    }
    let triangles: Vec<_> = f[..9 * tris]
        .chunks_exact(9)
        .map(|v| {
            raytrail::core::geometry::Triangle::new(
                glam::Vec3::new(v[0], v[1], v[2]),
                glam::Vec3::new(v[3], v[4], v[5]),
                glam::Vec3::new(v[6], v[7], v[8]),
            )
        })
        .collect();
    let rays: Vec<Ray> = f[9 * tris..]
        .chunks_exact(8)
        .take(256)
        .map(|r| Ray { origin: [r[0], r[1], r[2]], tmin: r[3], dir: [r[4], r[5], r[6]], tmax: r[7] })
        .collect();
    let Ok(scene) = Scene::new(triangles) else { return };
    let methods = [
        Method::Bvh2(Bvh2Method::Stack),
        Method::Wide(WideMethod::BVH8_SAH),
        Method::Wide(WideMethod::BVH8_SAH_PACKET),
        Method::Wide(WideMethod::BVH8_SAH_LISTS),
    ];
    let (serial, cpu) = (SerialBackend, CpuBackend::new());
    // The SAH tree's serial stack walk is the answer; hits do not depend on the tree, so the
    // spatial-split tree (triangles cut across leaves) must give the same.
    let mut want: Option<[Vec<Hit>; 2]> = None;
    for builder in [Builder::Sah, Builder::Sbvh] {
        let Ok(bvh) = builder.build(&scene) else { return };
        let prepared = Arc::new(PreparedScene::new(&scene, bvh, &methods).expect("a scene that builds prepares"));
        let serial_scene = serial.prepare(prepared.clone()).expect("prepare");
        let cpu_scene = cpu.prepare(prepared).expect("prepare");
        let answer = want.get_or_insert_with(|| {
            [Query::Closest, Query::Any].map(|query| {
                let mut hits = vec![Hit::MISS; rays.len()];
                let opts = TraceOptions::new(methods[0]).query(query);
                serial.trace(&serial_scene, &rays, &opts, &mut hits).expect("trace");
                hits
            })
        });
        for (query, want) in [Query::Closest, Query::Any].into_iter().zip(answer.iter()) {
            for method in methods {
                let mut got = vec![Hit::MISS; rays.len()];
                cpu.trace(&cpu_scene, &rays, &TraceOptions::new(method).query(query), &mut got).expect("trace");
                for (i, (w, g)) in want.iter().zip(&got).enumerate() {
                    let same = match query {
                        Query::Closest => w.same_as(g),
                        Query::Any => w.is_hit() == g.is_hit(),
                    };
                    let tree = builder.name();
                    assert!(same, "{tree} {method} {query:?} ray {i} {:?}: {g:?}, the serial SAH stack {w:?}", rays[i]);
                }
            }
        }
    }
}
