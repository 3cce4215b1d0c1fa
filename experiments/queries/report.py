"""Writes results/performance/queries.md: ktree's queries and their peers side by side (run by
experiments/queries.sh, which builds the programs this runs).

usage: python report.py PERF PEERS OUT

PERF is ktree's perf example, PEERS the C++ program of experiments/queries/peers.cpp; scipy is imported
by experiments/queries/edt.py, run with this interpreter. ROUNDS (default 3) rounds run every program of a
question once each, in turn, each process timing one run (REPEATS=1); the table keeps the best over the
rounds.
"""

import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from report_common import cpu, dpkg_version, goal, run  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
INPUTS = ROOT / "target" / "query-inputs"
POINTS, RAYS, NEAREST, RAY_HEAD = 10_000_000, 1_000_000, 1_000_000, 100_000
OBJECTS = ["ball-10", "armadillo-10"]
EDT_OBJECTS = ["ball-9", "armadillo-9"]



def questions(perf: str, peers: str) -> list[tuple[str, str, str, int, list[tuple[str, list[str]]]]]:
    """(object, question, threads, queries, [(tool, command)]): the first tool is ktree's reference."""
    out = []
    for obj in OBJECTS:
        d = INPUTS / obj
        ktree = lambda case: [perf, "--child", "queries", f"{obj}:{case}"]  # noqa: E731
        for kind, case, file in [("random", "random", "random.bin"), ("random walk", "coherent", "walk.bin")]:
            for threads, flag in [("1", "1"), ("all", "0")]:
                suffix = "1" if threads == "1" else "all"
                tools = [("ktree `contains_many`", ktree(f"batch-{case}-{suffix}"))]
                if threads == "1":
                    tools.append(("ktree `PointCursor`", ktree(f"cursor-{case}")))
                tools += [
                    ("OpenVDB `ValueAccessor`", [peers, "vdb-accessor", str(d / "tree.vdb"), str(d / file), flag]),
                    ("OpenVDB `tree.getValue`", [peers, "vdb-getvalue", str(d / "tree.vdb"), str(d / file), flag]),
                    ("OctoMap `search`", [peers, "octomap-search", str(d / "tree.bt"), str(d / file), flag]),
                ]
                out.append((obj, f"points, {kind}", threads, POINTS, tools))
        for threads, flag, suffix in [("1", "1", "1"), ("all", "0", "all")]:
            tools = [
                ("ktree `cast_rays`", ktree(f"rays-{suffix}")),
                ("OpenVDB `VolumeRayIntersector`", [peers, "vdb-rays", str(d / "tree.vdb"), str(d / "rays.bin"), flag]),
                (
                    f"OctoMap `castRay` (first {RAY_HEAD})",
                    [peers, "octomap-rays", str(d / "tree.bt"), str(d / "rays.bin"), flag, str(RAY_HEAD)],
                ),
            ]
            out.append((obj, "rays", threads, RAYS, tools))
        for threads, suffix in [("1", "1"), ("all", "all")]:
            out.append((obj, "nearest", threads, NEAREST, [("ktree `nearest_many`", ktree(f"nearest-{suffix}"))]))
    for obj in EDT_OBJECTS:
        d = INPUTS / obj
        edt = [sys.executable, str(HERE / "edt.py"), str(d)]
        for threads, suffix in [("1", "1"), ("all", "all")]:
            tools = [("ktree `nearest_many`", [perf, "--child", "queries", f"{obj}:nearest-{suffix}"])]
            if threads == "1":
                tools.append(("scipy `distance_transform_edt` (whole grid)", edt))
            out.append((obj, "nearest", threads, NEAREST, tools))
    return out


def agreement(tool: str, ref: dict[str, str], got: dict[str, str]) -> str:
    """Whether a peer's answers agree with ktree's: the counts (and checksums) compared."""
    if tool.startswith("ktree"):
        return "reference" if "PointCursor" not in tool else ("yes" if got["answers"] == ref["answers"] else "NO")
    if "castRay" in tool:
        pairs = [("hits", ref["hits_head"], got["answers"]), ("voxel sum", ref["voxel_sum_head"], got["voxel_sum"])]
    elif "Intersector" in tool:
        pairs = [("hits", ref["answers"], got["answers"]), ("voxel sum", ref["voxel_sum"], got["voxel_sum"])]
    elif "scipy" in tool:
        pairs = [("at 0", ref["answers"], got["answers"]), ("Σ squared", ref["sum_squared"], got["sum_squared"])]
    else:
        pairs = [("inside", ref["answers"], got["answers"])]
    parts = []
    for name, a, b in pairs:
        if a == b:
            parts.append(f"{name} equal")
        else:
            parts.append(f"{name} {b} vs ktree {a} ({int(b) - int(a):+d})")
    if all(a == b for _, a, b in pairs):
        verdict = "yes: "
    elif pairs[0][1] == pairs[0][2]:
        verdict = "counts agree, some voxels differ: "
    else:
        verdict = "NO: "
    return verdict + ", ".join(parts)


def main() -> None:
    perf, peers, out = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    os.environ["REPEATS"] = "1"
    rounds = int(os.environ.get("ROUNDS", "3"))
    load = open("/proc/loadavg").read().split()[:3]
    voxels = {}
    for obj in OBJECTS + EDT_OBJECTS:
        voxels[obj] = run([perf, "--child", "queries", f"{obj}:write-inputs:{INPUTS / obj}"])["voxels"]
        print(f"inputs of {obj} written", file=sys.stderr)
    qs = questions(perf, peers)
    best: dict[tuple[int, int], tuple[float, dict[str, str]]] = {}
    for r in range(rounds):
        for qi, (obj, question, threads, _, tools) in enumerate(qs):
            for ti, (tool, command) in enumerate(tools):
                got = run(command)
                seconds = float(got["seconds"])
                if (qi, ti) not in best or seconds < best[(qi, ti)][0]:
                    best[(qi, ti)] = (seconds, got)
            print(f"round {r + 1}: {obj} {question} {threads} done", file=sys.stderr)
    load_end = open("/proc/loadavg").read().split()[:3]

    lines = []
    w = lines.append
    w("# Queries: points, rays, nearest voxels — ktree and its peers side by side")
    w("")
    w(
        "Regenerate with `experiments/queries.sh` (builds ktree's `perf` example and "
        "`experiments/queries/peers.cpp` with `g++` against Debian's libopenvdb-dev and liboctomap-dev, and "
        "runs scipy in a virtual environment in `target/`). Objects: the voxels whose centres lie in the ball "
        "of radius U/2 centred in the universe, and `data/meshes/armadillo.obj` fitted to the universe and "
        "voxelized, at L = 10 (and L = 9 for the comparison with scipy). The peers answer on the *same voxels*: "
        "ktree writes them as `tree.vdb` (a BoolGrid, index = ktree voxel) and `tree.bt` (OctoMap, key = voxel "
        "+ 32768, resolution 1, so metric coordinates are ktree's continuous ones) and the same query arrays "
        "(`perf --child queries OBJECT:write-inputs:DIR`): 10^7 random points uniform in the universe, 10^7 "
        "points of a random walk of unit steps, 10^6 rays from uniform origins in uniform directions of the "
        "cube [-1, 1]^3, 10^6 random points for nearest voxels."
    )
    w("")
    w(
        "Tools. **ktree**: `contains_many` (batch: a table of the top levels, then Morton-ordered runs), `PointCursor` (one point after the "
        "other, cached path), `cast_rays`, `nearest_many`. **OpenVDB** (libopenvdb-dev "
        f"{dpkg_version('libopenvdb-dev')}): `getValue` through a `ValueAccessor` (cached, one per thread) and "
        "through the tree (no cache); rays: `tools::VolumeRayIntersector` on the BoolGrid, marching the leaf "
        "and tile intervals the ray crosses front to back, with a voxel `math::DDA` inside each interval to the "
        "first active voxel — chosen over `LevelSetRayIntersector` because it answers the same question on the "
        "same voxels (the first full voxel entered), where a level set's zero crossing would be an "
        "interpolated surface point of a different object. **OctoMap** (liboctomap-dev "
        f"{dpkg_version('liboctomap-dev')}): `OcTree::search` by key; `OcTree::castRay` (unknown cells as "
        "free, up to where the ray leaves the universe) on the first "
        f"{RAY_HEAD} rays only — it steps voxel by voxel at the finest level, too slow for 10^6 rays in every "
        "round; per-ray times are comparable. **scipy** (the version pinned in `experiments/queries.sh`): "
        "`ndimage.distance_transform_edt` of the dense L = 9 grid's empty voxels, the whole grid (one thread: "
        "scipy does not thread it), against ktree's 10^6 nearest voxels at L = 9."
    )
    w("")
    w(
        f"Times: the best of {rounds} rounds; in each round every program of a question runs once, in turn, in "
        "a fresh process timing one run, loading or building the map and reading or making the queries not "
        "timed. \"answers\": points inside, rays that "
        "hit, points at distance 0. \"agrees\": the peer's counts (for rays also the sum of the coordinates of "
        "the voxels hit; for scipy the sum of the squared distances at the 10^6 points) against ktree's. "
        "OctoMap casts in single precision (`point3d` is `float`), so a ray passing within rounding of a voxel's "
        "edge or corner may enter a neighbour first: its hits can agree while a few voxels differ."
    )
    w("")
    w(
        f"Machine: {cpu()}, {os.cpu_count()} cores, shared with other builds: load average "
        f"{' '.join(load)} at the start, {' '.join(load_end)} at the end."
    )
    w("")
    w("| object | question | threads | tool | queries | best time (s) | ns / query | answers | agrees |")
    w("|---|---|---|---|---:|---:|---:|---:|---|")
    figures: dict[tuple[str, str, str, str], float] = {}
    for qi, (obj, question, threads, n, tools) in enumerate(qs):
        ref = best[(qi, 0)][1]
        for ti, (tool, _) in enumerate(tools):
            seconds, got = best[(qi, ti)]
            count = RAY_HEAD if "castRay" in tool else n
            per = seconds * 1e9 / count
            figures[(obj, question, threads, tool)] = per
            answers = got["answers"]
            # scipy answers the whole grid, not the queries: its time is not per query.
            shown = ("whole grid", "—") if "scipy" in tool else (str(count), f"{per:.1f}")
            w(
                f"| {obj} | {question} | {threads} | {tool} | {shown[0]} | {seconds:.3f} | {shown[1]} | {answers} | "
                f"{agreement(tool, ref, got)} |"
            )
    w("")
    w("Goals, per object:")
    w("")
    for obj in OBJECTS:
        f = lambda q, t, tool: figures[(obj, q, t, tool)]  # noqa: E731
        acc = "OpenVDB `ValueAccessor`"
        batch = f("points, random", "1", "ktree `contains_many`")
        vdb = f("points, random", "1", acc)
        w(f"- {obj}: " + goal("batch random points faster than OpenVDB's cached accessor, one thread", batch, vdb, 1.0))
        coherent = min(f("points, random walk", "1", "ktree `contains_many`"), f("points, random walk", "1", "ktree `PointCursor`"))
        vdb_c = f("points, random walk", "1", acc)
        w(f"- {obj}: " + goal("coherent points (best ktree form) within 1.5× of OpenVDB's accessor, one thread", coherent, vdb_c, 1.5))
        rays = f("rays", "1", "ktree `cast_rays`")
        w(f"- {obj}: " + goal("ray casts faster than OpenVDB's intersector, one thread", rays, f("rays", "1", "OpenVDB `VolumeRayIntersector`"), 1.0))
        octo = f("rays", "1", f"OctoMap `castRay` (first {RAY_HEAD})")
        w(f"- {obj}: " + goal("ray casts at least 10× faster than OctoMap's castRay, one thread (10 × ktree's ns against OctoMap's)", rays * 10, octo, 1.0))
    for obj in EDT_OBJECTS:
        # Whole runs, in seconds.
        k = figures[(obj, "nearest", "1", "ktree `nearest_many`")] * NEAREST / 1e9
        ka = figures[(obj, "nearest", "all", "ktree `nearest_many`")] * NEAREST / 1e9
        s = figures[(obj, "nearest", "1", "scipy `distance_transform_edt` (whole grid)")] * NEAREST / 1e9
        w(
            f"- {obj}: "
            + goal("10^6 distances (one thread) faster than scipy's whole-grid transform, in s", k, s, 1.0, 2)
            + f" All threads: {ka:.2f} s."
        )
    w("")
    w(
        "Why. Random points: each query reads a path of ~L nodes that is not in cache, in ktree a rank over "
        "2-bit node states at every level (no pointers), in OpenVDB three fixed levels of pointer nodes. "
        "ktree's batch first reads the tree's top levels into a table of their cells (2^18 at most, a byte "
        "each: depth 6 of an octree), as OpenVDB keeps a root table, and answers every point in an empty or "
        "full cell of that table by one read; the rest, in each run of 16 384 points, it orders by Morton key "
        "(a radix sort) so that neighbouring queries share the top of their paths. Coherent points: a random walk stays in a few leaves, so both "
        "answer most points from the cached path. Rays: ktree walks the tree front to back, an empty cell of "
        "any size costing one step; OpenVDB's intersector marches leaf-sized intervals, then voxels within "
        "them; OctoMap's `castRay` steps voxel by voxel at the finest level and searches each from the root. "
        "Distances: scipy computes every voxel of the 512³ grid; ktree only the 10^6 asked, each an exact "
        "branch and bound over the tree, started from the previous answer in Morton order."
    )
    w("")
    out.write_text("\n".join(lines) + "\n")





if __name__ == "__main__":
    main()
