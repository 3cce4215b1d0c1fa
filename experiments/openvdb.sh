#!/usr/bin/env bash
# ktree's partitioned build against OpenVDB on one thread, L = 7 … 11, and writes
# results/performance/openvdb.md. The object: the voxel-centre sphere of results/performance/scale.md.
# ktree: `perf --child scale cells-L-1` (quadric → rays slab by slab → subtrees → tree). OpenVDB:
# experiments/openvdb/sphere.cpp (the same sphere's runs filled into a BoolGrid and pruned; and OpenVDB's
# narrow-band level-set sphere). Best of 3 per run, the three programs alternating, 3 rounds.
#
# Needs Debian's libopenvdb-dev, libboost-dev and libtbb-dev (apt-get install) and a C++ compiler.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --example perf
bin=target/openvdb-sphere
g++ -O2 -std=c++17 -o "$bin" experiments/openvdb/sphere.cpp -lopenvdb -ltbb
perf=target/release/examples/perf
value() { grep "^$1=" | cut -d= -f2; }
min() { python3 -c "import sys; print(min(float(x) for x in sys.argv[1:]))" "$@"; }
out=results/performance/openvdb.md
openvdb_version=$(dpkg-query -W -f='${Version}' libopenvdb-dev 2>/dev/null || echo unknown)
{
  echo "# ktree against OpenVDB: the voxel-centre sphere on one thread"
  echo
  echo "Regenerate with \`experiments/openvdb.sh\`. Object: the voxels whose centres lie in the sphere of centre U/2 and"
  echo "radius (U − 1)/2, U = 2^L. **ktree**: the partitioned build end to end from the sphere's quadric (rays made"
  echo "slab by slab, each cell's subtree built apart, levels joined), one thread. **OpenVDB fill** (libopenvdb-dev"
  echo "$openvdb_version, \`experiments/openvdb/sphere.cpp\`): the same sphere's runs along z made column by column from the"
  echo "same integer test, each run filled into a BoolGrid (\`sparseFill\` of its box), then \`prune\` — the same object,"
  echo "checked voxel for voxel by count. **OpenVDB level set**: \`createLevelSetSphere\` (half width 3, unthreaded), a"
  echo "narrow band around the surface rather than the solid, shown as OpenVDB's fastest sphere. Times: the best of 3"
  echo "runs inside one process, the three programs alternating over 3 rounds, best kept."
  echo
  echo "Machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), $(nproc) cores. Load average when started: $(cut -d' ' -f1-3 /proc/loadavg)."
  echo
  echo "| L | voxels | ktree s | OpenVDB fill s | OpenVDB level set s | fill / ktree | level set / ktree |"
  echo "|---:|---:|---:|---:|---:|---:|---:|"
} >"$out.tmp"
for level in 7 8 9 10 11; do
  k=(); f=(); l=()
  for round in 1 2 3; do
    r=$("$perf" --child scale "cells-$level-1")
    k+=("$(echo "$r" | value seconds)"); kv=$(echo "$r" | value voxels)
    r=$("$bin" "$level" fill 3)
    f+=("$(echo "$r" | value seconds)"); fv=$(echo "$r" | value voxels)
    r=$("$bin" "$level" levelset 3)
    l+=("$(echo "$r" | value seconds)")
  done
  if [ "$kv" != "$fv" ]; then
    echo "L = $level: ktree has $kv voxels, OpenVDB's fill $fv" >&2
    exit 1
  fi
  ks=$(min "${k[@]}"); fs=$(min "${f[@]}"); ls=$(min "${l[@]}")
  python3 - "$level" "$kv" "$ks" "$fs" "$ls" >>"$out.tmp" <<'PY'
import sys
level, voxels, k, f, l = sys.argv[1], sys.argv[2], *map(float, sys.argv[3:])
print(f"| {level} | {voxels} | {k:.4f} | {f:.4f} | {l:.4f} | {f / k:.1f}× | {l / k:.1f}× |")
PY
  echo "L = $level done" >&2
done
mv "$out.tmp" "$out"
echo "wrote $out"
