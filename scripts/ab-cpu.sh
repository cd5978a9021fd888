#!/usr/bin/env bash
# In-process A/B of the CPU backend: the same rays traced by an older commit's raytrail-core and
# raytrail-cpu and by the working tree's, one thread, in interleaved rounds (the order alternating),
# so that the machine's drift and noise fall on both alike. Prints per ray set the median time of
# each, the speed ratio new/old, the per-round median of that ratio, the work per ray of each, and
# whether every hit is bit for bit the same.
#
#   scripts/ab-cpu.sh OLD_REV SCENE [VIEW=inside] [METHOD=bvh8] [ROUNDS=15] [SETS=primary,shadow,diffuse,ao]
#
# Environment: AB_SIZE=WxH (primary rays, default 384x288); AB_TILES=1 orders the camera rays in
# tiles of 8 x 8 pixels; AB_SHUFFLE=1 shuffles the shadow, diffuse and AO rays by a fixed seed;
# AB_SORTED=1 has both sides trace every set sorted (TraceOrder::Sorted; the old commit must have
# it); AB_NEW_METHOD=NAME makes the new side trace with another method (say
# bvh8-packet against the old side's bvh8); AB_TRAV, AB_MAXLEAF, AB_BLOCK, AB_BINS change the new
# side's SAH settings (to try a builder change without editing it); AB_FRESH=0 keeps one copy of each tree for all
# rounds (by default each round traces fresh copies, so that where the trees land in physical
# memory, which moved a set by up to 25% between runs, averages out). AB_COUNT=N traces each set
# N times with the new side alone, untimed, and AB_RUNNER prefixes the harness's command line:
# both for scripts/instr-profile.sh.
# The old commit is checked out in a temporary worktree with its two crates renamed, so both link
# into one binary.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 2 ] || { sed -n 2,21p "$0"; exit 2; }
rev=$1; shift
old=$(mktemp -d /tmp/raytrail-ab-old.XXXXXX)
trap 'git -C "$root" worktree remove --force "$old" >/dev/null 2>&1 || true' EXIT
git -C "$root" worktree add --quiet --detach "$old" "$rev"
sed -i 's/^name = "raytrail-core"/name = "raytrail-core-old"/' "$old/core/Cargo.toml"
sed -i 's/^name = "raytrail-cpu"/name = "raytrail-cpu-old"/' "$old/backends/cpu/Cargo.toml"
sed -i -E 's|^(raytrail-core = \{ path = "core",[^}]*)\}|\1, package = "raytrail-core-old" }|; s|^(raytrail-cpu = \{ path = "backends/cpu",[^}]*)\}|\1, package = "raytrail-cpu-old" }|' "$old/Cargo.toml"
harness=$(mktemp -d /tmp/raytrail-ab-harness.XXXXXX)
mkdir -p "$harness/src"
cp "$root/scripts/ab-cpu/main.rs" "$harness/src/"
cat > "$harness/Cargo.toml" <<TOML
[package]
name = "raytrail-ab"
version = "0.0.0"
edition = "2021"
publish = false

[dependencies]
rc = { path = "$root/core", package = "raytrail-core" }
rcpu = { path = "$root/backends/cpu", package = "raytrail-cpu" }
rmesh = { path = "$root/mesh", package = "raytrail-mesh" }
conf = { path = "$root/conformance", package = "raytrail-conformance" }
oc = { path = "$old/core", package = "raytrail-core-old" }
ocpu = { path = "$old/backends/cpu", package = "raytrail-cpu-old" }
glam = "0.34"

# As the workspace's release profile: line tables for profilers, the same code.
[profile.release]
debug = 1

[workspace]
TOML
CARGO_TARGET_DIR="$root/target" cargo build --release --quiet --manifest-path "$harness/Cargo.toml"
${AB_RUNNER:-} "$root/target/release/raytrail-ab" "$@"
