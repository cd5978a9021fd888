#!/usr/bin/env bash
# The GPU checks of a session with a lent GPU machine, prepared here and run there in one call.
#
#   [AB_OLD=REV] scripts/gpu-check.sh prepare
#                                   # here: build, strip, gzip and gather into dev-carry/ (~40 MB)
#   scripts/gpu-check.sh run [quick] [kitchen,dragon,sponza]
#                                   # there: the wgpu conformance suites on the GPU, then the bench
#
# `prepare` builds the working tree's CLI and its two wgpu conformance suites (on the grid, and on
# persistent threads) in release mode, strips and gzips them into dev-carry/ and copies the scenes
# there (from $RAYTRAIL_SCENES, else ../shared/scenes). With AB_OLD=REV it also builds the CLI of
# commit REV (in a temporary worktree), and `run` then benches both binaries on each scene, the old
# one first, so that a GPU change is timed side by side with what it replaces. The machine there
# has no Vulkan loader: put its Debian packages in .gl/ (libvulkan1 and the libglvnd set); `run`
# unpacks them. Carry `.gl` and `dev-carry` with the call (with the repository, under the device
# tool's 64 MiB).
#
# `run` writes each suite's log and, per scene, SCENE.txt and SCENE.json (SCENE-old.* for the old
# binary) under $OUT (else /tmp/gpu-out). `quick` shrinks everything for a dry run on lavapipe;
# SKIP_CONF=1 skips the suites, SUITES=conformance runs the grid suite alone (about 40 s on an
# H200, half of both); METHODS=a,b,... replaces the bench's methods. On an H100 the grid
# suite and the three scenes took about 4 minutes
# (`docs/notes/*-benchmarks-h100-suite.md`, "On an NVIDIA H100").
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
carry=$root/dev-carry
case "${1:-}" in
prepare)
    set -e
    cd "$root"
    cargo build --release -p raytrail-cli
    rm -rf "$carry" && mkdir -p "$carry/scenes"
    strip -o "$carry/raytrail" target/release/raytrail
    for suite in ${SUITES:-conformance conformance_persistent}; do
        test=$(cargo test --release -p raytrail-wgpu --test $suite --no-run --message-format=json 2>/dev/null |
            sed -n 's/.*"executable":"\([^"]*\)".*/\1/p' | tail -1)
        [ -n "$test" ] || { echo "the $suite test binary was not built" >&2; exit 1; }
        strip -o "$carry/$suite" "$test"
    done
    scenes=${RAYTRAIL_SCENES:-$root/../shared/scenes}
    cp "$scenes"/* "$carry/scenes/" && chmod -R u+w "$carry/scenes"
    if [ -n "${AB_OLD:-}" ]; then
        old=$(mktemp -d /tmp/raytrail-gpu-old.XXXXXX)
        trap 'git -C "$root" worktree remove --force "$old" >/dev/null 2>&1 || true' EXIT
        git worktree add --quiet --detach "$old" "$AB_OLD"
        (cd "$old" && CARGO_TARGET_DIR=$root/target/ab-old cargo build --release -p raytrail-cli)
        strip -o "$carry/raytrail-old" target/ab-old/release/raytrail
    fi
    gzip -9 "$carry"/raytrail* "$carry"/conformance*
    du -sh "$carry"
    ;;
run)
    quick=""; scenes="kitchen,dragon,sponza"
    for a in "${@:2}"; do if [ "$a" = quick ]; then quick=1; else scenes=$a; fi; done
    out=${OUT:-/tmp/gpu-out}; mkdir -p "$out"
    cd "$root"
    # Unpacked outside dev-carry, which must stay small enough to carry.
    bin=$(mktemp -d /tmp/raytrail-gpu-bin.XXXXXX)
    for z in "$carry"/*.gz; do
        [ -e "$z" ] || continue
        b=$bin/$(basename "${z%.gz}")
        gzip -dc "$z" >"$b" && chmod +x "$b"
    done
    if [ -z "$quick" ] && [ -d .gl ]; then
        for f in .gl/*.deb; do dpkg -x "$f" /; done
        ldconfig
    fi
    export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp} RAYTRAIL_SCENES=$carry/scenes
    nvidia-smi --query-gpu=name,clocks.sm,clocks.max.sm,temperature.gpu --format=csv 2>/dev/null
    if [ -n "$quick" ]; then size="-W 64 -H 48"; warm=0.05; passes=1; threads=2
    else size="-W 1920 -H 1080"; warm=0.3; passes=5; threads=16; fi
    # The grid suite, then every method on persistent threads (together: both dispatches).
    for suite in ${SUITES:-conformance conformance_persistent}; do
        [ -n "${SKIP_CONF:-}" ] && break
        echo "== $suite $(date +%T)"
        RAYTRAIL_REQUIRE_GPU=1 timeout 200 "$bin/$suite" --test-threads 4 >"$out/$suite.log" 2>&1
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
        sides=""; [ -x "$bin/raytrail-old" ] && sides="-old"
        for side in $sides ""; do
            echo "== bench $name$side $(date +%T)"
            timeout 150 "$bin/raytrail$side" bench --scene "$file" --view inside --rays "$rays" \
                --methods "${METHODS:-stack,bvh4,bvh4-hash,bvh8,bvh8-packet}" --peers none $size \
                --ao-rays 1 --passes $passes --gpu-warm-up $warm --threads $threads \
                --gpu-dispatch grid,persistent --gpu-workgroup 64 --json "$out/$name$side.json" \
                >"$out/$name$side.txt" 2>&1
            echo "rc=$?"
            grep -E "^  gpu:" "$out/$name$side.txt" | tail -12
        done
    done
    ;;
*)
    awk 'NR > 1 && !/^#/ { exit } NR > 1' "$0"
    exit 2
    ;;
esac
