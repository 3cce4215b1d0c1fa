"""Questions asked of a tree from Python, checked against numpy and scipy: point queries (one point or an
(N, K) array, and tree[x, y, z]), dense windows and slices, full cells, bounding boxes, ray casts (against a
brute-force pass over every full voxel in exact fractions) and distances (scipy's distance_transform_edt)."""

from fractions import Fraction

import numpy as np
import pytest
from scipy.ndimage import distance_transform_edt

import ktree

LEVELS = {1: 5, 2: 4, 3: 3, 4: 2}


def random_object(rng, k, level):
    side = 2**level
    a = rng.random((side,) * k) < 0.15
    for _ in range(3):
        block = 2 ** rng.integers(0, level)
        start = rng.integers(0, side // block, size=k) * block
        a[tuple(slice(s, s + block) for s in start)] = True
    return a


@pytest.fixture
def rng():
    return np.random.default_rng(2024)


def padded_window(a, origin, shape):
    """The window of `a` (False outside it), by numpy."""
    out = np.zeros(shape, dtype=bool)
    src = tuple(slice(max(o, 0), min(o + s, n)) for o, s, n in zip(origin, shape, a.shape))
    dst = tuple(slice(sl.start - o, sl.stop - o) for sl, o in zip(src, origin))
    if all(sl.stop > sl.start for sl in src):
        out[dst] = a[src]
    return out


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_contains_one_point_and_arrays(rng, k):
    a = random_object(rng, k, LEVELS[k])
    t = ktree.Tree.from_dense(a)
    side = t.side
    points = rng.integers(-3, side + 3, size=(300, k))
    inside = np.all((points >= 0) & (points < side), axis=1)
    expect = np.zeros(len(points), dtype=bool)
    expect[inside] = a[tuple(points[inside].T)]
    got = t.contains(points)
    assert got.dtype == np.bool_ and got.shape == (len(points),)
    np.testing.assert_array_equal(got, expect)
    for p, e in zip(points[:20], expect[:20]):
        assert t.contains(p) is bool(e)
        assert t.contains(list(p)) is bool(e)
        assert t[tuple(p)] is bool(e)
    assert t.contains(np.zeros((0, k), dtype=np.int64)).shape == (0,)
    with pytest.raises(ValueError, match=f"{k} coordinates"):
        t.contains(np.zeros((3, k + 1), dtype=np.int64))


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_windows_slices_boxes_and_cells(rng, k):
    a = random_object(rng, k, LEVELS[k])
    t = ktree.Tree.from_dense(a)
    side = t.side
    full = np.argwhere(a)
    lo, hi = full.min(axis=0), full.max(axis=0) + 1
    assert t.bounding_box() == (list(lo), list(hi))
    # The default window is the bounding box.
    np.testing.assert_array_equal(t.to_dense(), a[tuple(slice(l, h) for l, h in zip(lo, hi))])
    np.testing.assert_array_equal(t.to_dense((0,) * k, (side,) * k), a)
    for _ in range(10):
        origin = rng.integers(-3, side, size=k)
        shape = rng.integers(0, side + 3, size=k)
        np.testing.assert_array_equal(
            t.to_dense(list(origin), list(shape)), padded_window(a, origin, shape)
        )
        # Slices as numpy slices the universe.
        key = tuple(slice(int(o), int(o + s)) for o, s in zip(origin, shape))
        np.testing.assert_array_equal(t[key if k > 1 else key[0]], a[key])
    # Integers drop their axes; negative bounds count from the side.
    if k >= 2:
        np.testing.assert_array_equal(t[(1,) + (slice(None),) * (k - 1)], a[1])
        np.testing.assert_array_equal(t[(slice(-3, None),) * k], a[(slice(-3, None),) * k])
    with pytest.raises(ValueError, match="steps must be 1"):
        t[(slice(0, side, 2),) * k]
    # The full cells rebuild the array; sides are powers of two and corners aligned.
    cells = t.cells()
    assert cells.dtype == np.int64 and cells.shape[1] == k + 1
    rebuilt = np.zeros_like(a)
    for row in cells:
        corner, s = row[:k], row[k]
        assert s & (s - 1) == 0 and np.all(corner % s == 0)
        rebuilt[tuple(slice(c, c + s) for c in corner)] = True
    np.testing.assert_array_equal(rebuilt, a)
    assert sum(int(s) ** k for s in cells[:, k]) == int(a.sum())


def test_an_empty_tree():
    t = ktree.Tree.empty(3, 4)
    assert t.bounding_box() is None
    assert t.to_dense().shape == (0, 0, 0)
    assert t.cells().shape == (0, 4)
    assert t.distance([1, 2, 3]) == np.inf
    np.testing.assert_array_equal(t.nearest([[1, 2, 3], [0, 0, 0]]), -np.ones((2, 3)))
    hits = t.cast_rays([[0.5, 0.5, 0.5]], [[1.0, 1.0, 1.0]])
    assert not hits.hit[0] and hits.t[0] == np.inf and list(hits.voxel[0]) == [-1, -1, -1]


@pytest.mark.parametrize("k", [1, 2, 3])
def test_distance_and_nearest_equal_scipy(rng, k):
    a = random_object(rng, k, LEVELS[k])
    t = ktree.Tree.from_dense(a)
    points = np.argwhere(np.ones_like(a))
    edt = distance_transform_edt(~a)
    d = t.distance(points)
    assert d.dtype == np.float64 and d.shape == (len(points),)
    np.testing.assert_allclose(d, edt[tuple(points.T)], rtol=0, atol=1e-12)
    n = t.nearest(points)
    assert n.dtype == np.int64 and n.shape == points.shape
    assert a[tuple(n.T)].all()
    np.testing.assert_allclose(np.linalg.norm(n - points, axis=1), d, atol=1e-12)
    # One point; points outside the universe.
    assert t.distance(points[3]) == pytest.approx(d[3])
    np.testing.assert_array_equal(t.nearest(points[3]), n[3])
    outside = np.full(k, -5)
    full = np.argwhere(a)
    assert t.distance(outside) == pytest.approx(np.linalg.norm(full - outside, axis=1).min())


def exact_entry(origin, direction, max_t, voxel):
    """The infimum of {t in [0, max_t]: origin + t * direction in [voxel, voxel + 1)}, or None."""
    low, low_open = Fraction(0), False
    high, high_open = max_t, False
    for o, d, v in zip(origin, direction, voxel):
        if d == 0:
            if not (v <= o < v + 1):
                return None
            continue
        if d > 0:
            lo, lo_open, hi, hi_open = (v - o) / d, False, (v + 1 - o) / d, True
        else:
            lo, lo_open, hi, hi_open = (v + 1 - o) / d, True, (v - o) / d, False
        if lo > low or (lo == low and lo_open):
            low, low_open = lo, lo_open
        if high is None or hi < high or (hi == high and hi_open):
            high, high_open = hi, hi_open
    if high is None or low < high or (low == high and not low_open and not high_open):
        return low
    return None


@pytest.mark.parametrize("k", [1, 2, 3])
def test_cast_rays_equal_a_brute_force_march(rng, k):
    a = random_object(rng, k, LEVELS[k])
    t = ktree.Tree.from_dense(a)
    side = t.side
    n = 40
    origins = rng.integers(-side * 64, 2 * side * 64, size=(n, k)) / 64
    directions = rng.integers(-100, 101, size=(n, k)) / 16
    directions[rng.random((n, k)) < 0.2] = 0
    hits = t.cast_rays(origins, directions)
    assert isinstance(hits, ktree.RayHits) and hits._fields == ("hit", "voxel", "t", "axis", "sign")
    full = [tuple(v) for v in np.argwhere(a)]
    for i in range(n):
        o = [Fraction(x) for x in origins[i]]
        d = [Fraction(x) for x in directions[i]]
        entries = {v: e for v in full if (e := exact_entry(o, d, None, v)) is not None}
        if not entries:
            assert not hits.hit[i] and hits.t[i] == np.inf and hits.axis[i] == -1
            continue
        first = min(entries.values())
        assert hits.hit[i]
        assert hits.t[i] == pytest.approx(float(first), abs=1e-9)
        assert entries.get(tuple(hits.voxel[i])) == first
        if first == 0 and hits.axis[i] == -1:
            assert hits.sign[i] == 0
        else:
            axis = hits.axis[i]
            assert hits.sign[i] == (-1 if directions[i][axis] > 0 else 1)
    # max_t cuts rays short.
    short = t.cast_rays(origins, directions, max_t=0.5)
    assert np.all(~short.hit | (short.t <= 0.5))
    assert np.all(short.hit <= hits.hit)


def test_cast_rays_named_cases_and_errors():
    a = np.zeros((8, 8), dtype=bool)
    a[2:4, 2:4] = True
    t = ktree.Tree.from_dense(a)
    hits = t.cast_rays(
        [[-3.0, 2.5], [2.5, 12.0], [3.25, 3.25], [2.0, 0.25], [4.0, 0.25], [0.5, 0.5]],
        [[1.0, 0.0], [0.0, -2.0], [1.0, 1.0], [0.0, 1.0], [0.0, 1.0], [-1.0, 0.0]],
    )
    np.testing.assert_array_equal(hits.hit, [True, True, True, True, False, False])
    np.testing.assert_array_equal(hits.voxel[:4], [[2, 2], [2, 3], [3, 3], [2, 2]])
    np.testing.assert_array_equal(hits.t[:4], [5.0, 4.0, 0.0, 1.75])
    np.testing.assert_array_equal(hits.axis, [0, 1, -1, 1, -1, -1])
    np.testing.assert_array_equal(hits.sign, [-1, 1, 0, -1, 0, 0])
    assert hits.voxel.dtype == np.int64 and hits.axis.dtype == np.int8
    for bad in [np.nan, np.inf]:
        with pytest.raises(ValueError, match="finite"):
            t.cast_rays([[0.5, bad]], [[1.0, 0.0]])
        with pytest.raises(ValueError, match="finite"):
            t.cast_rays([[0.5, 0.5]], [[bad, 0.0]])
    with pytest.raises(ValueError, match="max_t"):
        t.cast_rays([[0.5, 0.5]], [[1.0, 0.0]], max_t=np.nan)
    with pytest.raises(ValueError, match="as many"):
        t.cast_rays([[0.5, 0.5]], [[1.0, 0.0], [0.0, 1.0]])
