//! The same mesh written in every format raytrail reads: shared by the core's format tests and the
//! conformance suite's (which includes this file by path), so both test one set of writers.
#![allow(dead_code)]

use base64::Engine as _;
use raytrail_core::scene::Mesh;
use std::io::Write;

pub fn corners(mesh: &Mesh) -> Vec<[[f32; 3]; 3]> {
    mesh.triangles.iter().map(|t| t.map(|i| mesh.positions[i as usize].to_array())).collect()
}

pub fn obj(m: &Mesh) -> Vec<u8> {
    let mut s = String::from("# written by the test\n");
    m.positions.iter().for_each(|p| s += &format!("v {} {} {}\n", p.x, p.y, p.z));
    m.triangles.iter().for_each(|t| s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    s.into_bytes()
}

pub fn off(m: &Mesh) -> Vec<u8> {
    let mut s = format!("OFF\n{} {} 0\n", m.positions.len(), m.triangles.len());
    m.positions.iter().for_each(|p| s += &format!("{} {} {}\n", p.x, p.y, p.z));
    m.triangles.iter().for_each(|t| s += &format!("3 {} {} {}\n", t[0], t[1], t[2]));
    s.into_bytes()
}

pub fn ply_ascii(m: &Mesh) -> Vec<u8> {
    let mut s = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        m.positions.len(),
        m.triangles.len()
    );
    m.positions.iter().for_each(|p| s += &format!("{} {} {}\n", p.x, p.y, p.z));
    m.triangles.iter().for_each(|t| s += &format!("3 {} {} {}\n", t[0], t[1], t[2]));
    s.into_bytes()
}

pub fn ply_binary(m: &Mesh) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        m.positions.len(),
        m.triangles.len()
    )
    .into_bytes();
    m.positions.iter().flat_map(|p| p.to_array()).for_each(|c| out.extend(c.to_le_bytes()));
    for t in &m.triangles {
        out.push(3);
        t.iter().for_each(|&i| out.extend((i as i32).to_le_bytes()));
    }
    out
}

pub fn stl_ascii(m: &Mesh) -> Vec<u8> {
    let mut s = String::from("solid sample\n");
    for t in corners(m) {
        s += "  facet normal 0 0 0\n    outer loop\n";
        t.iter().for_each(|v| s += &format!("      vertex {} {} {}\n", v[0], v[1], v[2]));
        s += "    endloop\n  endfacet\n";
    }
    s += "endsolid sample\n";
    s.into_bytes()
}

/// Binary STL; `claim` is the triangle count written in the header.
pub fn stl_binary(m: &Mesh, claim: u32) -> Vec<u8> {
    let mut out = b"solid (a binary STL whose header starts like an ASCII one)".to_vec();
    out.resize(80, b' ');
    out.extend(claim.to_le_bytes());
    for t in corners(m) {
        out.extend([0u8; 12]);
        t.iter().flatten().for_each(|c| out.extend(c.to_le_bytes()));
        out.extend([0u8; 2]);
    }
    out
}

/// The buffer of a glTF: positions (f32 x 3), then indices (u32).
pub fn gltf_buffer(m: &Mesh) -> Vec<u8> {
    let mut bin: Vec<u8> = m.positions.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
    bin.extend(m.triangles.iter().flatten().flat_map(|i| i.to_le_bytes()));
    bin
}

/// glTF JSON of the mesh with its buffer at `uri` (`None`: the GLB's BIN chunk).
pub fn gltf_json(m: &Mesh, uri: Option<&str>) -> String {
    let (nv, ni) = (m.positions.len(), 3 * m.triangles.len());
    let uri = uri.map_or(String::new(), |u| format!(r#","uri":"{u}""#));
    format!(
        r#"{{"asset":{{"version":"2.0","generator":"raytrail test"}},"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"buffers":[{{"byteLength":{len}{uri}}}],
"bufferViews":[{{"buffer":0,"byteLength":{pl}}},{{"buffer":0,"byteOffset":{pl},"byteLength":{il}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":{nv},"type":"VEC3"}},
{{"bufferView":1,"componentType":5125,"count":{ni},"type":"SCALAR"}}]}}"#,
        len = 12 * nv + 4 * ni,
        pl = 12 * nv,
        il = 4 * ni
    )
}

pub fn glb(m: &Mesh) -> Vec<u8> {
    let mut json = gltf_json(m, None).into_bytes();
    json.resize(json.len().div_ceil(4) * 4, b' ');
    let bin = gltf_buffer(m);
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

pub fn gltf_embedded(m: &Mesh) -> Vec<u8> {
    let b64 = base64::engine::general_purpose::STANDARD.encode(gltf_buffer(m));
    gltf_json(m, Some(&format!("data:application/octet-stream;base64,{b64}"))).into_bytes()
}

pub fn gzip(data: &[u8]) -> Vec<u8> {
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    enc.write_all(data).unwrap();
    enc.finish().unwrap()
}

/// The sample in every format, named by file.
pub fn every_format(m: &Mesh) -> Vec<(&'static str, Vec<u8>)> {
    vec![
        ("sample.obj", obj(m)),
        ("sample.off", off(m)),
        ("sample_ascii.ply", ply_ascii(m)),
        ("sample_binary.ply", ply_binary(m)),
        ("sample_ascii.stl", stl_ascii(m)),
        ("sample_binary.stl", stl_binary(m, m.triangles.len() as u32)),
        ("sample_wrong_count.stl", stl_binary(m, 0)),
        ("sample.glb", glb(m)),
        ("sample_embedded.gltf", gltf_embedded(m)),
        ("sample.off.gz", gzip(&off(m))),
        ("sample.stl.gz", gzip(&stl_binary(m, 7))),
        ("sample.glb.gz", gzip(&glb(m))),
    ]
}
