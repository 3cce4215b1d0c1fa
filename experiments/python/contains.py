"""Writes results/performance/python.md: `Tree.contains` through the Python module beside the library's
`contains_many` and OpenVDB's cached accessor, on the same voxels and the same points (run by
experiments/python.sh, which builds the programs this runs).

usage: python contains.py PERF PEERS OUT
       python contains.py --child DTYPE DIR     (one timed call of Tree.contains; prints key=value lines)

PERF is ktree's perf example, PEERS the C++ program of experiments/queries/peers.cpp. The inputs are those of
experiments/queries.sh (`perf --child queries ball-10:write-inputs:DIR`): the L = 10 ball as `tree.vdb`
(read by `Tree.load`) and 10^7 random points as 3 × u32 each (`random.bin`). Every tool runs in a fresh
process on one thread (the library's case on a pool of one thread, Python and OpenVDB with one thread
asked for), loading the map and the points untimed, timing one call. ROUNDS (default 7) rounds run every
tool once each, in turn; the table gives the median and the best over the rounds.
"""

import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from report_common import cpu, dpkg_version, goal, run  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent.parent
INPUTS = ROOT / "target" / "query-inputs" / "ball-10"
POINTS = 10_000_000


def child(dtype: str, inputs: Path) -> None:
    """One timed `Tree.contains` call on the points read as `dtype` (int64: converted before timing)."""
    import numpy as np

    import ktree

    tree = ktree.Tree.load(inputs / "tree.vdb")
    points = np.fromfile(inputs / "random.bin", dtype="<u4").reshape(-1, 3)
    if dtype == "int64":
        points = points.astype(np.int64)
    start = time.perf_counter()
    inside = tree.contains(points)
    seconds = time.perf_counter() - start
    print(f"seconds={seconds}")
    print(f"answers={int(inside.sum())}")


def uptime() -> str:
    return subprocess.run(["uptime"], capture_output=True, text=True, check=False).stdout.strip()


def main() -> None:
    if sys.argv[1] == "--child":
        child(sys.argv[2], Path(sys.argv[3]))
        return
    perf, peers, out = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    rounds = int(os.environ.get("ROUNDS", "7"))
    if not (INPUTS / "random.bin").exists() or not (INPUTS / "tree.vdb").exists():
        run([perf, "--child", "queries", f"ball-10:write-inputs:{INPUTS}"])
    one = dict(os.environ, REPEATS="1", RAYON_NUM_THREADS="1")
    me = [sys.executable, str(Path(__file__).resolve()), "--child"]
    tools = [
        ("library `contains_many` (u32 points)", [perf, "--child", "queries", "ball-10:batch-random-1"]),
        ("Python `Tree.contains`, int64 array", [*me, "int64", str(INPUTS)]),
        ("Python `Tree.contains`, uint32 array", [*me, "uint32", str(INPUTS)]),
        ("OpenVDB `ValueAccessor`", [peers, "vdb-accessor", str(INPUTS / "tree.vdb"), str(INPUTS / "random.bin"), "1"]),
    ]
    load_start = uptime()
    times: dict[str, list[float]] = {name: [] for name, _ in tools}
    answers: dict[str, str] = {}
    for r in range(rounds):
        for name, command in tools:
            got = run(command, env=one)
            times[name].append(float(got["seconds"]))
            answers[name] = got["answers"]
        print(f"round {r + 1} of {rounds} done", file=sys.stderr)
    load_end = uptime()

    reference = answers[tools[0][0]]
    lines = []
    w = lines.append
    w("# Python: `Tree.contains` beside the library and OpenVDB")
    w("")
    w(
        "Regenerate with `experiments/python.sh` (builds ktree's `perf` example, the peers' program of "
        "`experiments/queries/peers.cpp` against Debian's libopenvdb-dev, and the Python module in a virtual "
        "environment in `target/`). The voxels and points of `results/performance/queries.md`: the voxels "
        "whose centres lie in the ball of radius U/2 centred in the universe at L = 10, and 10^7 random "
        "points uniform in the universe (`perf --child queries ball-10:write-inputs:DIR`), which Python reads "
        "from the same file (`tree.vdb` through `Tree.load`, the points as a numpy array)."
    )
    w("")
    w(
        "Tools, one thread each. **Library**: `contains_many` on a rayon pool of one thread, points as "
        "`[u32; 3]`. **Python**: `Tree.contains(points)` with `RAYON_NUM_THREADS=1`, points an (N, 3) numpy "
        "array: int64, read in place (C-contiguous, the dtype the method reads) and answered by the "
        "library's `contains_many_signed`; uint32, read in place too and answered by the library's "
        "`contains_many` itself. The timed "
        "call includes everything Python pays: reading the arguments, releasing the interpreter lock, the "
        "answer as a numpy array. **OpenVDB** (libopenvdb-dev "
        f"{dpkg_version('libopenvdb-dev')}): `getValue` through a `ValueAccessor` on a BoolGrid of the same "
        "voxels."
    )
    w("")
    w(
        f"Times: {rounds} rounds; in each round every tool runs once, in turn, in a fresh process timing one "
        "call (loading the map and the points not timed). The machine is shared with other builds, so the "
        "median over the rounds is the figure compared; the best is shown beside it."
    )
    w("")
    w(f"Machine: {cpu()}, {os.cpu_count()} cores. Load (`uptime`) at the start: {load_start}; at the end: {load_end}.")
    w("")
    w("| tool | points | median (s) | median ns / point | best (s) | best ns / point | answers | agrees |")
    w("|---|---:|---:|---:|---:|---:|---:|---|")
    per: dict[str, float] = {}
    for name, _ in tools:
        median, best = statistics.median(times[name]), min(times[name])
        per[name] = median * 1e9 / POINTS
        agrees = "reference" if name == tools[0][0] else ("yes" if answers[name] == reference else "NO")
        w(
            f"| {name} | {POINTS} | {median:.3f} | {per[name]:.1f} | {best:.3f} | {best * 1e9 / POINTS:.1f} | "
            f"{answers[name]} | {agrees} |"
        )
    w("")
    w("Every round's times (s), in the order run:")
    w("")
    for name, _ in tools:
        w(f"- {name}: " + ", ".join(f"{t:.3f}" for t in times[name]))
    w("")
    w("Goals (medians):")
    w("")
    lib, py = per[tools[0][0]], per[tools[1][0]]
    vdb = per[tools[3][0]]
    w("- " + goal("Python's `Tree.contains` (int64) within 1.2× of the library's `contains_many`", py, lib, 1.2))
    w("- " + goal("Python's `Tree.contains` (int64) faster than OpenVDB's cached accessor", py, vdb, 1.0))
    w("")
    out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
