"""Occupancy maps (ktree.OccupancyMap) against a naive reference written here in Python: OctoMap's
insertPointCloud with its key traversal (computeRayKeys) and its castRay step by step, in float32 and
float64 where OctoMap computes in each, and the log-odds of each voxel in a dict. Dimensions 2 and 3 (ray
casts: 3)."""

import math
import sys

import numpy as np
import pytest

import ktree
from test_ktree import run_json

CENTRE = 1 << 15
F32 = np.float32
F64_MAX = sys.float_info.max


def log_odds(p):
    return F32(math.log(p / (1.0 - p)))


class Reference:
    """An occupancy map as OctoMap computes it, one voxel and one float at a time."""

    def __init__(self, resolution, dim, hit=0.7, miss=0.4, clamp_min=0.1192, clamp_max=0.971, occupancy=0.5):
        self.res = float(resolution)
        self.factor = 1.0 / self.res
        self.dim = dim
        self.hit, self.miss = log_odds(hit), log_odds(miss)
        self.clamp_min, self.clamp_max = log_odds(clamp_min), log_odds(clamp_max)
        self.occupancy = log_odds(occupancy)
        self.voxels = {}  # key tuple -> float32 log-odds

    # Keys (OctoMap's coordToKeyChecked): floor(c / resolution) + 2**15, None outside 2**16 voxels.
    def key(self, c):
        scaled = math.floor(self.factor * float(c))
        if -CENTRE <= scaled < CENTRE:
            return scaled + CENTRE
        return None

    def keys(self, p):
        out = tuple(self.key(c) for c in p)
        return None if None in out else out

    def centre(self, k):
        return (float(k - CENTRE) + 0.5) * self.res

    @staticmethod
    def norm(v):
        # Squares summed in float32, the root in float64 (OctoMap's Vector3::norm).
        s = F32(0)
        for c in v:
            s = F32(s + c * c)
        return math.sqrt(float(s))

    def clipped_end(self, origin, end, max_range):
        d = end - origin
        length = self.norm(d)
        if length > 0:
            d = d / F32(length)
        return origin + d * F32(max_range)

    def ray(self, origin, end):
        """The keys computeRayKeys gives (origin's voxel first, end's voxel excluded), None if either
        point is outside the map."""
        key_origin, key_end = self.keys(origin), self.keys(end)
        if key_origin is None or key_end is None:
            return None
        if key_origin == key_end:
            return []
        out = [key_origin]
        direction = end - origin
        length = F32(self.norm(direction))
        direction = [F32(d / length) for d in direction]
        step = [0] * self.dim
        t_max = [F64_MAX] * self.dim
        t_delta = [F64_MAX] * self.dim
        for i in range(self.dim):
            if direction[i] > 0:
                step[i] = 1
            elif direction[i] < 0:
                step[i] = -1
            if step[i] != 0:
                border = self.centre(key_origin[i]) + float(F32(step[i] * self.res * 0.5))
                t_max[i] = (border - float(origin[i])) / float(direction[i])
                t_delta[i] = self.res / abs(float(direction[i]))
        key = list(key_origin)
        while True:
            # The smallest t_max, ties to the later axis (OctoMap's comparisons).
            axis = 0
            for i in range(1, self.dim):
                if t_max[i] <= t_max[axis]:
                    axis = i
            key[axis] = (key[axis] + step[axis]) & 0xFFFF
            t_max[axis] += t_delta[axis]
            if tuple(key) == key_end:
                break
            if min(t_max + [F64_MAX]) > float(length):
                break
            out.append(tuple(key))
        return out

    def update(self, key, hit):
        l = F32(self.voxels.get(key, F32(0)) + (self.hit if hit else self.miss))
        self.voxels[key] = min(max(l, self.clamp_min), self.clamp_max)

    def insert(self, points, origin, max_range=None):
        points = np.asarray(points, dtype=np.float32)
        origin = np.asarray(origin, dtype=np.float32)
        hits, misses = set(), set()
        for p in points:
            within = max_range is None or self.norm(p - origin) <= max_range
            end = p if within else self.clipped_end(origin, p, max_range)
            misses.update(self.ray(origin, end) or [])
            if within and self.keys(p) is not None:
                hits.add(self.keys(p))
        for k in misses - hits:
            self.update(k, False)
        for k in hits:
            self.update(k, True)
        return len(misses | hits)

    def cast(self, origin, direction, ignore_unknown=False, max_range=None):
        """OctoMap's castRay (3-D): (reason, key of the voxel where the ray ended or None), the reason as
        OccupancyMap.cast_rays codes it."""
        O = ktree.OccupancyMap
        origin = np.asarray(origin, dtype=np.float32)
        direction = np.asarray(direction, dtype=np.float32)
        key = self.keys(origin)
        if key is None:
            return O.OUTSIDE, None

        def stops(k):
            l = self.voxels.get(k)
            if l is None:
                return None if ignore_unknown else O.UNKNOWN
            return O.OCCUPIED if l >= self.occupancy else None

        reason = stops(key)
        if reason is not None:
            return reason, key
        # normalized(): the norm in float64, the division in float32.
        length = F32(self.norm(direction))
        d = [F32(c / length) for c in direction]
        step = [0] * 3
        t_max = [F64_MAX] * 3
        t_delta = [F64_MAX] * 3
        for i in range(3):
            step[i] = 1 if d[i] > 0 else -1 if d[i] < 0 else 0
            if step[i] != 0:
                border = self.centre(key[i]) + step[i] * self.res * 0.5
                t_max[i] = (border - float(origin[i])) / float(d[i])
                t_delta[i] = self.res / abs(float(d[i]))
        key = list(key)
        while True:
            if t_max[0] < t_max[1]:
                axis = 0 if t_max[0] < t_max[2] else 2
            else:
                axis = 1 if t_max[1] < t_max[2] else 2
            if (step[axis] < 0 and key[axis] == 0) or (step[axis] > 0 and key[axis] == 2 * CENTRE - 1):
                # OctoMap's end: the last voxel inside the map.
                return O.OUTSIDE, tuple(key)
            key[axis] += step[axis]
            t_max[axis] += t_delta[axis]
            k = tuple(key)
            if max_range is not None:
                # The voxel's centre as a float32 point, the squares in float32 summed in float64.
                sq = 0.0
                for j in range(3):
                    e = F32(F32(self.centre(k[j])) - origin[j])
                    sq += float(F32(e * e))
                if sq > max_range * max_range:
                    return O.BEYOND_RANGE, k
            reason = stops(k)
            if reason is not None:
                return reason, k

    def state(self, p):
        l = self.voxels.get(self.keys(np.asarray(p, dtype=np.float32)))
        if l is None:
            return ktree.OccupancyMap.UNKNOWN
        return ktree.OccupancyMap.OCCUPIED if l >= self.occupancy else ktree.OccupancyMap.FREE


def random_scan(rng, dim, resolution, n):
    """Points around the origin, some on voxel borders and on the sensor's axes (ties in the traversal),
    some in the sensor's voxel, one outside the map now and then."""
    points = rng.uniform(-3, 3, size=(n, dim))
    origin = rng.uniform(-1, 1, size=dim)
    if rng.random() < 0.5:
        origin = np.round(origin / resolution) * resolution
    for i in range(n):
        r = rng.random()
        if r < 0.2:
            points[i] = np.round(points[i] / resolution) * resolution
        elif r < 0.35:
            points[i, rng.integers(dim)] = origin[rng.integers(dim)]
        elif r < 0.4:
            points[i] = origin + rng.uniform(-0.3, 0.3, size=dim) * resolution
        elif r < 0.43:
            points[i, rng.integers(dim)] = 1e5 * resolution
    return points, origin


def check_against(m, ref, probes):
    """The map's log-odds, parts and states are the reference's."""
    dim = ref.dim
    keys = np.array(sorted(ref.voxels), dtype=np.int64).reshape(-1, dim)
    log = m.log_odds()
    assert log.dtype == "float32"
    assert log.voxel_count == len(ref.voxels)
    occupied = {k for k, l in ref.voxels.items() if l >= ref.occupancy}
    free = set(ref.voxels) - occupied
    occ_tree, free_tree, unknown_tree = m.occupied(), m.free(), m.unknown()
    assert occ_tree.voxel_count == len(occupied)
    assert free_tree.voxel_count == len(free)
    assert unknown_tree.voxel_count == 2 ** (16 * dim) - len(ref.voxels)
    if len(keys):
        lo = keys.min(axis=0)
        shape = keys.max(axis=0) - lo + 1
        expected = np.zeros(shape, np.float32)
        observed = np.zeros(shape, bool)
        expected_occupied = np.zeros(shape, bool)
        for k, l in ref.voxels.items():
            i = tuple(np.array(k) - lo)
            expected[i], observed[i] = l, True
            expected_occupied[i] = l >= ref.occupancy
        lo, shape = [int(x) for x in lo], [int(x) for x in shape]
        np.testing.assert_array_equal(log.to_dense(lo, shape).view(np.uint32), expected.view(np.uint32))
        np.testing.assert_array_equal(log.shape().to_dense(lo, shape), observed)
        np.testing.assert_array_equal(occ_tree.to_dense(lo, shape), expected_occupied)
        np.testing.assert_array_equal(free_tree.to_dense(lo, shape), observed & ~expected_occupied)
        np.testing.assert_array_equal(unknown_tree.to_dense(lo, shape), ~observed)
        # The log-odds at the voxels, read through the tree's values.
        np.testing.assert_array_equal(
            log.values(keys).view(np.uint32), np.array([ref.voxels[tuple(k)] for k in keys], np.float32).view(np.uint32)
        )
    # The three parts partition the map's universe.
    assert (occ_tree & free_tree).voxel_count == 0
    assert (occ_tree & unknown_tree).voxel_count == 0
    assert (free_tree & unknown_tree).voxel_count == 0
    assert occ_tree | free_tree | unknown_tree == ktree.Tree.full(dim, 16)
    assert log.shape() == ~unknown_tree
    # States and keys of points.
    probes = np.asarray(probes, dtype=np.float32)
    states = m.states(probes)
    assert states.dtype == np.uint8 and states.shape == (len(probes),)
    assert states.tolist() == [ref.state(p) for p in probes]
    got_keys = m.keys(probes)
    assert got_keys.dtype == np.int64 and got_keys.shape == (len(probes), dim)
    want_keys = [ref.keys(p) or (-1,) * dim for p in probes]
    assert got_keys.tolist() == [list(k) for k in want_keys]


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("seed", range(16))
def test_scans_against_reference(dim, seed):
    rng = np.random.default_rng(1000 * dim + seed)
    # Windows of up to (6 / resolution)**dim voxels are compared.
    fine = [0.05] if dim == 2 else []
    resolution = float(rng.choice(fine + [0.1, 0.25, 0.5, 1.0, rng.uniform(0.07, 0.6)]))
    max_range = None if seed % 2 == 0 else float(rng.uniform(0.5, 3.0))
    m = ktree.OccupancyMap(resolution, dim=dim)
    ref = Reference(resolution, dim)
    probes = [rng.uniform(-4, 4, size=(40, dim)), np.full((1, dim), 1e6)]
    for _ in range(int(rng.integers(1, 4))):
        points, origin = random_scan(rng, dim, resolution, int(rng.integers(0, 60)))
        # float64 in: converted to float32 by the map, as by the reference.
        assert m.insert(points, origin.tolist(), max_range=max_range) == ref.insert(points, origin, max_range)
        probes.append(points)
    check_against(m, ref, np.concatenate(probes))


@pytest.mark.parametrize("dim", [2, 3])
def test_repeated_scans_reach_the_clamps(dim):
    rng = np.random.default_rng(7 + dim)
    m = ktree.OccupancyMap(0.2, dim=dim)
    ref = Reference(0.2, dim)
    points, origin = random_scan(rng, dim, 0.2, 25)
    for _ in range(8):
        m.insert(points.astype(np.float32), origin, None)
        ref.insert(points, origin)
    values = set(ref.voxels.values())
    assert ref.clamp_max in values and ref.clamp_min in values
    check_against(m, ref, points)


@pytest.mark.parametrize("dim", [2, 3])
def test_other_sensor_model(dim):
    rng = np.random.default_rng(20 + dim)
    model = dict(prob_hit=0.9, prob_miss=0.2, clamp_min=0.3, clamp_max=0.99, occupancy=0.8)
    m = ktree.OccupancyMap(0.3, dim, **model)
    ref = Reference(0.3, dim, hit=0.9, miss=0.2, clamp_min=0.3, clamp_max=0.99, occupancy=0.8)
    probes = []
    for _ in range(3):
        points, origin = random_scan(rng, dim, 0.3, 20)
        m.insert(points, origin)
        ref.insert(points, origin)
        probes.append(points)
    check_against(m, ref, np.concatenate(probes))


def test_two_rays_in_a_plane():
    # Two rays from (0.05, 0.05): to (1.05, 0.05) along x and to (0.05, 0.55) along y.
    m = ktree.OccupancyMap(0.1, dim=2)
    assert m.insert(np.array([[1.05, 0.05], [0.05, 0.55]]), (0.05, 0.05)) == 2 + 10 + 5 - 1
    states = m.states(np.array([[1.05, 0.05], [0.55, 0.05], [-3.0, 2.0]]))
    assert states.tolist() == [ktree.OccupancyMap.OCCUPIED, ktree.OccupancyMap.FREE, ktree.OccupancyMap.UNKNOWN]
    assert m.occupied().voxel_count == 2
    assert m.free().voxel_count == 10 + 5 - 1
    c = CENTRE
    assert m.keys(np.array([[1.05, 0.05], [-0.05, 0.0]])).tolist() == [[c + 10, c], [c - 1, c]]
    assert m.occupied().contains(np.array([[c + 10, c], [c, c + 5]])).tolist() == [True, True]
    assert m.free().contains(np.array([[c + k, c] for k in range(10)])).all()


def test_max_range_cuts_rays():
    m = ktree.OccupancyMap(1.0, dim=2)
    # A point 10 voxels away seen with a range of 4: no hit, the misses of the ray cut at 4.
    assert m.insert(np.array([[10.5, 0.5]]), [0.5, 0.5], max_range=4.0) == 4
    c = CENTRE
    assert m.occupied().voxel_count == 0
    # Runs along the last axis (y): one voxel at each x of the ray.
    assert m.free() == ktree.Tree.from_rays(np.array([[c + i, c, c + 1] for i in range(4)]), 16)
    # A point within range is a hit.
    assert m.insert(np.array([[0.5, 3.5]]), [0.5, 0.5], max_range=4.0) == 4
    assert m.occupied().contains(np.array([[c, c + 3]])).tolist() == [True]
    # A range of 0 keeps only the points in the sensor's own place.
    m0 = ktree.OccupancyMap(1.0, dim=2)
    assert m0.insert(np.array([[5.5, 0.5], [0.5, 0.5]]), [0.5, 0.5], max_range=0.0) == 1
    assert m0.states(np.array([[0.5, 0.5]])).tolist() == [ktree.OccupancyMap.OCCUPIED]


@pytest.mark.parametrize("dim", [2, 3])
def test_max_range_boundary(dim):
    # A point exactly at max_range (its distance as OctoMap computes it: squares summed in float32) is a
    # hit; a point just beyond it is none.
    rng = np.random.default_rng(40 + dim)
    for _ in range(50):
        points, origin = random_scan(rng, dim, 0.1, 1)
        p, o = points.astype(np.float32)[0], origin.astype(np.float32)
        if np.abs(p).max() > 1000:
            continue  # outside the map
        distance = Reference.norm(p - o)
        at = ktree.OccupancyMap(0.1, dim)
        at.insert(p[None], o, max_range=distance)
        assert at.states(p[None]).tolist() == [ktree.OccupancyMap.OCCUPIED]
        if distance > 0:
            short = ktree.OccupancyMap(0.1, dim)
            short.insert(p[None], o, max_range=float(np.nextafter(distance, 0)))
            assert short.states(p[None]).tolist() != [ktree.OccupancyMap.OCCUPIED]


def test_rays_leaving_the_map_are_skipped():
    m = ktree.OccupancyMap(0.1, dim=3)
    # The map spans +-3276.8 here: a point beyond it updates nothing.
    assert m.insert(np.array([[4000.0, 0.0, 0.0]]), [0, 0, 0]) == 0
    assert m.unknown() == ktree.Tree.full(3, 16)
    # A sensor beyond it: no ray, but the point's voxel is a hit (as in OctoMap).
    assert m.insert(np.array([[1.05, 0.05, 0.05]]), [5000, 0, 0]) == 1
    c = CENTRE
    assert m.occupied() == ktree.Tree.from_rays(np.array([[c + 10, c, c, c + 1]]), 16)
    assert m.free().voxel_count == 0
    assert m.keys(np.array([[4000.0, 0.0, 0.0]])).tolist() == [[-1, -1, -1]]
    assert m.states(np.array([[np.nan, 0, 0]])).tolist() == [ktree.OccupancyMap.UNKNOWN]


def test_float32_and_float64_points_agree():
    rng = np.random.default_rng(5)
    points, origin = random_scan(rng, 3, 0.1, 30)
    a, b = ktree.OccupancyMap(0.1), ktree.OccupancyMap(0.1)
    a.insert(points, origin)
    b.insert(points.astype(np.float32), np.asarray(origin, np.float32))
    assert a.log_odds() == b.log_odds()
    # A non-contiguous view reads the same numbers.
    c = ktree.OccupancyMap(0.1)
    wide = np.zeros((len(points), 6))
    wide[:, ::2] = points
    c.insert(wide[:, ::2], origin)
    assert c.log_odds() == a.log_odds()


def test_parts_are_trees():
    rng = np.random.default_rng(11)
    m = ktree.OccupancyMap(0.25, dim=3)
    points, origin = random_scan(rng, 3, 0.25, 30)
    m.insert(points, origin)
    occupied = m.occupied()
    assert isinstance(occupied, ktree.Tree) and (occupied.k, occupied.level) == (3, 16)
    grown = occupied.dilate(1)
    assert (occupied - grown).voxel_count == 0 and grown.voxel_count > occupied.voxel_count
    assert m.free() | occupied == ~m.unknown()
    log = m.log_odds()
    assert (log.k, log.level, log.dtype) == (3, 16, "float32")
    # After one scan, the occupied voxels hold one hit's log-odds and the free ones one miss's.
    assert log.select(float(log_odds(0.7))) == occupied
    assert log.select(float(log_odds(0.4))) == m.free()


def test_properties_and_repr():
    m = ktree.OccupancyMap(0.05, dim=2)
    assert (m.resolution, m.dim) == (0.05, 2)
    assert ktree.OccupancyMap(0.1).dim == 3
    assert (ktree.OccupancyMap.UNKNOWN, ktree.OccupancyMap.FREE, ktree.OccupancyMap.OCCUPIED) == (0, 1, 2)
    text = repr(m)
    assert text.startswith("OccupancyMap(resolution=0.05, dim=2, prob_hit=0.7, prob_miss=0.4")
    assert "observed=0" in text
    # Ten voxels crossed along x, one hit.
    assert m.insert(np.array([[0.51, 0.01]]), [0.01, 0.01]) == 11
    assert "observed=11" in repr(m)


@pytest.mark.parametrize(
    "args, message",
    [
        ((0.0,), "resolution"),
        ((-1.0,), "resolution"),
        ((float("nan"),), "resolution"),
        ((float("inf"),), "resolution"),
        ((0.1, 4), "dimension"),
        ((0.1, 1), "dimension"),
        ((0.1, 3, 0.3), "hit"),
        ((0.1, 3, 0.7, 0.6), "miss"),
        ((0.1, 3, 1.0), "probabilit"),
        ((0.1, 3, 0.7, 0.4, 0.0), "probabilit"),
        ((0.1, 3, 0.7, 0.4, 0.9, 0.2), "clamp"),
        ((0.1, 3, 0.7, 0.4, 0.1192, 0.971, float("nan")), "probabilit"),
    ],
)
def test_bad_maps_are_value_errors(args, message):
    with pytest.raises(ValueError, match=message):
        ktree.OccupancyMap(*args)


def test_bad_scans_are_value_errors():
    m = ktree.OccupancyMap(0.1, dim=3)
    good = np.zeros((2, 3))
    for points in [np.zeros((2, 2)), np.zeros(3), np.zeros((2, 3, 1)), np.zeros((0, 4)), [[1, 2], [3]], "points"]:
        with pytest.raises(ValueError, match="points"):
            m.insert(points, [0, 0, 0])
    with pytest.raises(ValueError, match="point 1 .*not finite"):
        m.insert(np.array([[0.0, 0, 0], [np.nan, 0, 0]]), [0, 0, 0])
    with pytest.raises(ValueError, match="not finite"):
        m.insert(np.array([[np.inf, 0, 0]]), [0, 0, 0])
    with pytest.raises(ValueError, match="not finite"), np.errstate(over="ignore"):
        m.insert(np.array([[1e300, 0, 0]]), [0, 0, 0])  # beyond float32: inf
    with pytest.raises(ValueError, match="origin"):
        m.insert(good, [0, 0])
    with pytest.raises(ValueError, match="origin"):
        m.insert(good, [0, float("nan"), 0])
    for bad in [-1.0, float("nan")]:
        with pytest.raises(ValueError, match="max_range"):
            m.insert(good, [0, 0, 0], max_range=bad)
    for method in (m.states, m.keys):
        with pytest.raises(ValueError, match="points"):
            method(np.zeros((3, 2)))
    # Nothing was integrated by the calls that failed.
    assert m.unknown() == ktree.Tree.full(3, 16)
    # An empty scan is no error.
    assert m.insert(np.zeros((0, 3)), [0, 0, 0]) == 0


def test_save_and_load_through_octomaps_files(tmp_path):
    rng = np.random.default_rng(5)
    points = rng.uniform(-2.0, 2.0, size=(300, 3))
    m = ktree.OccupancyMap(0.1)
    m.insert(points, [0.05, 0.05, 0.05])
    m.save(tmp_path / "m.ot")
    back = ktree.OccupancyMap.load(tmp_path / "m.ot")
    assert back.resolution == 0.1
    assert back.log_odds() == m.log_odds()
    m.save(str(tmp_path / "m.bt"))
    ml = ktree.OccupancyMap.load(tmp_path / "m.bt")
    assert ml.occupied() == m.occupied()
    assert ml.free() == m.free()
    probes = rng.uniform(-2.5, 2.5, size=(500, 3))
    assert (ml.states(probes) == m.states(probes)).all()
    # A .ktree map keeps every log-odds and the resolution (its world frame).
    m.save(tmp_path / "m.ktree")
    mk = ktree.OccupancyMap.load(tmp_path / "m.ktree")
    assert mk.resolution == 0.1
    assert mk.log_odds() == m.log_odds()
    ktree.Tree.full(3, 4).save(tmp_path / "cube.ktree")
    with pytest.raises(ValueError, match="cube.ktree"):
        ktree.OccupancyMap.load(tmp_path / "cube.ktree")
    with pytest.raises(ValueError, match=r"\.ot, \.bt or \.ktree"):
        m.save(tmp_path / "m.png")
    with pytest.raises(ValueError, match="dimension 2"):
        ktree.OccupancyMap(0.1, dim=2).save(tmp_path / "flat.ot")
    (tmp_path / "bad.ot").write_bytes(b"# Octomap OcTree file\nid OcTree\nsize 3\nres 0.1\ndata\n")
    with pytest.raises(ValueError, match="bad.ot"):
        ktree.OccupancyMap.load(tmp_path / "bad.ot")
    with pytest.raises(OSError):
        ktree.OccupancyMap.load(tmp_path / "missing.ot")


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("seed", range(6))
def test_a_map_forgets_what_lies_outside_a_ball(dim, seed):
    rng = np.random.default_rng(500 + 10 * dim + seed)
    resolution = float(rng.choice([0.1, 0.25, 0.5]))
    m = ktree.OccupancyMap(resolution, dim=dim)
    ref = Reference(resolution, dim)
    for _ in range(2):
        points, origin = random_scan(rng, dim, resolution, 40)
        m.insert(points, origin.tolist())
        ref.insert(points, origin, None)
    centre, radius = rng.uniform(-2, 2, size=dim), float(rng.uniform(0.3, 3.0))
    m.forget_outside(centre.tolist(), radius)
    # The reference keeps the voxels whose centres are within the radius.
    ref.voxels = {
        k: l
        for k, l in ref.voxels.items()
        if sum((ref.centre(c) - centre[a]) ** 2 for a, c in enumerate(k)) <= radius * radius
    }
    check_against(m, ref, rng.uniform(-4, 4, size=(60, dim)))


def test_forgetting_refuses_bad_balls_and_maps_with_a_history():
    m = ktree.OccupancyMap(0.2)
    m.insert(np.array([[1.0, 0.0, 0.0]]), [0.0, 0.0, 0.0])
    m.set_colours(np.array([[1.0, 0.0, 0.0]]), np.array([[9, 9, 9]], dtype=np.uint8))
    for centre, radius, message in [([0.0, 0.0], 1.0, "3 coordinates"), ([0.0] * 3, -1.0, "radius"), ([math.nan] * 3, 1.0, "centre")]:
        with pytest.raises(ValueError, match=message):
            m.forget_outside(centre, radius)
    # The colours of the voxels forgotten go with them.
    m.forget_outside([0.0, 0.0, 0.0], 0.5)
    assert m.colours().voxel_count == 0 and m.occupied().voxel_count == 0
    with pytest.raises(ValueError, match="history"):
        ktree.OccupancyMap(0.2, history=True).forget_outside([0.0] * 3, 1.0)


def test_colours_are_means_of_points_and_kept_by_colour_octree_files(tmp_path):
    rng = np.random.default_rng(9)
    points = rng.uniform(-1.5, 1.5, size=(400, 3)).astype(np.float32)
    colours = rng.integers(0, 255, size=(400, 3), dtype=np.uint8)
    m = ktree.OccupancyMap(0.2)
    assert m.colours() is None
    m.insert(points, [0.05, 0.05, 0.05])
    # A point in an unknown voxel colours nothing.
    far = np.array([[50.0, 50.0, 50.0]], dtype=np.float32)
    assert m.states(far)[0] == ktree.OccupancyMap.UNKNOWN
    count = m.set_colours(np.vstack([points, far]), np.vstack([colours, [[1, 2, 3]]]).astype(np.uint8))
    groups = {}
    for key, colour in zip(map(tuple, m.keys(points)), colours):
        groups.setdefault(key, []).append(colour.astype(np.int64))
    assert count == len(groups)
    tree = m.colours()
    assert tree.dtype == "rgb8" and tree.voxel_count == len(groups)
    keys = np.array(list(groups), dtype=np.int64)
    # The mean of each channel, rounded half up.
    expected = np.array([np.floor(np.mean(g, axis=0) + 0.5) for g in groups.values()], dtype=np.uint8)
    assert (tree.values(keys) == expected).all()
    # A second colouring replaces the colours of the voxels it colours and keeps the others'.
    m.set_colours(points[:1], np.array([[7, 8, 9]], dtype=np.uint8))
    again = m.colours().values(keys)
    first = tuple(m.keys(points[:1])[0])
    for key, colour, before in zip(map(tuple, keys), again, expected):
        assert tuple(colour) == ((7, 8, 9) if key == first else tuple(before))
    # Saved as a ColorOcTree and read back with the same log-odds and colours; an OcTree has none.
    m.save(tmp_path / "coloured.ot")
    back = ktree.OccupancyMap.load(tmp_path / "coloured.ot")
    assert back.log_odds() == m.log_odds()
    assert back.colours() == m.colours()
    assert b"id ColorOcTree" in (tmp_path / "coloured.ot").read_bytes()[:200]
    plain = ktree.OccupancyMap(0.2)
    plain.insert(points, [0.05, 0.05, 0.05])
    plain.save(tmp_path / "plain.ot")
    assert ktree.OccupancyMap.load(tmp_path / "plain.ot").colours() is None
    with pytest.raises(ValueError, match="a colour for each point"):
        m.set_colours(points, colours[:10])
    with pytest.raises(ValueError, match="3-D maps"):
        ktree.OccupancyMap(0.2, dim=2).set_colours(points[:, :2], colours)


def test_a_history_gives_each_steps_states_and_separates_what_moved(tmp_path):
    m = ktree.OccupancyMap(0.1, history=True)
    origin = [0.05, 0.05, 0.05]
    wall = [[1.05, 0.1 * y + 0.05, 0.05] for y in range(-3, 4)]
    person = [[0.55, 0.05, 0.05]]
    probes = np.array(wall + person + [[0.35, 0.05, 0.05], [-2.0, 0.0, 0.0]])
    seen = []
    for t in range(6):
        m.insert(np.array(person if t == 0 else wall), origin)
        seen.append(m.states(probes))
    h = m.history()
    assert h.steps == 6
    keys = m.keys(probes)
    for t, states in enumerate(seen):
        assert np.array_equal(h.at(t).values(keys, background=0), states)
    # Only the scans' points are ever occupied, and all of them are probes.
    occupied = np.any(np.array(seen) == ktree.OccupancyMap.OCCUPIED, axis=0)
    free = np.any(np.array(seen) == ktree.OccupancyMap.FREE, axis=0)
    moved, still = h.moved(), h.static_map()
    assert np.array_equal(moved.contains(keys), occupied & free)
    assert np.array_equal(still.contains(keys), occupied & ~free)
    assert moved.voxel_count == 1 and still.voxel_count == len(wall)
    assert h.dynamic().k == 4 and h.tree.k == 4
    h.save(tmp_path / "history.ktree")
    assert ktree.Tree.load(tmp_path / "history.ktree") == h.tree
    # Read back with its steps (nothing changed after step 1, yet all 6 are kept) and resolution.
    back = ktree.MapHistory.load(tmp_path / "history.ktree")
    assert back == h and back.steps == 6 and back.resolution == 0.1
    assert back.at(5) == h.at(5)
    m.save(tmp_path / "map.ktree")
    with pytest.raises(ValueError, match="map.ktree"):
        ktree.MapHistory.load(tmp_path / "map.ktree")
    with pytest.raises(ValueError, match="step 6"):
        h.at(6)


def test_a_history_needs_a_3d_map_made_to_keep_it():
    with pytest.raises(ValueError, match="history=True"):
        ktree.OccupancyMap(0.1).history()
    with pytest.raises(ValueError, match="3-D"):
        ktree.OccupancyMap(0.1, dim=2, history=True)
# --- ray casts (OctoMap's castRay) ---------------------------------------------------------------------


def cast_map(seed, resolution):
    """A 3-D map and its reference after a few random scans, and rays to cast on it: origins and directions
    with voxel borders, shared axes, zero components and exact diagonals among them (ties in the
    traversal)."""
    rng = np.random.default_rng(seed)
    m = ktree.OccupancyMap(resolution)
    ref = Reference(resolution, 3)
    for _ in range(3):
        points, origin = random_scan(rng, 3, resolution, 60)
        m.insert(points, origin)
        ref.insert(points, origin)
    n = 120
    origins = rng.uniform(-1.5, 1.5, size=(n, 3))
    directions = rng.normal(size=(n, 3))
    for i in range(n):
        r = rng.random()
        if r < 0.2:
            origins[i] = np.round(origins[i] / resolution) * resolution
        elif r < 0.3:
            origins[i] = (np.floor(origins[i] / resolution) + 0.5) * resolution
        r = rng.random()
        if r < 0.15:
            directions[i, rng.integers(3)] = 0.0
        elif r < 0.25:
            directions[i] = 0.0
            directions[i, rng.integers(3)] = rng.choice([-1.0, 1.0]) * rng.uniform(0.1, 10)
        elif r < 0.35:
            directions[i] = rng.choice([-1.0, 1.0], size=3)
    return m, ref, origins, directions


def check_casts(m, ref, origins, directions, ignore_unknown, max_range):
    got = m.cast_rays(origins, directions, ignore_unknown=ignore_unknown, max_range=max_range)
    assert isinstance(got, ktree.MapRayHits) and got._fields == ("hit", "end", "key", "reason")
    n = len(directions)
    assert got.hit.dtype == np.bool_ and got.hit.shape == (n,)
    assert got.end.dtype == np.float64 and got.end.shape == (n, 3)
    assert got.key.dtype == np.int64 and got.key.shape == (n, 3)
    assert got.reason.dtype == np.uint8 and got.reason.shape == (n,)
    origins = np.broadcast_to(origins, (n, 3))
    reasons = []
    for i in range(n):
        reason, key = ref.cast(origins[i], directions[i], ignore_unknown, max_range)
        reasons.append(reason)
        assert got.reason[i] == reason, i
        assert got.hit[i] == (reason == ktree.OccupancyMap.OCCUPIED)
        if key is None:
            assert got.key[i].tolist() == [-1, -1, -1]
            assert np.isnan(got.end[i]).all()
        else:
            assert tuple(got.key[i]) == key, i
            assert got.end[i].tolist() == [ref.centre(k) for k in key]
    return reasons


@pytest.mark.parametrize("seed", range(6))
def test_cast_rays_against_reference(seed):
    resolution = [0.1, 0.25, 0.5, 0.17][seed % 4]
    m, ref, origins, directions = cast_map(300 + seed, resolution)
    seen = set()
    seen.update(check_casts(m, ref, origins, directions, False, None))
    seen.update(check_casts(m, ref, origins, directions, False, 1.0))
    # Through unknown voxels, within a range (a ray to the map's edge is tens of thousands of voxels).
    seen.update(check_casts(m, ref, origins, directions, True, 2.5))
    seen.update(check_casts(m, ref, origins, directions.astype(np.float32), True, float(resolution)))
    O = ktree.OccupancyMap
    assert {O.OCCUPIED, O.UNKNOWN, O.BEYOND_RANGE} <= seen


def test_cast_rays_one_origin_for_all_rays():
    m, ref, origins, directions = cast_map(7, 0.25)
    one = m.cast_rays(origins[0], directions, max_range=3.0)
    each = m.cast_rays(np.repeat(origins[:1], len(directions), axis=0), directions, max_range=3.0)
    for a, b in zip(one, each):
        np.testing.assert_array_equal(a, b)
    check_casts(m, ref, origins[0], directions, True, 3.0)
    # One direction for all origins, and a single ray.
    along = m.cast_rays(origins, [1.0, 0.0, 0.0], ignore_unknown=True, max_range=2.0)
    assert along.reason.shape == (len(origins),)
    single = m.cast_rays(origins[0], directions[0])
    assert single.key.shape == (1, 3) and single.reason.shape == (1,)
    assert m.cast_rays(np.zeros((0, 3)), np.zeros((0, 3))).key.shape == (0, 3)


def test_cast_rays_named_cases():
    O = ktree.OccupancyMap
    m = O(0.1)
    # A wall at x = 2.05 seen from the origin's voxel along x; beside it, free voxels, then unknown ones.
    m.insert(np.array([[2.05, 0.05, 0.05], [2.05, 0.15, 0.05]]), [0.05, 0.05, 0.05])
    c = CENTRE
    got = m.cast_rays(
        [[0.05, 0.05, 0.05], [0.05, 0.05, 0.05], [1.05, 0.05, 0.05], [2.05, 0.05, 0.05], [0.05, 0.05, 0.05]],
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
        max_range=None,
    )
    assert got.reason.tolist() == [O.OCCUPIED, O.UNKNOWN, O.UNKNOWN, O.OCCUPIED, O.OCCUPIED]
    assert got.hit.tolist() == [True, False, False, True, True]
    assert got.key[0].tolist() == [c + 20, c, c]
    np.testing.assert_allclose(got.end[0], [2.05, 0.05, 0.05], rtol=0, atol=1e-12)
    # Along -x from x = 1.05 the free voxels end at the sensor's: the next one is unknown.
    assert got.key[2].tolist() == [c - 1, c, c]
    # A range of 0.95: the first voxel whose centre is beyond it, 1 away.
    short = m.cast_rays([0.05, 0.05, 0.05], [1.0, 0.0, 0.0], max_range=0.95)
    assert short.reason.tolist() == [O.BEYOND_RANGE] and short.key.tolist() == [[c + 10, c, c]]
    # Passing through unknown voxels up the y axis to the map's edge; from outside the map.
    edge = m.cast_rays([[0.05, 0.05, 0.05], [4000.0, 0, 0], [3276.75, 0.05, 0.05]], [0.0, 1.0, 0.0], True)
    assert edge.reason.tolist() == [O.OUTSIDE, O.OUTSIDE, O.OUTSIDE]
    assert not edge.hit.any()
    # Where a ray leaves the map its end is the last voxel inside (OctoMap's end); from outside, none.
    assert edge.key.tolist() == [[c, 2 * c - 1, c], [-1, -1, -1], [2 * c - 1, 2 * c - 1, c]]
    np.testing.assert_allclose(edge.end[0], [0.05, 3276.75, 0.05], rtol=0, atol=1e-9)
    assert np.isnan(edge.end[1]).all()
    # A ray from the last voxel along x leaves the map at once; unknown voxels stop it otherwise.
    last = m.cast_rays([3276.75, 0.05, 0.05], [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])
    assert last.reason.tolist() == [O.UNKNOWN, O.UNKNOWN]
    assert last.key.tolist() == [[2 * c - 1, c, c]] * 2


def test_cast_rays_bad_input_is_value_error():
    m = ktree.OccupancyMap(0.1)
    m.insert(np.array([[1.0, 0, 0]]), [0, 0, 0])
    good = np.ones((2, 3))
    cases = [
        (dict(origins=np.zeros((2, 2)), directions=good), "origins"),
        (dict(origins=good, directions=np.zeros((2, 3, 1))), "directions"),
        (dict(origins=np.zeros(2), directions=good), "origins"),
        (dict(origins="here", directions=good), "origins"),
        (dict(origins=np.zeros((3, 3)), directions=good), "3 origins and 2 directions"),
        (dict(origins=[[0, 0, 0], [np.nan, 0, 0]], directions=good), "origin of ray 1 .*not finite"),
        (dict(origins=good, directions=[[1, 0, 0], [0, np.inf, 0]]), "direction of ray 1 .*not finite"),
        (dict(origins=good, directions=[[1, 0, 0], [0, 0, 0]]), "direction of ray 1, .*no length"),
        (dict(origins=good, directions=[1e-30, 0, 0]), "direction of ray 0, .*no length"),
        (dict(origins=good, directions=good, max_range=-1.0), "max_range"),
        (dict(origins=good, directions=good, max_range=0.0), "max_range"),
        (dict(origins=good, directions=good, max_range=float("nan")), "max_range"),
    ]
    for kwargs, message in cases:
        with pytest.raises(ValueError, match=message):
            m.cast_rays(**kwargs)
    with pytest.raises(ValueError, match="dimension 2"):
        ktree.OccupancyMap(0.1, dim=2).cast_rays([0, 0], [1, 0])


def test_cast_rays_agree_with_the_cli(tmp_path):
    m, ref, origins, directions = cast_map(11, 0.1)
    m.save(tmp_path / "m.ot")
    rays = tmp_path / "rays.csv"
    np.savetxt(rays, np.hstack([origins, directions]).astype(np.float32), delimiter=",", fmt="%.9g")
    names = {"occupied": 2, "unknown": 0, "range": 3, "outside": 4}
    for flags, ignore, max_range in [([], False, None), (["--ignore-unknown", "--max-range", "2"], True, 2.0)]:
        answer = run_json("raycast", tmp_path / "m.ot", "--rays", rays, *flags)
        got = m.cast_rays(origins, directions, ignore_unknown=ignore, max_range=max_range)
        assert [names[a["end"]] for a in answer] == got.reason.tolist()
        assert [a["key"] or [-1, -1, -1] for a in answer] == got.key.tolist()
        points = np.array([a["point"] or [math.nan] * 3 for a in answer], dtype=np.float64)
        np.testing.assert_array_equal(points, got.end)
