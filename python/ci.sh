#!/usr/bin/env bash
# The Python module `ktree`: installs it with `pip install ./python` into a fresh virtual environment and runs
# its pytest suite (python/tests/) against numpy, scipy and scikit-image references, the command-line tool's
# JSON, and trimesh's and VTK's readings of the meshes and VTK files written, after checking the type stubs
# with mypy's stubtest. Exits non-zero on any failure, including a run that collected no test. A test whose
# tool is missing is skipped (the reasons are listed at the end), or fails when KTREE_REQUIRE_TOOLS is set to
# anything but empty or 0, as `.ci/run` sets it.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
venv="$root/target/python-venv"
python=${PYTHON:-python3}

# A virtual environment; Debian's python3 needs python3-venv for it (PyO3 itself needs no C headers).
rm -rf "$venv"
if ! "$python" -m venv "$venv" >/dev/null 2>&1; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-venv python3-dev >/dev/null
  fi
  rm -rf "$venv"
  "$python" -m venv "$venv"
fi
export PATH="$venv/bin:$PATH" # maturin, for the build without isolation below
pip=("$venv/bin/python" -m pip)
"${pip[@]}" install --quiet --upgrade pip
"${pip[@]}" install --quiet maturin numpy pytest mypy
# The references the tests check against (pinned: the tests rely on their definitions and checks): scipy
# and scikit-image for shape operations, trimesh and VTK for the meshes and VTK files written.
"${pip[@]}" install --quiet scipy==1.17.1 scikit-image==0.26.0 trimesh==5.2.0 vtk==9.7.2
# The module (a release build of the extension, in the workspace's target folder).
"${pip[@]}" install --no-build-isolation ./python

# The tests compare with the command-line tool's JSON.
cargo build --quiet -p ktree-cli
export KTREE_BIN="${CARGO_TARGET_DIR:-$root/target}/debug/ktree"

# The installed type stubs against the installed module.
"$venv/bin/python" -m mypy.stubtest ktree --allowlist python/stubtest-allowlist.txt
status=0
(cd python && "$venv/bin/python" -m pytest -q -rs -p no:cacheprovider tests) || status=$?
if [ "$status" -eq 5 ]; then
  echo "python/ci.sh: pytest collected no test" >&2
  exit 1
fi
exit "$status"
