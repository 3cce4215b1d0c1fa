#!/usr/bin/env bash
# ktree's queries against OpenVDB, OctoMap and scipy on the same voxels and the same queries, and writes
# results/performance/queries.md (the whole file): points (random, random walk), rays and nearest voxels on
# the L = 10 ball and armadillo, one thread and all threads; nearest voxels at L = 9 against scipy's
# distance_transform_edt of the whole grid. See experiments/queries/report.py for what is timed and how.
#
# Needs a C++ compiler and Debian's libopenvdb-dev (with libboost-dev and libtbb-dev) and liboctomap-dev
# (installed here with apt-get when missing and running as root), python3 with venv, and the network once
# for scipy and numpy (pinned below) in target/query-venv. ROUNDS=N (default 3) sets the rounds.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! [ -e /usr/include/openvdb/openvdb.h ] || ! [ -e /usr/include/octomap/OcTree.h ] ||
  ! [ -e /usr/include/boost/version.hpp ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends g++ libopenvdb-dev \
      libboost-dev libtbb-dev liboctomap-dev python3-venv >/dev/null
  else
    echo "queries.sh: needs libopenvdb-dev, libboost-dev, libtbb-dev and liboctomap-dev" >&2
    exit 1
  fi
fi
cargo build --release --example perf
peers=target/query-peers
g++ -O2 -std=c++17 -o "$peers" experiments/queries/peers.cpp -lopenvdb -ltbb -loctomap -loctomath
venv=target/query-venv
if ! [ -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet numpy==2.4.2 scipy==1.17.1
"$venv/bin/python" experiments/queries/report.py target/release/examples/perf "$peers" \
  results/performance/queries.md.tmp
mv results/performance/queries.md.tmp results/performance/queries.md
echo "wrote results/performance/queries.md"
