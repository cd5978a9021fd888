#!/usr/bin/env bash
# A new user's crate, CPU only, triangles from memory: checks that it builds neither wgpu nor the
# conformance suite nor any mesh loader, traces a ray in three statements, and reports the number
# of crates it builds and its clean build time.
#
# Usage: scripts/user-crate.sh [--features LIST]   (default: cpu, with default-features = false)
# The crate is made in a temporary folder with its own target folder, so the build is clean.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
features=${2:-cpu}
[ "${1:-}" = "--features" ] || features=cpu
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/src"
cat > "$dir/Cargo.toml" <<TOML
[package]
name = "raytrail-user"
version = "0.1.0"
edition = "2021"
publish = false

[dependencies]
raytrail = { path = "$repo", default-features = false, features = [$(printf '"%s",' ${features//,/ } | sed 's/,$//')] }

[workspace]
TOML
cat > "$dir/src/main.rs" <<'RS'
use raytrail::{Ray, Tracer, Vec3};

fn main() -> Result<(), raytrail::Error> {
    let tracer = Tracer::new(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]])?;
    let ray = Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::new(0.0, 0.0, -1.0), 0.0, f32::INFINITY);
    let hit = tracer.intersect_one(&ray)?;
    println!("{hit:?}");
    assert_eq!(hit.map(|h| (h.prim, h.t)), Some((0, 1.0)));
    Ok(())
}
RS
cd "$dir"
cp "$repo/Cargo.lock" . 2>/dev/null || true
tree=$(cargo tree --edges normal,build --prefix none --format '{p}' | sort -u)
crates=$(echo "$tree" | awk '{print $1}' | sort -u | wc -l)
for banned in wgpu naga raytrail-conformance raytrail-wgpu raytrail-mesh tobj gltf; do
    if echo "$tree" | awk '{print $1}' | grep -qx "$banned"; then
        echo "FAIL: a CPU-only user crate builds $banned"; exit 1
    fi
done
echo "the user crate (features: $features) depends on $crates crates; none of wgpu, naga, the conformance suite or a mesh loader"
start=$(date +%s)
cargo build --quiet
echo "clean build: $(( $(date +%s) - start )) s on $(nproc) cores"
cargo run --quiet
