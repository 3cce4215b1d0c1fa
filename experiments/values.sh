#!/usr/bin/env bash
# Trees with values against OpenVDB on one thread, and writes results/performance/values.md: building from
# a dense label volume (u32 → ktree uint32 / OpenVDB Int32Grid) and a dense float volume (f32 → float32 /
# FloatGrid), L = 8 and 9, and the values at 10^7 random points; memory of the structures and of the
# processes; bits a node per value type. The volume: the 3-D Shepp–Logan phantom
# (experiments/examples/values.rs). ktree: `KTree::from_dense_background` (straight from the array),
# `KTree::values_at`. OpenVDB: experiments/values/peers.cpp (`tools::copyFromDense` serial + `prune`, one
# ValueAccessor), given the array in its own default layout (ZYX) and as the file holds it (XYZ). Best of 3
# inside each process, the programs alternating over 3 rounds, best kept; ktree also on two threads. Answers
# checked equal (voxel counts, checksums of the values read). Then each label's closed surface of the L = 8 and 9
# labels and of many small labels (export::surface::value_boundary_mesh), timed from their trees written by
# `ktree voxelize --labels`.
#
# Needs Debian's libopenvdb-dev, libboost-dev and libtbb-dev and a C++ compiler; about 2 GB of scratch.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p ktree-experiments --example values
cargo build --release -p ktree-cli
target=${CARGO_TARGET_DIR:-target}
ktree_bin=$target/release/examples/values
ktree_cli=$target/release/ktree
peers=$target/values-peers
g++ -O2 -std=c++17 -o "$peers" experiments/values/peers.cpp -lopenvdb -ltbb -lImath-3_1
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
out=results/performance/values.md
openvdb_version=$(dpkg-query -W -f='${Version}' libopenvdb-dev 2>/dev/null || echo unknown)
load=$(cut -d' ' -f1-3 /proc/loadavg)
for level in 8 9; do "$ktree_bin" phantom "$level" "$scratch"; done
rows=$scratch/rows.txt
: >"$rows"
for level in 8 9; do
  for kind in labels density; do
    file=$scratch/$kind-$level.raw
    for round in 1 2 3; do
      {
        echo "program=ktree level=$level kind=$kind"
        RAYON_NUM_THREADS=1 /usr/bin/time -f "rss_kb=%M" "$ktree_bin" build "$kind" "$level" "$scratch" 3 2>&1
        echo "program=ktree-2 level=$level kind=$kind"
        RAYON_NUM_THREADS=2 /usr/bin/time -f "rss_kb=%M" "$ktree_bin" build "$kind" "$level" "$scratch" 3 2>&1
        for layout in zyx xyz; do
          echo "program=openvdb-$layout level=$level kind=$kind"
          /usr/bin/time -f "rss_kb=%M" "$peers" "$kind" "$level" "$file" "$layout" 3 2>&1
        done
      } >>"$rows"
    done
    echo "L = $level $kind done" >&2
  done
done
"$ktree_bin" bits 9 "$scratch" >"$scratch/bits.txt"
# The L = 9 labels as a file to voxelize: read slab by slab along z, never held whole.
echo '{"shape_xyz": [512, 512, 512], "dtype": "uint32", "endianness": "little", "file": "labels-9.raw"}' >"$scratch/labels-9.json"
streamed=$scratch/streamed.txt
: >"$streamed"
for round in 1 2 3; do
  start=$(date +%s.%N)
  RAYON_NUM_THREADS=1 /usr/bin/time -f "rss_kb=%M" "$ktree_cli" voxelize "$scratch/labels-9.json" --labels --dtype uint32 \
    --out "$scratch/labels-9.ktree" >/dev/null 2>>"$streamed"
  echo "secs=$(echo "$(date +%s.%N) - $start" | bc)" >>"$streamed"
done
echo "file_bytes=$(stat -c %s "$scratch/labels-9.raw")" >>"$streamed"
echo "tree_bytes=$(stat -c %s "$scratch/labels-9.ktree")" >>"$streamed"
# Each label's closed surface (export::surface::value_boundary_mesh) of the L = 8 and 9 labels' trees.
surfaces=$scratch/surfaces.txt
: >"$surfaces"
# Then many small labels: the Voronoi cells of a seed in each cube of 4 voxels at L = 8 (`values cells`).
"$ktree_bin" cells 8 4 "$scratch"
for volume in labels-8 labels-9 cells-8; do
  side=$((1 << ${volume##*-}))
  echo "{\"shape_xyz\": [$side, $side, $side], \"dtype\": \"uint32\", \"endianness\": \"little\", \"file\": \"$volume.raw\"}" >"$scratch/surface-$volume.json"
  "$ktree_cli" voxelize "$scratch/surface-$volume.json" --labels --dtype uint32 --out "$scratch/surface-$volume.ktree" >/dev/null
  for round in 1 2 3; do
    echo "volume=$volume" >>"$surfaces"
    RAYON_NUM_THREADS=1 /usr/bin/time -f "rss_kb=%M" "$ktree_bin" surfaces "$scratch/surface-$volume.ktree" 3 >>"$surfaces" 2>&1
  done
done
python3 - "$rows" "$scratch/bits.txt" "$streamed" "$surfaces" "$openvdb_version" "$load" "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')" "$(nproc)" >"$out.tmp" <<'PY'
import sys
rows_path, bits_path, streamed_path, surfaces_path, version, load, cpu, cores = sys.argv[1:]
runs = {}
current = None
for line in open(rows_path):
    line = line.strip()
    if line.startswith("program="):
        fields = dict(f.split("=") for f in line.split())
        current = {}
        runs.setdefault((fields["level"], fields["kind"], fields["program"]), []).append(current)
    elif "=" in line and current is not None:
        k, v = line.split("=", 1)
        current[k] = float(v)

def best(level, kind, program, key):
    return min(r[key] for r in runs[(level, kind, program)])

def one(level, kind, program, key):
    values = {r[key] for r in runs[(level, kind, program)]}
    assert len(values) == 1, (level, kind, program, key, values)
    return values.pop()

print("# Trees with values against OpenVDB: building from a dense volume, values at points, memory")
print()
print("Regenerate with `experiments/values.sh`. The volume: the 3-D Shepp–Logan head phantom at U³ voxels, U = 2^L (ten")
print("ellipsoids, the table of Kak & Slaney as extended to 3-D by Schabel's `phantom3d`, with the \"modified\" intensities")
print("and the rotations about z only: `experiments/examples/values.rs`), as **labels** (the last ellipsoid holding a voxel's")
print("centre, 1–10, 0 outside; stored as u32) and as a **density** (the sum of the intensities, float32, 0 outside). Both")
print("programs read the same raw file (x fastest) before the clock starts, and 0 is the background of both.")
print("**ktree**: `KTree::from_dense_background`, straight from the array (read once in its order a row of bricks of 16³")
print("voxels at a time, the rows 16 KiB ahead asked of memory (a hint into the outer caches) while one is read: a brick")
print("of one value a leaf, the voxels of each other brick copied out as they are read — from the first that differs from")
print("the brick's first — and its subtree built bottom up once the row is read; the cells of bricks settled from their")
print("bricks), one thread (and two beside: slabs of bricks read and the subtrees of cells of 2^18 voxels built on the")
print("rayon pool). **OpenVDB**")
print(f"(libopenvdb-dev {version}, `experiments/values/peers.cpp`): `tools::copyFromDense` (serial, tolerance 0) into an")
print("`Int32Grid` / `FloatGrid`, then `tools::prune` (tolerance 0), TBB limited to one thread; it is given the array in its")
print("default layout (ZYX, z fastest: transposed before the clock starts) and as the file holds it (`LayoutXYZ`); the faster")
print("is compared. Times: best of 3 runs inside a process, the programs alternating over 3 rounds, best kept.")
print("Memory: the structure (ktree `KTree::heap_bytes`, OpenVDB `Grid::memUsage`) and the peak resident memory of the")
print("whole process (which holds the dense input too, 4 bytes a voxel, and 10^7 points of 12 bytes; ktree's keeps its")
print("answers as well, an array of 10^7 optional values, where OpenVDB's program adds them up as it reads them).")
print("**Read once**: the time of a plain loop reading the array once, each voxel compared with the background (one")
print("thread, the same process as ktree's build): what touching every voxel costs when memory is read without asking for")
print("it ahead. ktree's build reads the same array in less time than this loop on its own (its prefetch hints), so this")
print("column is a reference, not a bound.")
print()
print(f"Machine: {cpu}, {cores} cores. Load average when started: {load}.")
print()
print("## Building")
print()
print("| volume | L | voxels with a value | ktree s | OpenVDB ZYX s | OpenVDB XYZ s | OpenVDB best / ktree | ktree 2 threads s | read once s | OpenVDB best / read once | ktree bytes | OpenVDB bytes | ktree / OpenVDB bytes | ktree peak MB | OpenVDB peak MB |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
query_rows = []
for level in ("8", "9"):
    for kind in ("labels", "density"):
        k = best(level, kind, "ktree", "seconds")
        z = best(level, kind, "openvdb-zyx", "seconds")
        x = best(level, kind, "openvdb-xyz", "seconds")
        k2 = best(level, kind, "ktree-2", "seconds")
        once = best(level, kind, "ktree", "read_once_seconds")
        voxels = one(level, kind, "ktree", "voxels")
        assert one(level, kind, "ktree-2", "voxels") == voxels, (level, kind)
        assert one(level, kind, "ktree-2", "heap_bytes") == one(level, kind, "ktree", "heap_bytes"), (level, kind)
        for p in ("openvdb-zyx", "openvdb-xyz"):
            assert one(level, kind, p, "active") == voxels, (level, kind, p)
        kb = one(level, kind, "ktree", "heap_bytes")
        vb = one(level, kind, "openvdb-zyx", "mem_bytes")
        kr = best(level, kind, "ktree", "rss_kb") / 1024
        vr = min(best(level, kind, "openvdb-zyx", "rss_kb"), best(level, kind, "openvdb-xyz", "rss_kb")) / 1024
        ks = one(level, kind, "ktree", "checksum")
        for p in ("openvdb-zyx", "openvdb-xyz"):
            vs = one(level, kind, p, "checksum")
            assert abs(ks - vs) <= 1e-6 * max(1.0, abs(ks)), (level, kind, p, ks, vs)
        print(f"| {kind} | {level} | {int(voxels)} | {k:.4f} | {z:.4f} | {x:.4f} | {min(z, x) / k:.1f}× | {k2:.4f} | {once:.4f} | {min(z, x) / once:.1f}× | {int(kb)} | {int(vb)} | {kb / vb:.3f} | {kr:.0f} | {vr:.0f} |")
        kq = best(level, kind, "ktree", "query_seconds")
        vq = min(best(level, kind, "openvdb-zyx", "query_seconds"), best(level, kind, "openvdb-xyz", "query_seconds"))
        query_rows.append(f"| {kind} | {level} | {kq:.4f} | {vq:.4f} | {kq / 1e7 * 1e9:.1f} | {vq / 1e7 * 1e9:.1f} | {vq / kq:.2f}× |")
print()
print("## Values at 10^7 random points")
print()
print("The same points (splitmix64, uniform in the universe) in the same order; ktree `KTree::values_at_into` (one thread: a")
print("table of the cells of the box the points span, 2^15 cells — here the universe's top levels —, then descents sixteen side")
print("by side; the answers written into one buffer kept over the repeats), OpenVDB one `ValueAccessor` (`getValue`, its cache")
print("of the last nodes; the values summed as they are read). The sums of the values read are checked equal.")
print()
print("| volume | L | ktree s | OpenVDB s | ktree ns a point | OpenVDB ns a point | OpenVDB / ktree |")
print("|---|---:|---:|---:|---:|---:|---:|")
for r in query_rows:
    print(r)
print()
print("## Bits a node per value type")
print()
print("The L = 9 phantom's labels stored as each type (the colours a palette of the labels), its density as float32, and the")
print("tree of its voxels without values. Bits a node = `heap_bytes` × 8 / nodes: the 2-bit codes, the rank indexes and the")
print("value column (the value's bits for each full node).")
print()
print("| type | nodes | full nodes | bytes | bits a node | bits a full node |")
print("|---|---:|---:|---:|---:|---:|")
for line in open(bits_path):
    _, name, nodes, full, heap = line.split()
    nodes, full, heap = int(nodes), int(full), int(heap)
    label = "none (the shape)" if name == "none" else name
    print(f"| {label} | {nodes} | {full} | {heap} | {heap * 8 / nodes:.2f} | {heap * 8 / full:.2f} |")
print()
print("## A label volume read slab by slab")
print()
print("`ktree voxelize labels-9.json --labels --dtype uint32 --out labels-9.ktree` (one thread) on the L = 9 phantom's labels")
print("as a raw file (512³ uint32, x fastest): the file is read slab by slab along z, at most 64 MiB of labels at once")
print("(`stacking::ValueSlabs::write_file`), each slab's cells of 2^s voxels a side built apart, their levels below the")
print("cells spilled to temporary files at once, and the file written level by level from the cells' roots and the spilled")
print("pieces, so the process holds one slab and the top levels, never the volume nor the whole tree. Best of 3 (the whole")
print("command: reading, building, writing).")
print()
streamed = {"secs": [], "rss_kb": []}
for line in open(streamed_path):
    k, v = line.strip().split("=", 1)
    streamed.setdefault(k, []).append(float(v))
print("| file MB | peak MB | peak / file | seconds | tree file MB |")
print("|---:|---:|---:|---:|---:|")
fb, rss = streamed["file_bytes"][0], min(streamed["rss_kb"]) * 1024
print(f"| {fb / 1e6:.0f} | {rss / 1e6:.0f} | {rss / fb:.2f} | {min(streamed['secs']):.2f} | {streamed['tree_bytes'][0] / 1e6:.1f} |")
print()
print("## Surfaces of the labels")
print()
print("`export::surface::value_boundary_mesh` of the phantom's labels, and of many small labels (`cells`: the Voronoi cells")
print("of a seed placed at random in each cube of 4 voxels, as an electron-microscopy over-segmentation; `values cells`),")
print("each tree read from the file `ktree voxelize --labels` wrote: each label's closed, outward surface, the label behind")
print("each triangle, its rectangles merged as far as one label (or nothing) stays behind each — the faces between two labels")
print("are in both labels' surfaces. One thread; best of 3 inside a process over 3 rounds; peak: the whole process (the tree,")
print("one run's surfaces). Unit faces: the labels' surface areas summed (`value_stats`), what a mesh of one square a voxel")
print("face would have, at two triangles a square.")
print()
print("| volume | L | labels | unit faces | triangles | triangles a unit face | vertices | faces once | seconds | peak MB |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
surface_runs = {}
for line in open(surfaces_path):
    k, v = line.strip().split("=", 1)
    if k == "volume":
        current = {}
        surface_runs.setdefault(v, []).append(current)
    else:
        current[k] = float(v)
for volume, rounds in surface_runs.items():
    name, level = volume.rsplit("-", 1)
    def same(key):
        values = {r[key] for r in rounds}
        assert len(values) == 1, (volume, key, values)
        return int(values.pop())
    secs = min(r["seconds"] for r in rounds)
    peak = min(r["rss_kb"] for r in rounds) * 1024
    unit, triangles = same("unit_faces"), same("triangles")
    print(f"| {'phantom' if name == 'labels' else 'cells'} | {level} | {same('labels')} | {unit} | {triangles} | {triangles / unit:.2f} | {same('vertices')} | {same('faces_once')} | {secs:.3f} | {peak / 1e6:.0f} |")
PY
mv "$out.tmp" "$out"
echo "wrote $out"
