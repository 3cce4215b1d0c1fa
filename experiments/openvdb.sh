#!/usr/bin/env bash
# ktree's partitioned build against OpenVDB on one thread, L = 7 … 11, and writes
# results/performance/openvdb.md. The object: the voxel-centre sphere of results/performance/scale.md.
# ktree: `perf --child scale cells-L-1` (quadric → rays slab by slab → subtrees → tree). OpenVDB:
# experiments/openvdb/sphere.cpp (the same sphere's runs filled into a BoolGrid and pruned; and OpenVDB's
# narrow-band level-set sphere). Best of 3 per run, the three programs alternating, 3 rounds. Then, at
# L = 7 and 8, each program as a whole process (exec to exit: ktree's CLI writing its .ktree, OpenVDB's
# program building once), best of 7 alternating.
#
# Needs Debian's libopenvdb-dev, libboost-dev and libtbb-dev (apt-get install) and a C++ compiler.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --example perf
cargo build --release -p ktree-cli
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
{
  echo
  echo "## As whole processes"
  echo
  echo "Wall time from starting the program to its exit, best of 7 runs, the three programs alternating:"
  echo "**ktree** is the command a user runs, \`ktree rays --solid ball --radius (U−1)/2 --level L --threads 1"
  echo "--out FILE.ktree\` (the build and writing the file); **OpenVDB** is the program above building once"
  echo "(\`openvdb::initialize\`, the build, no file written)."
  echo
  echo "| L | ktree s | OpenVDB fill s | OpenVDB level set s | fill / ktree | level set / ktree |"
  echo "|---:|---:|---:|---:|---:|---:|"
} >>"$out.tmp"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
for level in 7 8; do
  python3 - "$level" "$bin" target/release/ktree "$scratch/sphere.ktree" >>"$out.tmp" <<'PY'
import subprocess, sys, time
level, vdb, ktree, out = int(sys.argv[1]), *sys.argv[2:]
u = 1 << level
programs = {
    "ktree": [ktree, "rays", "--solid", "ball", "--radius", f"{u - 1}/2", "--level", str(level),
              "--threads", "1", "--out", out],
    "fill": [vdb, str(level), "fill", "1"],
    "levelset": [vdb, str(level), "levelset", "1"],
}
best = {name: float("inf") for name in programs}
for _ in range(7):
    for name, argv in programs.items():
        start = time.perf_counter()
        subprocess.run(argv, check=True, stdout=subprocess.DEVNULL)
        best[name] = min(best[name], time.perf_counter() - start)
k, f, l = best["ktree"], best["fill"], best["levelset"]
print(f"| {level} | {k:.4f} | {f:.4f} | {l:.4f} | {f / k:.1f}× | {l / k:.1f}× |")
PY
done
mv "$out.tmp" "$out"
echo "wrote $out"
