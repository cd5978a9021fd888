#!/usr/bin/env bash
# The GPU checks of a session with a lent GPU machine, prepared here and run there in one call.
#
#   scripts/gpu-check.sh prepare    # here: build, strip and gather into dev-carry/ (about 53 MB)
#   scripts/gpu-check.sh run [quick] [kitchen,dragon,sponza]
#                                   # there: the wgpu conformance suites on the GPU, then the bench
#
# `prepare` builds the CLI and the two wgpu conformance suites (on the grid, and on persistent
# threads) in release mode, strips them into dev-carry/ and copies the scenes there (from
# $RAYTRAIL_SCENES, else ../shared/scenes). The machine there has no Vulkan loader: put its
# Debian packages in .gl/ (libvulkan1 and the libglvnd set); `run` unpacks them. Carry `.gl` and
# `dev-carry` with the call (with the repository, under the device tool's 64 MiB).
#
# `run` writes each suite's log and, per scene, SCENE.txt and SCENE.json under $OUT (else
# /tmp/gpu-out). `quick` shrinks everything for a dry run on lavapipe; SKIP_CONF=1 skips the
# suites. On an H100 the suite and the three scenes took about 4 minutes (BENCHMARKS.md, "On an
# NVIDIA H100 (2026-11-27)"); the persistent-threads suite has not run there yet.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
carry=$root/dev-carry
case "${1:-}" in
prepare)
    set -e
    cd "$root"
    cargo build --release -p raytrail-cli
    mkdir -p "$carry/scenes"
    strip -o "$carry/raytrail" target/release/raytrail
    for suite in conformance conformance_persistent; do
        test=$(cargo test --release -p raytrail-wgpu --test $suite --no-run --message-format=json 2>/dev/null |
            sed -n 's/.*"executable":"\([^"]*\)".*/\1/p' | tail -1)
        [ -n "$test" ] || { echo "the $suite test binary was not built" >&2; exit 1; }
        strip -o "$carry/$suite" "$test"
    done
    scenes=${RAYTRAIL_SCENES:-$root/../shared/scenes}
    cp "$scenes"/* "$carry/scenes/" && chmod -R u+w "$carry/scenes"
    du -sh "$carry"
    ;;
run)
    quick=""; scenes="kitchen,dragon,sponza"
    for a in "${@:2}"; do if [ "$a" = quick ]; then quick=1; else scenes=$a; fi; done
    out=${OUT:-/tmp/gpu-out}; mkdir -p "$out"
    cd "$root"
    if [ -z "$quick" ] && [ -d .gl ]; then
        for f in .gl/*.deb; do dpkg -x "$f" /; done
        ldconfig
    fi
    export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp} RAYTRAIL_SCENES=$carry/scenes
    nvidia-smi --query-gpu=name,clocks.sm,clocks.max.sm,temperature.gpu --format=csv 2>/dev/null
    if [ -n "$quick" ]; then size="-W 64 -H 48"; warm=0.05; passes=1; threads=2
    else size="-W 1920 -H 1080"; warm=0.3; passes=5; threads=16; fi
    # The grid suite, then every method on persistent threads (together: both dispatches).
    for suite in conformance conformance_persistent; do
        [ -n "${SKIP_CONF:-}" ] && break
        echo "== $suite $(date +%T)"
        RAYTRAIL_REQUIRE_GPU=1 timeout 200 "$carry/$suite" --test-threads 4 >"$out/$suite.log" 2>&1
        echo "$suite rc=$?"
        grep -E "test result|FAILED|panicked" "$out/$suite.log" | tail -20
    done
    cd "$carry/scenes"
    for name in ${scenes//,/ }; do
        case $name in
        kitchen) file=kitchen.obj; rays=primary,shadow,diffuse,ao ;;
        dragon) file=dragon_vrip.ply.gz; rays=primary,ao ;;
        sponza) file=sponza.obj; rays=primary,ao ;;
        *) file=$name; rays=primary,ao ;;
        esac
        [ -n "$quick" ] && file=builtin
        echo "== bench $name $(date +%T)"
        timeout 150 "$carry/raytrail" bench --scene "$file" --view inside --rays "$rays" \
            --methods stack,bvh4,bvh4-hash,bvh8,bvh8-packet --peers none $size --ao-rays 1 \
            --passes $passes --gpu-warm-up $warm --threads $threads --gpu-dispatch grid,persistent \
            --gpu-workgroup 64 --json "$out/$name.json" >"$out/$name.txt" 2>&1
        echo "rc=$?"
        grep -E "^  gpu:" "$out/$name.txt" | tail -12
    done
    ;;
*)
    sed -n 2,17p "$0"
    exit 2
    ;;
esac
