#!/usr/bin/env bash
# ktree's shape operations against OpenVDB and scipy on the same voxels, and writes
# results/performance/shape.md (the whole file): dilation and erosion by a ball, box and cross of radius 2,
# 8 and 32 of the L = 10 ball and armadillo against OpenVDB's dilateActiveValues / erodeActiveValues and
# its level-set offset; the ball dilation and the connected components at L = 8 and 9 against scipy's
# binary_dilation and label; the narrow band against OpenVDB's topologyToLevelSet; peak memory of every
# program. All on one thread. See experiments/shape/report.py for what is timed and how.
#
# Needs a C++ compiler and Debian's libopenvdb-dev (with libboost-dev and libtbb-dev; installed here with
# apt-get when missing and running as root), python3 with venv, and the network once for scipy and numpy
# (pinned below) in target/shape-venv. ROUNDS=N (default 3) sets the rounds.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! [ -e /usr/include/openvdb/openvdb.h ] || ! [ -e /usr/include/boost/version.hpp ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends g++ libopenvdb-dev \
      libboost-dev libtbb-dev python3-venv >/dev/null
  else
    echo "shape.sh: needs libopenvdb-dev, libboost-dev and libtbb-dev" >&2
    exit 1
  fi
fi
cargo build --release --example perf
peers=target/shape-peers
g++ -O2 -std=c++17 -o "$peers" experiments/shape/peers.cpp -lopenvdb -ltbb -lImath
venv=target/shape-venv
if ! [ -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet numpy==2.4.2 scipy==1.17.1
"$venv/bin/python" experiments/shape/report.py target/release/examples/perf "$peers" \
  results/performance/shape.md.tmp
mv results/performance/shape.md.tmp results/performance/shape.md
echo "wrote results/performance/shape.md"
