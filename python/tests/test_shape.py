"""Shape operations checked against scipy.ndimage (binary_dilation, binary_erosion with border_value=0,
label) and scikit-image (measure.euler_number) on random arrays for K = 1...4 and on held data (the CT
skull, a voxelized mesh)."""

import itertools
from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage
from skimage import measure

import ktree


def universe(t):
    """The whole universe of `t` as a dense array (`to_dense()` alone gives the bounding box)."""
    return t.to_dense((0,) * t.k, (t.side,) * t.k)

ROOT = Path(__file__).resolve().parents[2]
LEVELS = {1: 5, 2: 4, 3: 3, 4: 2}
SHAPES = ["ball", "box", "cross"]
RADII = [0.0, 0.5, 1.0, 1.5, 2 ** 0.5, 2.0, 2.5]


def structure(k, r, shape):
    """The element of radius r as a boolean array of side 2*floor(r) + 1 (scipy's structure)."""
    e = int(np.floor(r))
    d = np.indices((2 * e + 1,) * k) - e
    if shape == "ball":
        return (d**2).sum(axis=0) <= r * r
    if shape == "box":
        return np.abs(d).max(axis=0) <= r
    return np.abs(d).sum(axis=0) <= r


def random_array(rng, k, level):
    side = 2**level
    a = rng.random((side,) * k) < 0.25
    for _ in range(2):
        lo = rng.integers(0, side, size=k)
        hi = lo + rng.integers(1, side + 1, size=k)
        a[tuple(slice(l, h) for l, h in zip(lo, hi))] = True
    return a


def closing_ref(a, s, r):
    """scipy's closing in an array padded by more than the reach, cropped back."""
    m = int(np.floor(r)) + 1
    p = np.pad(a, m)
    c = ndimage.binary_erosion(ndimage.binary_dilation(p, s), s, border_value=0)
    return c[tuple(slice(m, m + n) for n in a.shape)]


@pytest.fixture
def rng():
    return np.random.default_rng(20)


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_morphology_matches_scipy(rng, k):
    for _ in range(4):
        a = random_array(rng, k, LEVELS[k])
        t = ktree.Tree.from_dense(a)
        for shape, r in itertools.product(SHAPES, RADII):
            s = structure(k, r, shape)
            dil = ndimage.binary_dilation(a, s)
            ero = ndimage.binary_erosion(a, s, border_value=0)
            np.testing.assert_array_equal(universe(t.dilate(r, shape)), dil, f"{shape} {r}")
            np.testing.assert_array_equal(universe(t.erode(r, shape)), ero, f"{shape} {r}")
            np.testing.assert_array_equal(
                universe(t.opening(r, shape)), ndimage.binary_dilation(ero, s), f"{shape} {r}"
            )
            np.testing.assert_array_equal(universe(t.closing(r, shape)), closing_ref(a, s, r))
    assert t.dilate(1.5) == t.dilate(1.5, "ball")


def test_bad_arguments_are_value_errors():
    t = ktree.Tree.full(2, 3)
    with pytest.raises(ValueError, match="radius"):
        t.dilate(-1.0)
    with pytest.raises(ValueError, match="radius"):
        t.erode(float("nan"))
    with pytest.raises(ValueError, match="star"):
        t.opening(1.0, "star")
    with pytest.raises(ValueError, match="connectivity"):
        t.components(3)
    with pytest.raises(ValueError, match="connectivity"):
        ktree.Tree.full(3, 2).euler_number(2)


def check_components(a, t):
    k = a.ndim
    for c in range(1, k + 1):
        labels, n = ndimage.label(a, ndimage.generate_binary_structure(k, c))
        parts = t.components(c)
        assert len(parts) == n
        sizes = [p.voxel_count for p in parts]
        assert sizes == sorted(sizes, reverse=True)
        expect = sorted((labels == i).tobytes() for i in range(1, n + 1))
        assert sorted(universe(p).tobytes() for p in parts) == expect
        if n:
            assert t.largest_component(c).voxel_count == sizes[0]
        else:
            assert t.largest_component(c).voxel_count == 0


def surface_ref(a):
    p = np.pad(a, 1).astype(np.int8)
    return int(sum(np.abs(np.diff(p, axis=i)).sum() for i in range(a.ndim)))


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_components_and_surface_match_scipy(rng, k):
    for _ in range(6):
        a = random_array(rng, k, LEVELS[k])
        t = ktree.Tree.from_dense(a)
        check_components(a, t)
        assert t.surface_area() == surface_ref(a)
        assert t.stats()["surface_area"] == surface_ref(a)


@pytest.mark.parametrize("k", [2, 3])
def test_euler_number_matches_scikit_image(rng, k):
    for _ in range(8):
        a = random_array(rng, k, LEVELS[k] + 1)
        t = ktree.Tree.from_dense(a)
        for c in (1, k):
            assert t.euler_number(c) == measure.euler_number(a, connectivity=c), c
        assert t.euler_number() == measure.euler_number(a)
        assert t.stats()["euler_number"] == measure.euler_number(a)
        assert t.mass()["euler_number"] == measure.euler_number(a)


def test_held_data_skull_and_mesh():
    skull = ktree.Tree.from_volume(ROOT / "data/volumes/skull_grey.json", 29000)
    a = universe(skull)
    assert a.any()
    ball = structure(3, 2.0, "ball")
    np.testing.assert_array_equal(universe(skull.dilate(2.0)), ndimage.binary_dilation(a, ball))
    np.testing.assert_array_equal(
        universe(skull.erode(1.0, "cross")),
        ndimage.binary_erosion(a, structure(3, 1.0, "cross"), border_value=0),
    )
    check_components(a, skull)
    assert skull.surface_area() == surface_ref(a)
    for c in (1, 3):
        assert skull.euler_number(c) == measure.euler_number(a, connectivity=c)
    bunny = ktree.Tree.from_mesh(ROOT / "data/meshes/bunny_npm.obj", 5)
    b = universe(bunny)
    np.testing.assert_array_equal(
        universe(bunny.closing(1.5, "box")), closing_ref(b, structure(3, 1.5, "box"), 1.5)
    )
    assert bunny.euler_number(3) == measure.euler_number(b, connectivity=3)
    assert len(bunny.components(1)) == ndimage.label(b)[1]


def signed_distance_ref(a):
    """scipy's signed distance of a whole universe: + to the nearest full voxel, - to the nearest empty."""
    inf = np.full(a.shape, np.inf)
    out = ndimage.distance_transform_edt(~a) if a.any() else inf
    inside = ndimage.distance_transform_edt(a) if (~a).any() else inf
    return np.where(a, -inside, out).astype(np.float32)


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_signed_distance_matches_scipy(rng, k):
    for _ in range(3):
        a = random_array(rng, k, LEVELS[k])
        t = ktree.Tree.from_dense(a)
        sd = t.signed_distance((0,) * k, (t.side,) * k)
        assert sd.dtype == np.float32 and sd.shape == a.shape
        np.testing.assert_array_equal(sd, signed_distance_ref(a))
        # A window sees the whole tree: it equals the universe's values there.
        lo = rng.integers(0, t.side, size=k)
        n = rng.integers(0, t.side - lo + 1)
        w = t.signed_distance(tuple(int(x) for x in lo), tuple(int(x) for x in n))
        np.testing.assert_array_equal(w, sd[tuple(slice(l, l + m) for l, m in zip(lo, n))])
        # The default window is the bounding box.
        lo, hi = t.bounding_box()
        np.testing.assert_array_equal(
            t.signed_distance(), sd[tuple(slice(l, h) for l, h in zip(lo, hi))]
        )


def test_signed_distance_held_data():
    skull = ktree.Tree.from_volume(ROOT / "data/volumes/skull_grey.json", 29000)
    a = universe(skull)
    np.testing.assert_array_equal(
        skull.signed_distance((0,) * 3, (skull.side,) * 3), signed_distance_ref(a)
    )
    bunny = ktree.Tree.from_mesh(ROOT / "data/meshes/bunny_npm.obj", 6)
    b = universe(bunny)
    np.testing.assert_array_equal(
        bunny.signed_distance((0,) * 3, (bunny.side,) * 3), signed_distance_ref(b)
    )
    with pytest.raises(ValueError):
        bunny.signed_distance((-1, 0, 0), (2, 2, 2))
    with pytest.raises(ValueError):
        bunny.signed_distance((0, 0), (2, 2))
