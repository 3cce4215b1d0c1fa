"""scipy's distance_transform_edt on the dense grid ktree wrote (`perf --child queries OBJECT:write-inputs:DIR`).

usage: python edt.py DIR [REPEATS]

Times the whole-grid transform of the empty voxels (the distance from each to the nearest full voxel, as
ktree's `nearest_many` measures it), best of REPEATS (default 1) in this process, loading not timed; then
reads the transform at the points of DIR/nearest.bin and prints `seconds=`, `answers=` (points at distance
0) and `sum_squared=` (the sum of the squared distances, rounded to integers), as ktree's perf child does.
"""

import sys
import time

import numpy as np
from scipy import ndimage


def main() -> None:
    folder = sys.argv[1]
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    dense = np.load(f"{folder}/dense.npy")  # index [z, y, x]
    empty = dense == 0
    best = float("inf")
    distances = None
    for _ in range(repeats):
        distances = None  # the previous run's array freed before the next
        start = time.perf_counter()
        distances = ndimage.distance_transform_edt(empty)
        best = min(best, time.perf_counter() - start)
    points = np.fromfile(f"{folder}/nearest.bin", dtype="<u4").reshape(-1, 3).astype(np.intp)
    found = distances[points[:, 2], points[:, 1], points[:, 0]]
    squared = np.rint(found * found).astype(np.int64)
    print(f"seconds={best}")
    print(f"answers={int((squared == 0).sum())}")
    print(f"sum_squared={int(squared.sum())}")


if __name__ == "__main__":
    main()
