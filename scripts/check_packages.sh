#!/usr/bin/env bash
# Checks that each library crate's package (`cargo package --list`) holds its README and license
# files, and that the shaders crate holds every WGSL file of shaders/: a crate published alone must
# carry what it needs.
set -euo pipefail
cd "$(dirname "$0")/.."
fail=0
for crate in raytrail raytrail-core raytrail-mesh raytrail-build raytrail-shaders raytrail-cpu raytrail-wgpu raytrail-conformance raytrail-cli; do
  list=$(cargo package --list --allow-dirty --offline -p "$crate" 2>/dev/null || cargo package --list --allow-dirty -p "$crate")
  for need in README.md LICENSE-MIT LICENSE-APACHE Cargo.toml; do
    if ! grep -qx "$need" <<<"$list"; then echo "MISSING: $crate's package lacks $need"; fail=1; fi
  done
  if [ "$crate" = raytrail-conformance ]; then
    for f in conformance/scenes/*; do
      if ! grep -qx "scenes/$(basename "$f")" <<<"$list"; then echo "MISSING: raytrail-conformance lacks scenes/$(basename "$f")"; fail=1; fi
    done
  fi
  if [ "$crate" = raytrail-shaders ]; then
    for f in shaders/*.wgsl; do
      if ! grep -qx "$(basename "$f")" <<<"$list"; then echo "MISSING: raytrail-shaders lacks $(basename "$f")"; fail=1; fi
    done
  fi
  echo "$crate: $(wc -l <<<"$list") files"
done
exit $fail
