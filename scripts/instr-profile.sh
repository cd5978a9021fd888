#!/usr/bin/env bash
# Instructions per ray, on a machine without hardware counters: one ray set traced by one CPU
# method under valgrind's callgrind (an instruction-level simulator, with its model of a branch
# predictor), counted only inside the harness's `counted` function. Prints per ray the
# instructions and simulated mispredicted branches, the source lines the instructions come from,
# and, where `llvm-mca` is installed, its estimate of the cycles per ray of the instructions every
# ray runs (those executed at least 0.9 times a ray, in address order: a straight path, right
# where every ray takes the same one, as shadow rays stopped by one big occluder do).
#
#   scripts/instr-profile.sh SCENE [VIEW=inside] [METHOD=bvh8] [SET=shadow] [TIMES=4]
#
# Environment: AB_SIZE=WxH (camera rays, default 384x288), AB_SHUFFLE=1 and AB_SORTED=1 (as
# scripts/ab-cpu.sh takes them), MCA_CPU (llvm-mca's -mcpu, default znver3). The rays and the
# tree are scripts/ab-cpu.sh's (same harness, one thread; the tree is the SAH builder's). Under
# callgrind a trace runs about 50 times slower than natively.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 1 ] || { sed -n 2,16p "$0"; exit 2; }
command -v valgrind >/dev/null || { echo "instr-profile: needs valgrind (apt-get install valgrind)" >&2; exit 2; }
scene=$1 view=${2:-inside} method=${3:-bvh8} set=${4:-shadow} times=${5:-4}
out=$(mktemp /tmp/raytrail-callgrind.XXXXXX)
err=$(mktemp /tmp/raytrail-callgrind-log.XXXXXX)
trap 'rm -f "$out" "$err"' EXIT
# Costs are zeroed on entering the harness's `counted`, so only its traces are counted (the rays'
# making and the warm-up trace before it are not). The build and valgrind's own lines go to $err,
# shown only if the run fails.
log=$(AB_COUNT=$times AB_FRESH=0 \
  AB_RUNNER="valgrind --tool=callgrind --dump-instr=yes --branch-sim=yes --zero-before=*counted* --callgrind-out-file=$out" \
  "$root/scripts/ab-cpu.sh" HEAD "$scene" "$view" "$method" 1 "$set" 2>"$err") || { cat "$err" >&2; exit 1; }
echo "$log" | grep "AB_COUNT" || { echo "instr-profile: the harness traced no set named $set" >&2; exit 2; }
rays=$(echo "$log" | grep "AB_COUNT" | awk '{print $2}')
python3 "$root/scripts/instr_profile.py" "$out" "$root/target/release/raytrail-ab" $((rays * times)) "${MCA_CPU:-znver3}"
