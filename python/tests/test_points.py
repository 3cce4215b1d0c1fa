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
