"""Writes results/performance/shape.md: ktree's shape operations and their peers side by side (run by
experiments/shape.sh, which builds the programs this runs).

usage: python report.py PERF PEERS OUT

PERF is ktree's perf example, PEERS the C++ program of experiments/shape/peers.cpp; scipy is imported by
experiments/shape/scipy_ops.py, run with this interpreter. ROUNDS (default 3) rounds run every program of a
question once each, in turn, each process timing one run (REPEATS=1); the tables keep the best over the
rounds. Where two programs compute the same set, their voxel counts must be equal or this fails.
"""

import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from report_common import cpu, dpkg_version, goal, run  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
INPUTS = Path("target") / "shape-inputs"
OBJECTS = ["ball-10", "armadillo-10"]
RADII = [2, 8, 32]
# scipy's binary_dilation by a ball: its cost is (empty voxels) × (offsets of the ball), so the radii stop
# where one run would take over a few minutes on this machine (see the estimates in the file).
SCIPY_DILATIONS = [("ball-8", [2, 8]), ("armadillo-8", [2, 8]), ("ball-9", [2, 8]), ("armadillo-9", [2])]
# OpenVDB's level-set offset moves the surface half a voxel a step, each step a renormalization of the
# band: minutes a run at L = 10, so the ball is compared with it at L = 8.
OFFSETS = [("ball-8", [2, 8]), ("armadillo-8", [2, 8])]
OFFSET_TOOL = "OpenVDB `topologyToLevelSet` + `LevelSetFilter::offset`"
LABEL_OBJECTS = ["ball-8", "armadillo-8", "ball-9", "armadillo-9"]
BAND = 3
MIB = 1 << 20



def level(obj: str) -> int:
    return int(obj.rsplit("-", 1)[1])


def ball_offsets(r: int) -> int:
    return sum(1 for x in range(-r, r + 1) for y in range(-r, r + 1) for z in range(-r, r + 1) if x * x + y * y + z * z <= r * r)


def questions(perf: str, peers: str) -> list[tuple[str, str, str, list[tuple[str, list[str]]]]]:
    """(section, object, question, [(tool, command)])."""
    py = sys.executable
    ops = str(HERE / "scipy_ops.py")
    out = []
    for obj in OBJECTS:
        d = str(INPUTS / obj)
        side = str(1 << level(obj))
        ktree = lambda case: [perf, "--child", "shape", f"{d}:{case}"]  # noqa: E731
        for op in ["dilate", "erode"]:
            for r in RADII:
                tools = [(f"ktree `{op}` {e}", ktree(f"{op}:{e}:{r}")) for e in ["ball", "box", "cross"]]
                tools += [
                    (f"OpenVDB `{op}ActiveValues` box (NN_FACE_EDGE_VERTEX × {r})", [peers, "morph", d, op, "box", str(r), side]),
                    (f"OpenVDB `{op}ActiveValues` cross (NN_FACE × {r})", [peers, "morph", d, op, "cross", str(r), side]),
                ]
                out.append(("morph", obj, f"{op} {r}", tools))
    for obj in OBJECTS:
        # The tree to runs and back, no element: what every ktree dilation or erosion pays besides its passes.
        tools = [("ktree `dilate` box 0 (tree → runs → tree)", [perf, "--child", "shape", f"{INPUTS / obj}:dilate:box:0"])]
        out.append(("morph", obj, "round trip", tools))
    for obj, radii in OFFSETS:
        d = str(INPUTS / obj)
        side = str(1 << level(obj))
        for op in ["dilate", "erode"]:
            for r in radii:
                tools = [
                    (f"ktree `{op}` ball", [perf, "--child", "shape", f"{d}:{op}:ball:{r}"]),
                    (OFFSET_TOOL, [peers, "offset", d, op, str(r), side]),
                ]
                out.append(("ball", obj, f"{op} {r}", tools))
    for obj, radii in SCIPY_DILATIONS:
        d = str(INPUTS / obj)
        for r in radii:
            tools = [
                ("ktree `dilate` ball", [perf, "--child", "shape", f"{d}:dilate:ball:{r}"]),
                ("scipy `binary_dilation` ball", [py, ops, "dilate", d, str(r)]),
            ]
            out.append(("scipy", obj, f"dilate {r}", tools))
    for obj in LABEL_OBJECTS:
        d = str(INPUTS / obj)
        tools = [
            ("ktree `components(1)`", [perf, "--child", "shape", f"{d}:components"]),
            ("scipy `label`", [py, ops, "label", d]),
        ]
        out.append(("scipy", obj, "components", tools))
    for obj in OBJECTS:
        d = str(INPUTS / obj)
        tools = [
            (f"ktree `narrow_band({BAND})`", [perf, "--child", "shape", f"{d}:band:{BAND}"]),
            (f"OpenVDB `topologyToLevelSet` (half-width {BAND})", [peers, "band", d, str(BAND), str(1 << level(obj))]),
        ]
        out.append(("band", obj, "band", tools))
    return out


def mib(v: str) -> str:
    return f"{int(v) / MIB:.1f}"


def check(obj: str, question: str, results: dict[str, dict[str, str]]) -> dict[str, str]:
    """What each tool's answer says against ktree's: equal where the sets are the same, or this fails."""
    verdict: dict[str, str] = {}
    for tool, got in results.items():
        if tool.startswith("ktree"):
            verdict[tool] = "reference"
            continue
        if "ActiveValues" in tool:
            element = "box" if " box " in tool else "cross"
            ref = next(v for t, v in results.items() if t.startswith("ktree") and t.endswith(element))
            if ref["voxels"] != got["voxels"]:
                sys.exit(f"{obj} {question}: {tool} has {got['voxels']} voxels, ktree's {element} {ref['voxels']}")
            verdict[tool] = f"yes: voxels equal to ktree's {element}"
        elif "offset" in tool:
            ref = next(v for t, v in results.items() if t.startswith("ktree") and t.endswith("ball"))
            a, b = int(ref["voxels"]), int(got["voxels"])
            verdict[tool] = f"approximate: {b - a:+d} voxels ({100 * (b - a) / a:+.2f} %) against ktree's ball" if a else "—"
        elif "binary_dilation" in tool:
            ref = results["ktree `dilate` ball"]
            if ref["voxels"] != got["voxels"]:
                sys.exit(f"{obj} {question}: scipy has {got['voxels']} voxels, ktree {ref['voxels']}")
            verdict[tool] = "yes: voxels equal"
        elif "label" in tool:
            ref = results["ktree `components(1)`"]
            if (ref["count"], ref["largest"]) != (got["count"], got["largest"]):
                sys.exit(f"{obj}: scipy labels {got['count']} (largest {got['largest']}), ktree {ref['count']} ({ref['largest']})")
            verdict[tool] = "yes: count and largest equal"
        elif "topologyToLevelSet" in tool:
            verdict[tool] = "other definition (see below)"
    return verdict


def main() -> None:
    perf, peers, out = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    os.environ["REPEATS"] = "1"
    rounds = int(os.environ.get("ROUNDS", "3"))
    load = open("/proc/loadavg").read().split()[:3]
    began = time.monotonic()
    inputs: dict[str, dict[str, str]] = {}
    for obj in sorted(set(OBJECTS + LABEL_OBJECTS + [o for o, _ in SCIPY_DILATIONS + OFFSETS])):
        inputs[obj] = run([perf, "--child", "shape", f"{obj}:write-inputs:{INPUTS / obj}"])
        print(f"inputs of {obj} written", file=sys.stderr)
    qs = questions(perf, peers)
    best: dict[tuple[int, int], tuple[float, dict[str, str]]] = {}
    for r in range(rounds):
        for qi, (_, obj, question, tools) in enumerate(qs):
            for ti, (tool, command) in enumerate(tools):
                got = run(command)
                seconds = float(got["seconds"])
                if (qi, ti) not in best or seconds < best[(qi, ti)][0]:
                    best[(qi, ti)] = (seconds, got)
            print(f"round {r + 1}: {obj} {question} done", file=sys.stderr)
    load_end = open("/proc/loadavg").read().split()[:3]
    minutes = (time.monotonic() - began) / 60

    lines: list[str] = []
    w = lines.append
    w("# Shape operations: morphology, components, narrow band — ktree and its peers side by side")
    w("")
    w(
        "Regenerate with `experiments/shape.sh` (builds ktree's `perf` example and `experiments/shape/peers.cpp` "
        "with `g++` against Debian's libopenvdb-dev, and runs scipy in a virtual environment in `target/`). "
        "Objects, as in `queries.md`: the voxels whose centres lie in the ball of radius U/2 centred in the "
        "universe, and `data/meshes/armadillo.obj` fitted to the universe and voxelized, at L = 10 (L = 8 and 9 "
        "against scipy). ktree writes each once (`perf --child shape OBJECT:write-inputs:DIR`) as `tree.ktree`, "
        "`tree.vdb` (a BoolGrid, index = ktree voxel) and for L ≤ 9 `dense.npy` (u8, index [z, y, x]); every "
        "program reads the same voxels from them, untimed."
    )
    w("")
    w(
        "Tools, all on **one thread**. **ktree**: `KTree::dilate` / `KTree::erode` by a ball (`|d|² ≤ r²`), "
        "box (`max |d_i| ≤ r`) or cross (`Σ |d_i| ≤ r`), each from the tree to the result tree (runs "
        "extracted, operated, stacked again); `components(1)`; `narrow_band(3)`. **OpenVDB** (libopenvdb-dev "
        f"{dpkg_version('libopenvdb-dev')}, TBB limited to one thread): `tools::dilateActiveValues` / "
        "`tools::erodeActiveValues` on a MaskTree of the voxels (`PRESERVE_TILES`), r iterations of "
        "NN_FACE_EDGE_VERTEX (the 3×3×3 box: r of them make ktree's box of radius r) or NN_FACE (the unit "
        "cross: r of them make ktree's cross of radius r); for the ball, at L = 8, `tools::topologyToLevelSet` "
        "(half-width 3, no closing) and `LevelSetFilter::offset` by ∓r, counting the interior voxels "
        "(`tools::sdfInteriorMask`) — the offset moves the surface half a voxel a step, each step "
        "renormalizing the band, minutes a run at L = 10; the narrow band by `tools::topologyToLevelSet` (half-width 3). "
        "**scipy** (the versions pinned in `experiments/shape.sh`): `ndimage.binary_dilation` of the dense "
        "grid with the ball structure `|d|² ≤ r²`, and `ndimage.label` (connectivity 1, its default)."
    )
    w("")
    w(
        "Border. ktree's universe is the array: a dilation is clipped to it, an erosion counts the outside as "
        "empty (scipy's `border_value=0`). The objects touch the universe's faces, so OpenVDB's results are "
        "clipped to [0, U)³ before they are counted (OpenVDB still computes the part outside, a few percent "
        "of the work at r = 32); its erosion already counts the outside as empty (inactive background). "
        "Box and cross are then the same sets in ktree and OpenVDB, and ktree's ball dilation the same set as "
        "scipy's: their voxel counts are checked equal (this file is not written otherwise). OpenVDB has no "
        "exact ball: its level-set offset moves a surface through the voxels' faces by r with a first-order "
        "PDE, so its interior differs from the exact ball dilation or erosion by a thin shell; the table gives "
        "by how much."
    )
    w("")
    w(
        f"Times: the best of {rounds} round{'s' if rounds != 1 else ''} (ROUNDS={rounds}; the default is 3, and "
        f"this run took {minutes:.0f} minutes); in each round every program of a "
        "question runs once, in turn, in a fresh process timing one run (reading the input not timed). "
        "Memory: the process's peak resident memory (VmHWM; for scipy `ru_maxrss`) and its resident memory "
        "once the input was read; \"result\" is the result's own size (ktree `KTree::heap_bytes`, OpenVDB "
        "`Tree::memUsage` before clipping)."
    )
    w("")
    w(
        f"Machine: {cpu()}, {os.cpu_count()} cores, shared with other builds and runs: load average "
        f"{' '.join(load)} at the start, {' '.join(load_end)} at the end. The programs measured add about 1; "
        "other work above that takes time from ktree and its peers alike (they alternate)."
    )
    w("")
    w("Inputs:")
    w("")
    w("| object | voxels | ktree nodes |")
    w("|---|---:|---:|")
    for obj, facts in inputs.items():
        w(f"| {obj} | {facts['voxels']} | {facts['nodes']} |")
    w("")

    times: dict[tuple[str, str, str], float] = {}
    peaks: dict[tuple[str, str, str], dict[str, str]] = {}
    sections = {
        "morph": "## Dilation and erosion, L = 10, one thread",
        "ball": "## The ball against OpenVDB's level-set offset, L = 8, one thread",
        "scipy": "## Against scipy, L = 8 and 9, one thread",
        "band": f"## Narrow band of half-width {BAND}, L = 10, one thread",
    }
    for section, title in sections.items():
        w(title)
        w("")
        w("| object | question | tool | best time (s) | voxels | agrees | peak RSS (MiB) | RSS with input (MiB) | result (MiB) |")
        w("|---|---|---|---:|---:|---|---:|---:|---:|")
        for qi, (sec, obj, question, tools) in enumerate(qs):
            if sec != section:
                continue
            results = {tool: best[(qi, ti)][1] for ti, (tool, _) in enumerate(tools)}
            verdict = check(obj, question, results)
            for ti, (tool, _) in enumerate(tools):
                seconds, got = best[(qi, ti)]
                times[(obj, question, tool)] = seconds
                peaks[(obj, question, tool)] = got
                answer = got.get("voxels") or got.get("band") or f"{got.get('count')} (largest {got.get('largest')})"
                if "band" in got and "voxels" not in got:
                    answer = f"{got['band']} ({got['band_inside']} inside)"
                if section == "band" and "band" in got:
                    answer = f"{got['band']} ({got['band_inside']} inside)"
                result = mib(got["tree_bytes"]) if "tree_bytes" in got else "—"
                w(
                    f"| {obj} | {question} | {tool} | {seconds:.3f} | {answer} | {verdict[tool]} | "
                    f"{mib(got['peak_bytes'])} | {mib(got['rss_loaded'])} | {result} |"
                )
        w("")
        if section == "scipy":
            w(scipy_estimates(inputs, times))
            w("")
        if section == "band":
            w(
                "The two bands are different sets: ktree's holds every voxel whose exact signed distance "
                f"(between voxel centres) is at most {BAND} in absolute value; OpenVDB's the voxels within "
                f"{BAND} face steps (NN_FACE) of the interface, outside and inside, with values from the "
                "level set's renormalization (a first-order PDE, `LevelSetFilter::normalize`) — the counts are "
                "given for scale, not checked."
            )
            w("")

    w("## Goals")
    w("")
    for obj in OBJECTS:
        for r in [x for x in RADII if x >= 8]:
            for element, vdb in [("box", "box (NN_FACE_EDGE_VERTEX"), ("cross", "cross (NN_FACE")]:
                k = times[(obj, f"dilate {r}", f"ktree `dilate` {element}")]
                v = next(t for (o, q, tool), t in times.items() if o == obj and q == f"dilate {r}" and vdb in tool)
                w(f"- {obj}, r = {r}: " + goal(f"dilation by a {element} faster than OpenVDB's `dilateActiveValues`, one thread, in s", k, v, 1.0, 3))
    for obj, radii in OFFSETS:
        for r in [x for x in radii if x >= 8]:
            k = times[(obj, f"dilate {r}", "ktree `dilate` ball")]
            v = times[(obj, f"dilate {r}", OFFSET_TOOL)]
            w(f"- {obj}, r = {r}: " + goal("exact ball dilation faster than OpenVDB's level-set offset (its nearest way to a ball), one thread, in s", k, v, 1.0, 3))
    for obj in [o for o in LABEL_OBJECTS if level(o) == 9]:
        pairs = [(f"dilate {r}", "ktree `dilate` ball", "scipy `binary_dilation` ball") for r in RADII]
        for question, ktool, stool in pairs + [("components", "ktree `components(1)`", "scipy `label`")]:
            if (obj, question, ktool) in times:
                k, s = times[(obj, question, ktool)], times[(obj, question, stool)]
                w(f"- {obj}, {question}: " + goal("at least 10× faster than scipy, one thread (10 × ktree's s against scipy's)", 10 * k, s, 1.0, 3))
    w(memory_goal(inputs, peaks))
    w("")
    def trip_share(obj: str, t: str) -> str:
        fastest = min(v for (o, q, tool), v in times.items() if o == obj and q == "dilate 2" and tool.startswith("ktree"))
        return f"{obj} {times[(obj, 'round trip', t)]:.2f} s, {100 * times[(obj, 'round trip', t)] / fastest:.0f} %"

    trip = "; ".join(trip_share(obj, t) for (obj, q, t) in times if q == "round trip")
    w(
        "Why. OpenVDB's `dilateActiveValues` / `erodeActiveValues` work on the 8³ bit masks of its leaves, a "
        "step shifting 64-bit words, r steps. ktree's box is a segment along the runs and, on each other "
        "axis, about log₂ r passes of three column offsets (segments by doubling); its cross r passes of the "
        "unit cross (five column offsets); its ball one pass per column offset of the ball's slice (13 at "
        "r = 2, 197 at r = 8, 3209 at r = 32; from r = 40 the exact distance transform over blocks, whose "
        "cost grows with the surface times (block + 2r)³ / block³). Every pass is a merge over all the runs, and every "
        "ktree operation also pays the way from the tree to runs and back (the \"round trip\" rows, and "
        f"their share of ktree's fastest dilation at r = 2: {trip}). scipy's `binary_dilation` costs about (empty voxels) × "
        "(offsets of the ball), ktree's (runs) × (column offsets). ktree's memory is its runs (a packed "
        "64-bit column key and two 64-bit ends: 24 bytes a run), three buffers alive during the passes, the "
        "cells of the rebuilt tree, and for the ball from r = 40 the dense blocks of the distance transform "
        "(a block's source up to 2^25 voxels): proportional to the runs and the surface, not the universe, but with a large "
        "constant against the 2-bit tree. Components: the runs are labelled by union–find over the "
        "neighbouring columns (timed in full); both objects are one piece, and a single piece's tree is the "
        "input tree itself, handed back instead of rebuilt from its runs — with several pieces each is "
        "stacked from its runs, which this table does not measure."
    )
    w("")
    out.write_text("\n".join(lines) + "\n")


def scipy_estimates(inputs: dict[str, dict[str, str]], times: dict[tuple[str, str, str], float]) -> str:
    """scipy's dilations not run, estimated from its rate at L = 8 and r = 8 (its cost: empty voxels × offsets)."""
    parts = []
    for obj in ["ball", "armadillo"]:
        key = (f"{obj}-8", "dilate 8", "scipy `binary_dilation` ball")
        if key not in times:
            continue
        empty8 = (1 << 24) - int(inputs[f"{obj}-8"]["voxels"])
        rate = times[key] / (empty8 * ball_offsets(8))
        empty9 = (1 << 27) - int(inputs[f"{obj}-9"]["voxels"])
        radii = [r for r in [8, 32] if (f"{obj}-9", f"dilate {r}", "scipy `binary_dilation` ball") not in times]
        est = ", ".join(f"r = {r}: about {rate * empty9 * ball_offsets(r) / 60:.0f} min" for r in radii)
        parts.append(f"{obj}-9 ({est})")
    return (
        "scipy's `binary_dilation` tests, at every voxel not set, the structure's offsets until one is set: "
        "its time is about (empty voxels) × (offsets of the ball: 33, 2109 and 143 013 for r = 2, 8 and 32). "
        "It was run where one run takes minutes at most; the rest, estimated from its measured rate at L = 8, "
        "r = 8 (an estimate, not a measurement): " + "; ".join(parts) + ". ktree's cost depends on the runs "
        "and the element's column offsets, not on the empty space."
    )


def memory_goal(inputs: dict[str, dict[str, str]], peaks: dict[tuple[str, str, str], dict[str, str]]) -> str:
    """Memory proportional to the tree: ktree's largest peak at L = 10 against the universe's bit mask, and
    the growth of its peak from L = 8 to L = 10 against the growth of its tree and of the universe."""
    lines = []
    worst = None
    for (obj, question, tool), got in peaks.items():
        if not tool.startswith("ktree") or level(obj) != 10 or not question.startswith(("dilate", "erode")):
            continue
        peak = int(got["peak_bytes"])
        if worst is None or peak > worst[0]:
            worst = (peak, obj, question, tool, got)
    if worst is not None:
        peak, obj, question, tool, got = worst
        bitmask = (1 << (3 * level(obj))) // 8
        trees = int(got["tree_bytes_in"]) + int(got.get("tree_bytes", "0"))
        lines.append(
            "- memory, L = 10: "
            + goal(
                "every ktree dilation and erosion peaks below one bit per voxel of the universe (the smallest "
                "dense mask), in MiB",
                peak / MIB,
                bitmask / MIB,
                1.0,
            )
            + f" The largest: {obj} {question}, {tool}; its input and result trees take {trees / MIB:.1f} MiB."
        )
    tool = "ktree `dilate` ball"
    for name in ["ball", "armadillo"]:
        small, big = peaks.get((f"{name}-8", "dilate 2", tool)), peaks.get((f"{name}-10", "dilate 2", tool))
        if small is None or big is None:
            continue
        grew = int(big["peak_bytes"]) / int(small["peak_bytes"])
        nodes = int(big["nodes_in"]) / int(small["nodes_in"])
        lines.append(
            f"- memory, {name} from L = 8 to L = 10 (the universe 64× larger): "
            + goal(
                "ktree's peak for the ball dilation of radius 2 grows like its tree, within 1.5× of the growth "
                "of its nodes (growth of the peak against 1.5 × growth of the nodes)",
                grew,
                1.5 * nodes,
                1.0,
                2,
            )
        )
    return "\n".join(lines) if lines else "- memory: no ktree case at L = 10."





if __name__ == "__main__":
    main()
