#!/usr/bin/env bash
# A fuzzing campaign over every target of fuzz/: each fuzzed with libFuzzer until its process has
# used SECONDS of CPU time (default 3600: user plus system time, read from /proc, so a fuzzer that
# shares its core with other work, or is stopped for a while, still gets its full budget). On
# stable Rust through RUSTC_BOOTSTRAP=1 and without a sanitizer (a machine with a nightly toolchain
# may drop both). New inputs go to fuzz/target/campaign/TARGET, beside the committed seeds of
# fuzz/corpus/TARGET, which stay as they are; a crash input is left in the artifacts folder this
# script has libFuzzer write under fuzz/, in a folder named after the target.
# Prints one line a target: runs, CPU seconds, wall seconds and how it ended.
#
#   scripts/fuzz-campaign.sh [SECONDS] [TARGET...]
#   FUZZ_BUILD=-O scripts/fuzz-campaign.sh 3600 mesh_obj   # a release build (see fuzz/README.md)
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
seconds=${1:-3600}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  mapfile -t targets < <(sed -n 's/^name = "\(.*\)"$/\1/p' Cargo.toml | grep -v '^raytrail-fuzz$')
fi
command -v cargo-fuzz >/dev/null || { echo "cargo-fuzz is not installed: cargo install cargo-fuzz"; exit 1; }
export RUSTC_BOOTSTRAP=1
ticks=$(getconf CLK_TCK)
triple=$(rustc -vV | sed -n 's/^host: //p')

# CPU seconds used so far by process $1 and the threads it has (fields 14 and 15 of its stat).
cpu_seconds() {
  awk -v t="$ticks" '{ sub(/^.*\) /, ""); print int(($12 + $13) / t) }' "/proc/$1/stat" 2>/dev/null || echo -1
}

for t in "${targets[@]}"; do
  # shellcheck disable=SC2086 # FUZZ_BUILD is a list of cargo fuzz flags
  cargo fuzz build ${FUZZ_BUILD:-} "$t" -s none >/dev/null
  bin=target/$triple/release/$t
  work=target/campaign/$t
  mkdir -p "$work" "artifacts/$t"
  log=target/campaign/$t.log
  start=$(date +%s)
  # Crash inputs of earlier campaigns stay in the artifacts folder: only those newer than this
  # marker are this run's.
  marker=$work.started
  touch "$marker"
  "$bin" -print_final_stats=1 -artifact_prefix="artifacts/$t/" "$work" "corpus/$t" >"$log" 2>&1 &
  pid=$!
  used=0
  while kill -0 "$pid" 2>/dev/null; do
    used=$(cpu_seconds "$pid")
    if [ "$used" -ge "$seconds" ]; then
      kill -INT "$pid"
      break
    fi
    sleep 5
  done
  status=0
  wait "$pid" || status=$?
  # libFuzzer exits 72 on the interrupt this loop sends at the budget.
  ended="exit $status"
  if [ "$status" = 72 ] && [ "$used" -ge "$seconds" ]; then ended="stopped at the budget"; fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  crashed=$(find "artifacts/$t" -type f -newer "$marker" -printf '%f\n' | head -1)
  echo "$t: ${runs:-?} runs, ${used} CPU s, $(($(date +%s) - start)) wall s, ${ended}${crashed:+, crash input artifacts/$t/$crashed}"
  if [ -n "$crashed" ]; then tail -30 "$log"; fi
done
