"""scipy's side of ktree's shape operations (results/performance/shape.md, experiments/shape.sh), on the
dense voxels ktree wrote (`perf --child shape OBJECT:write-inputs:DIR`: DIR/dense.npy, u8, index [z, y, x]).

usage: python scipy_ops.py dilate DIR R     ndimage.binary_dilation by the ball |d|² ≤ R² (border 0)
       python scipy_ops.py label DIR        ndimage.label, connectivity 1 (the default structure)

Prints `key=value` lines as ktree's perf child does: `seconds` (best of REPEATS, default 3, reading the
array and making the structure not timed), `voxels` (dilation) or `count` and `largest` (label),
`peak_bytes` (the process's peak resident memory) and `rss_loaded` (resident once the array is read).
"""

import os
import resource
import sys
import time

import numpy as np
from scipy import ndimage


def rss_bytes() -> int:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    return 0


def main() -> None:
    op, folder = sys.argv[1], sys.argv[2]
    repeats = max(1, int(os.environ.get("REPEATS", "3")))
    grid = np.load(os.path.join(folder, "dense.npy")).astype(bool)
    loaded = rss_bytes()
    best = float("inf")
    facts: dict[str, int] = {}
    if op == "dilate":
        r = float(sys.argv[3])
        e = int(np.floor(r))
        d = np.arange(-e, e + 1)
        z, y, x = np.meshgrid(d, d, d, indexing="ij")
        ball = z * z + y * y + x * x <= np.floor(r * r)
        for _ in range(repeats):
            start = time.perf_counter()
            out = ndimage.binary_dilation(grid, structure=ball)
            best = min(best, time.perf_counter() - start)
            facts["voxels"] = int(np.count_nonzero(out))
            del out
    elif op == "label":
        for _ in range(repeats):
            start = time.perf_counter()
            labels, count = ndimage.label(grid)
            best = min(best, time.perf_counter() - start)
            sizes = np.bincount(labels.ravel())
            facts["count"] = int(count)
            facts["largest"] = int(sizes[1:].max()) if count else 0
            del labels, sizes
    else:
        sys.exit(f"unknown operation {op}")
    print(f"seconds={best:.9f}")
    for k, v in facts.items():
        print(f"{k}={v}")
    print(f"peak_bytes={resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024}")
    print(f"rss_loaded={loaded}")


if __name__ == "__main__":
    main()
