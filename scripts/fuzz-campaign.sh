#!/usr/bin/env bash
# A fuzzing campaign over every target of fuzz/: each run for SECONDS (default 3600) with
# libFuzzer, then its corpus minimized (`cargo fuzz cmin`), so that fuzz/corpus/ keeps only inputs
# that add coverage. On stable Rust through RUSTC_BOOTSTRAP=1 and without a sanitizer (a machine
# with a nightly toolchain may drop both). Prints each target's runs and whether it crashed; a
# crash input is left in the target's artifacts folder under fuzz/ (cargo fuzz's).
#
#   scripts/fuzz-campaign.sh [SECONDS] [TARGET...]
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
for t in "${targets[@]}"; do
  log=$(mktemp)
  status=0
  cargo fuzz run "$t" -s none -- -max_total_time="$seconds" >"$log" 2>&1 || status=$?
  runs=$(grep -oE '^Done [0-9]+ runs in [0-9]+ second' "$log" | tail -1 || true)
  echo "$t: ${runs:-no summary} (exit $status)"
  if [ "$status" != 0 ]; then tail -30 "$log"; fi
  cargo fuzz cmin "$t" -s none >/dev/null 2>&1 || echo "$t: cmin failed"
  rm -f "$log"
done
