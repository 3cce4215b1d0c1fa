#!/usr/bin/env bash
# Point queries through the Python module against the library and OpenVDB on the same voxels and points,
# and writes results/performance/python.md (the whole file): `Tree.contains` on the 10^7 random points of
# the L = 10 ball (int64 and uint32 arrays), the library's `contains_many` (the `perf` example's case of
# results/performance/queries.md) and OpenVDB's cached `ValueAccessor`, one thread each, interleaved round
# after round. See experiments/python/contains.py for what is timed and how.
#
# Needs what experiments/queries.sh needs for OpenVDB (g++, libopenvdb-dev, libboost-dev, libtbb-dev;
# liboctomap-dev for the peers' program), python3 with venv, and the network once for maturin and numpy in
# target/python-perf-venv. ROUNDS=N (default 7) sets the rounds.
set -euo pipefail
cd "$(dirname "$0")/.."
target=${CARGO_TARGET_DIR:-target}
if ! [ -e /usr/include/openvdb/openvdb.h ] || ! [ -e /usr/include/octomap/OcTree.h ]; then
  echo "python.sh: needs libopenvdb-dev, libboost-dev, libtbb-dev and liboctomap-dev (see queries.sh)" >&2
  exit 1
fi
cargo build --release --example perf
peers="$target/query-peers"
if ! [ -x "$peers" ] || [ experiments/queries/peers.cpp -nt "$peers" ]; then
  g++ -O2 -std=c++17 -o "$peers" experiments/queries/peers.cpp -lopenvdb -ltbb -loctomap -loctomath
fi
venv="$target/python-perf-venv"
if ! [ -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet maturin numpy==2.4.2
# The module as users install it: a release build of the extension.
PATH="$venv/bin:$PATH" "$venv/bin/python" -m pip install --quiet --no-build-isolation ./python
"$venv/bin/python" experiments/python/contains.py "$target/release/examples/perf" "$peers" \
  results/performance/python.md.tmp
mv results/performance/python.md.tmp results/performance/python.md
echo "wrote results/performance/python.md"
