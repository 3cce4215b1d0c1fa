"""Writes results/performance/export.md: ktree's boundary mesh against OpenVDB's volumeToMesh on the same
voxels (run by experiments/export.sh, which builds the programs this runs).

usage: python report.py PERF PEERS OUT

PERF is ktree's perf example (`--child export CASE` times `export::surface::boundary_mesh`; `--child
export CASE:write-vdb:PATH` writes the voxels as a BoolGrid), PEERS the C++ program of
experiments/export/peers.cpp. ROUNDS (default 3) rounds run every program of a case once each, in turn;
the table keeps each program's best over the rounds.
"""

import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from report_common import cpu, dpkg_version, run  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent.parent
INPUTS = ROOT / "target" / "export-inputs"
CASES = ["ball-6", "ball-8", "ball-10", "armadillo-8", "armadillo-10"]
PLY_HEADER = 200  # bytes, about: ktree's binary PLY header
COARSE = 0.5  # the adaptivity of the extra OpenVDB run



def machine() -> str:
    return f"{cpu()}, {os.cpu_count()} cores"


def load() -> str:
    try:
        return " ".join(Path("/proc/loadavg").read_text().split()[:3])
    except OSError:
        return "unknown"


def ply_mib(vertices: float, triangles: float) -> float:
    return (PLY_HEADER + 12 * vertices + 13 * triangles) / (1024 * 1024)



def main() -> None:
    perf, peers, out = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    rounds = int(os.environ.get("ROUNDS", "3"))
    started = load()
    INPUTS.mkdir(parents=True, exist_ok=True)
    rows = []
    for case in CASES:
        vdb = INPUTS / f"{case}.vdb"
        written = run([perf, "--child", "export", f"{case}:write-vdb:{vdb}"])
        env = dict(os.environ, REPEATS="1" if case.endswith("-10") else "3")
        best: dict[str, dict[str, str]] = {}
        for _ in range(rounds):
            for tool, command in [
                ("ktree", [perf, "--child", "export", case]),
                ("vdb-1", [peers, str(vdb), "1", "0"]),
                ("vdb-all", [peers, str(vdb), "0", "0"]),
            ]:
                got = run(command, env)
                if tool not in best or float(got["seconds"]) < float(best[tool]["seconds"]):
                    best[tool] = got
        coarse = run([peers, str(vdb), "1", str(COARSE)], dict(os.environ, REPEATS="1"))
        k, v1, va = best["ktree"], best["vdb-1"], best["vdb-all"]
        if not (k["voxels"] == written["voxels"] == v1["voxels"]):
            sys.exit(f"{case}: ktree has {k['voxels']} voxels, the BoolGrid {v1['voxels']}")
        faces = int(k["faces"])
        if int(v1["quads"]) != faces or int(v1["triangles"]) != 0:
            sys.exit(f"{case}: OpenVDB made {v1['quads']} quads and {v1['triangles']} triangles for {faces} unit faces")
        rows.append((case, k, v1, va, coarse))
        print(f"{case}: ktree {k['seconds']} s, OpenVDB {v1['seconds']} s", file=sys.stderr)

    lines = [
        "# Export: the boundary of an octree as a triangle mesh, against OpenVDB's volumeToMesh",
        "",
        "Regenerate with `experiments/export.sh`. Objects: the voxels whose centres lie in the ball of radius U/2 "
        "centred in the universe, and the armadillo (`data/meshes/`) fitted into the universe and voxelized.",
        "",
        "**ktree**: `export::surface::boundary_mesh`, the closed, 2-manifold boundary of the voxels with merged "
        "rectangles — the exact surface of the voxels (its volume is the voxel count), made by one sweep across "
        "the first axis over the tree's cross-sections. Timed: extracting the mesh, "
        "from the built tree, one thread; writing it as binary PLY into memory is shown apart (one run); peak "
        "memory is the child process's high-water mark of resident memory (building the tree included). "
        f"**OpenVDB** (libopenvdb-dev {dpkg_version('libopenvdb-dev')}, `experiments/export/peers.cpp`): the voxels written by "
        "ktree as a BoolGrid (`.vdb`, as `ktree convert X.ktree X.vdb` writes), turned into a level set by "
        "`tools::topologyToLevelSet` (half width 3, no closing, dilation or smoothing; its time shown apart), "
        "then `tools::volumeToMesh` at isovalue 0 and adaptivity 0 — the only part timed, on one thread "
        "(`tbb::global_control`) and on all threads. It makes one quad per unit voxel face (checked: quads = "
        "unit faces), its vertices inside the cells between voxel centres, where the level set crosses zero, so "
        "its surface is a rounded one, not the voxels' boundary; a quad is counted as two triangles. Adaptivity > 0 merges coplanar-ish "
        f"cells into fewer, larger polygons that only approximate that surface (column: adaptivity {COARSE}). "
        "One quad per face: two triangles per unit voxel face, vertices shared (V = F + χ for a closed quad mesh "
        "of F faces and Euler characteristic χ). PLY sizes for all: 12 bytes a vertex, 13 a triangle, and the "
        "header.",
        "",
        f"Times: the best over {rounds} rounds, the programs alternating, each process a fresh one timing the "
        "best of 3 runs (1 at L = 10).",
        "",
        f"Machine: {machine()}. Load average when started: {started}; when done: {load()}.",
        "",
        "**Goal**: faster than OpenVDB's `volumeToMesh` (one thread against one thread), with fewer triangles "
        "for the exact surface.",
        "",
        "| case | voxels | unit faces | ktree triangles | vertices | PLY MiB | ktree s | PLY write s | ktree peak MiB "
        "| OpenVDB triangles | PLY MiB | OpenVDB s, 1 thread | all threads | level set build s "
        f"| adaptivity {COARSE}: triangles | OpenVDB / ktree time | fewer triangles | faster "
        "| one quad per face: triangles | PLY MiB | triangles saved |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|---:|---:|---:|",
    ]
    fewer_all, faster_all = True, True
    for case, k, v1, va, coarse in rows:
        faces, tri, verts, chi = int(k["faces"]), int(k["triangles"]), int(k["vertices"]), int(k["chi"])
        ks, vs = float(k["seconds"]), float(v1["seconds"])
        vtri = int(v1["triangles_total"])
        fewer, faster = tri < vtri, ks < vs
        fewer_all &= fewer
        faster_all &= faster
        lines.append(
            f"| {case} | {k['voxels']} | {faces} | {tri} | {verts} | {int(k['bytes']) / 2**20:.2f} | {ks:.3f} "
            f"| {float(k['ply_seconds']):.3f} | {int(k['peak_bytes']) / 2**20:.0f} | {vtri} | {ply_mib(int(v1['points']), vtri):.2f} | {vs:.3f} "
            f"| {float(va['seconds']):.3f} | {float(v1['levelset_seconds']):.3f} | {coarse['triangles_total']} "
            f"| {vs / ks:.2f}× | {'yes' if fewer else 'no'} | {'yes' if faster else 'no'} | {2 * faces} | {ply_mib(faces + chi, 2 * faces):.2f} "
            f"| {2 * faces / tri:.1f}× |"
        )
    lines += [
        "",
        "Goal: fewer triangles than OpenVDB at adaptivity 0 — "
        + ("met in every case" if fewer_all else "**not** met in every case")
        + "; faster than OpenVDB — "
        + ("met in every case." if faster_all else "**not** met in every case (see the columns)."),
        "",
    ]
    out.write_text("\n".join(lines))


if __name__ == "__main__":
    main()
