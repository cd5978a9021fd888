#!/usr/bin/env bash
# CI for the Python package, on a machine with only Rust and Python: a fresh virtual environment,
# the test dependencies from PyPI, `pip install ./python` (a release build of the abi3 wheel),
# the import check, then pytest on python/tests. Any failure fails the script, and so does
# pytest collecting no tests (its exit status 5).
#
#   python/ci.sh            # from anywhere; PYTHON=python3.12 python/ci.sh for another interpreter
#
# The venv lives in python/target/ci-venv (ignored), reused when present (CI_FRESH=1: remade).
set -euo pipefail
cd "$(dirname "$0")/.."
PYTHON=${PYTHON:-python3}
VENV=${VENV:-python/target/ci-venv}
case "$VENV" in /*) ;; *) VENV="$PWD/$VENV" ;; esac   # absolute: the import check runs from /

step() { echo; echo "== $* ($(date +%T))"; }

step "a virtual environment ($VENV) for $($PYTHON --version)"
if [ "${CI_FRESH:-0}" = 1 ]; then rm -rf "$VENV"; fi
[ -x "$VENV/bin/python" ] || "$PYTHON" -m venv "$VENV"
PY="$VENV/bin/python"
"$PY" -m pip install --quiet --upgrade pip

step "test dependencies from PyPI"
# rtree: trimesh's own ray_triangle (the reference the tests compare with) needs it.
"$PY" -m pip install --quiet maturin numpy pytest trimesh rtree embreex "dask[distributed]"
"$PY" -m pip list 2>/dev/null | grep -iE '^(maturin|numpy|pytest|trimesh|rtree|embreex|dask|distributed) '

step "pip install ./python (maturin, release build, abi3 wheel)"
# --no-deps: its one dependency, numpy, is installed above; --force-reinstall: a rerun replaces
# the wheel of the last run with one built from the tree as it is now.
# The test wheel carries the conformance crate's exact reference (feature exact-reference), which
# judges the disagreeing rays in tests/test_trimesh.py; a user's `pip install ./python` lacks it.
MATURIN_PEP517_ARGS="--features exact-reference" "$PY" -m pip install --force-reinstall --no-deps ./python

step "import"
# Outside the repository, so that the installed wheel is imported, not python/raytrail.
(cd / && "$PY" -c "import raytrail, raytrail.trimesh, raytrail.dask; print('raytrail', raytrail.__version__, 'from', raytrail.__file__)")

step "pytest python/tests"
# embreex installed above: a missing or broken one fails its tests instead of skipping them.
export RAYTRAIL_REQUIRE_EMBREEX=1 RAYTRAIL_REQUIRE_EXACT=1
set +e
"$PY" -m pytest python/tests -q -rs -p no:cacheprovider
status=$?
set -e
if [ "$status" = 5 ]; then
  echo "FAILED: pytest collected no tests"
  exit 1
fi
exit "$status"
