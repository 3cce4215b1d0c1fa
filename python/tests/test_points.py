"""Tree.from_points against numpy: the voxels are np.unique(np.floor((p - origin) / s)), the origin by default
the points' minimum corner and the level the smallest holding every voxel."""

import numpy as np
import pytest

import ktree


def reference(points, s, origin):
    """The floored voxel keys of the points, one row each, and the smallest level holding them."""
    keys = np.unique(np.floor((points - origin) / s).astype(np.int64), axis=0)
    level = int(np.ceil(np.log2(keys.max() + 1))) if keys.size and keys.max() > 0 else 0
    return keys, level


def voxels(t):
    """The tree's full voxels as sorted rows."""
    dense = t.to_dense((0, 0, 0), (t.side,) * 3)
    return np.argwhere(dense)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("s", [0.1, 0.5, 1.0, 2.5])
def test_from_points_equals_numpy_floor(seed, s):
    rng = np.random.default_rng(seed)
    points = rng.normal(scale=3.0, size=(int(rng.integers(1, 400)), 3)) + rng.normal(size=3) * 10
    origin = points.min(axis=0)
    keys, level = reference(points, s, origin)
    if level > 8:  # keep the dense comparison small
        pytest.skip("universe too large for a dense check")
    t = ktree.Tree.from_points(points, s)
    assert (t.k, t.level) == (3, level)
    assert t.voxel_count == len(keys)
    np.testing.assert_array_equal(voxels(t), keys)
    # A given origin and level.
    below = origin - np.array([1.0, 2.0, 3.0]) * s
    keys, level = reference(points, s, below)
    t = ktree.Tree.from_points(points, s, origin=tuple(below), level=max(level, 1))
    np.testing.assert_array_equal(voxels(t), keys)


def test_from_points_errors():
    p = np.array([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="outside the universe") as e:
        ktree.Tree.from_points(p, 1.0, origin=(0.0, 0.0, 0.0), level=2)
    # The advice names what a Python caller can change, not the command line's flags.
    assert str(e.value).endswith(": use a larger level or voxel_size, or another origin")
    assert "--" not in str(e.value)
    with pytest.raises(ValueError, match="below the origin") as e:
        ktree.Tree.from_points(p, 1.0, origin=(1.0, 0.0, 0.0))
    assert "another origin" in str(e.value) and "--" not in str(e.value)
    with pytest.raises(ValueError, match="not finite"):
        ktree.Tree.from_points(np.array([[0.0, np.nan, 0.0]]), 1.0)
    with pytest.raises(ValueError, match="voxel size"):
        ktree.Tree.from_points(p, 0.0)
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        ktree.Tree.from_points(np.zeros((4, 2)), 1.0)


def groups(points, s, origin):
    """The voxel keys of the points (unique rows) and, for each point, the index of its voxel."""
    keys = np.floor((points - origin) / s).astype(np.int64)
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    return unique, inverse.reshape(-1)


@pytest.mark.parametrize("seed", range(4))
def test_from_points_with_values_reduces_each_voxels_points_as_numpy(seed):
    rng = np.random.default_rng(seed)
    n = 600
    points = rng.uniform(0.0, 6.0, size=(n, 3))
    s = 1.0
    keys, of = groups(points, s, points.min(axis=0))
    members = [of == g for g in range(len(keys))]
    floats = rng.normal(size=n)
    for reduce, fn in [("max", np.max), ("min", np.min), ("mean", np.mean)]:
        t = ktree.Tree.from_points(points, s, values=floats, reduce=reduce)
        assert t.dtype == "float32" and t.voxel_count == len(keys)
        want = np.array([fn(floats[m]) for m in members]).astype(np.float32)
        if reduce == "mean":  # summed in another order than numpy's pairwise sum
            np.testing.assert_allclose(t.values(keys), want, rtol=1e-6)
        else:
            np.testing.assert_array_equal(t.values(keys), want)
    labels = rng.integers(0, 5, size=n).astype(np.uint8)
    t = ktree.Tree.from_points(points, s, values=labels, reduce="mode")
    assert t.dtype == "uint8"
    # np.argmax takes the first of equal counts: the smallest label, as ktree does.
    want = np.array([np.argmax(np.bincount(labels[m], minlength=5)) for m in members])
    np.testing.assert_array_equal(t.values(keys), want)
    wide = labels.astype(np.int64) * 1000
    t = ktree.Tree.from_points(points, s, values=wide, reduce="mean")
    assert t.dtype == "uint16"
    want = np.floor(np.array([wide[m].mean() for m in members]) + 0.5)
    np.testing.assert_array_equal(t.values(keys), want)
    colours = rng.integers(0, 256, size=(n, 3)).astype(np.uint8)
    t = ktree.Tree.from_points(points, s, values=colours)
    assert t.dtype == "rgb8"
    want = np.floor(np.array([colours[m].mean(axis=0) for m in members]) + 0.5)
    np.testing.assert_array_equal(t.values(keys), want)
    t = ktree.Tree.from_points(points, s, reduce="count")
    assert t.dtype == "uint32"
    np.testing.assert_array_equal(t.values(keys), np.bincount(of))
    # The voxels are those of the points without values.
    assert t.shape() == ktree.Tree.from_points(points, s)


def test_from_points_with_bad_values_is_an_error():
    p = np.array([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="reduce"):
        ktree.Tree.from_points(p, 1.0, values=[1.0, 2.0], reduce="median")
    with pytest.raises(ValueError, match="shape"):
        ktree.Tree.from_points(p, 1.0, values=[1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="NaN"):
        ktree.Tree.from_points(p, 1.0, values=[1.0, np.nan])
    with pytest.raises(ValueError, match="needs values"):
        ktree.Tree.from_points(p, 1.0, reduce="max")
    with pytest.raises(ValueError, match="colours"):
        ktree.Tree.from_points(p, 1.0, values=np.zeros((2, 3), np.uint8), reduce="max")
