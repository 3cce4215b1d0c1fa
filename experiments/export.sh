#!/usr/bin/env bash
# ktree's mesh export against OpenVDB's volumeToMesh on the same voxels, and writes
# results/performance/export.md (the whole file): the balls at L = 6, 8, 10 and the armadillo at L = 8, 10.
# See experiments/export/report.py for what is timed and how.
#
# Needs a C++ compiler and Debian's libopenvdb-dev (with libboost-dev and libtbb-dev; installed here with
# apt-get when missing and running as root) and python3. ROUNDS=N (default 3) sets the rounds.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! [ -e /usr/include/openvdb/openvdb.h ] || ! [ -e /usr/include/boost/version.hpp ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends g++ libopenvdb-dev \
      libboost-dev libtbb-dev >/dev/null
  else
    echo "export.sh: needs libopenvdb-dev, libboost-dev and libtbb-dev" >&2
    exit 1
  fi
fi
cargo build --release --example perf
peers=target/export-peers
g++ -O2 -std=c++17 -o "$peers" experiments/export/peers.cpp -lopenvdb -ltbb
python3 experiments/export/report.py target/release/examples/perf "$peers" results/performance/export.md.tmp
mv results/performance/export.md.tmp results/performance/export.md
echo "wrote results/performance/export.md"
