#!/usr/bin/env bash
# Flash and RAM per method on the Cortex-M4F: builds the qemu program once with only the measuring
# scaffold (RAYTRAIL_QEMU_ONLY=none) and once per method with that method alone, runs each under
# qemu with instruction counting, and prints a table: the code the method adds over the scaffold,
# the read-only data (the validating loader keeps every table), instructions per ray and peak
# stack. Needs qemu-system-arm and the thumbv7em-none-eabihf target. Run from anywhere.
set -euo pipefail
cd "$(dirname "$0")/../.."
target=thumbv7em-none-eabihf
elf="${CARGO_TARGET_DIR:-target}/$target/release/raytrail-embedded-qemu"
run() {
  RAYTRAIL_QEMU_ONLY="$1" cargo build -q --release -p raytrail-embedded-qemu --target "$target"
  timeout 120 qemu-system-arm -M mps2-an386 -cpu cortex-m4 -display none -serial none -monitor none \
    -semihosting-config enable=on,target=native -icount shift=0 -kernel "$elf"
}
base=$(run none | awk '/^footprint/ {print $3}')
printf '%-16s %10s %12s %10s %11s %9s\n' method "text B" "method code" "rodata B" "insns/ray" "stack B"
printf '%-16s %10s %12s %10s %11s %9s\n' "(scaffold)" "$base" 0 - - -
for i in $(seq 0 13); do
  out=$(run "$i")
  text=$(awk '/^footprint/ {print $3}' <<<"$out")
  rodata=$(awk '/^footprint/ {print $5}' <<<"$out")
  read -r name insns stack < <(awk '/^only/ {print $2, $4, $6}' <<<"$out")
  printf '%-16s %10s %12s %10s %11s %9s\n' "$name" "$text" "$((text - base))" "$rodata" "$insns" "$stack"
done
# Leave the full program built, as a plain build would.
cargo build -q --release -p raytrail-embedded-qemu --target "$target"
