"""Trees with values against numpy and scipy.ndimage, K = 1..4, every dtype."""

import pickle
import subprocess

import numpy as np
import pytest
from scipy import ndimage

import ktree

DTYPES = ["uint8", "uint16", "uint32", "int8", "float32"]


def random_labels(rng, k, dtype, side=8):
    shape = tuple(int(rng.integers(1, side + 1)) for _ in range(k))
    a = rng.integers(0, 4, size=shape).astype(dtype)
    if dtype == "float32":
        a = (a * 0.25).astype(np.float32)
    return a


@pytest.mark.parametrize("k", [1, 2, 3, 4])
@pytest.mark.parametrize("dtype", DTYPES)
def test_dense_round_trip_and_values(k, dtype):
    rng = np.random.default_rng(k * 10 + DTYPES.index(dtype))
    side = 5 if k == 4 else 8
    for _ in range(3):
        a = random_labels(rng, k, dtype, side)
        t = ktree.Tree.from_dense(a)
        assert t.dtype == dtype
        assert t.voxel_count == int(np.count_nonzero(a))
        whole = t.to_dense((0,) * k, a.shape)
        assert whole.dtype == np.dtype(dtype)
        np.testing.assert_array_equal(whole, a)
        points = np.argwhere(np.ones(a.shape, bool))
        np.testing.assert_array_equal(t.values(points), a[tuple(points.T)])
        # The shape is the non-background voxels, as a tree without values.
        assert t.shape().dtype is None
        np.testing.assert_array_equal(t.shape().to_dense((0,) * k, a.shape), a != 0)
        # Another background.
        b = ktree.Tree.from_dense(a, background=1)
        assert b.voxel_count == int(np.count_nonzero(a != 1))
        np.testing.assert_array_equal(b.to_dense((0,) * k, a.shape), a)
        np.testing.assert_array_equal(b.to_dense((0,) * k, a.shape, background=3), np.where(a == 1, 3, a))


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_value_stats_against_scipy(k):
    rng = np.random.default_rng(100 + k)
    a = rng.integers(0, 4, size=(5,) * k).astype(np.uint16)
    stats = ktree.Tree.from_dense(a).value_stats()
    labels = [v for v in np.unique(a) if v != 0]
    assert sorted(stats) == [int(v) for v in labels]
    counts = ndimage.labeled_comprehension(a, a, labels, np.size, int, 0)
    centres = ndimage.center_of_mass(np.ones_like(a), a, labels)
    boxes = ndimage.find_objects(a.astype(np.int64))
    for value, count, centre in zip(labels, counts, centres):
        s = stats[int(value)]
        assert s["voxels"] == count
        np.testing.assert_allclose(s["centroid"], np.array(centre) + 0.5)
        box = boxes[int(value) - 1]
        assert list(s["bounding_box"][0]) == [sl.start for sl in box]
        assert list(s["bounding_box"][1]) == [sl.stop for sl in box]
        # Faces between the value's voxels and any other (or outside).
        m = np.pad(a == value, 1)
        faces = sum(int(np.count_nonzero(np.diff(m.astype(np.int8), axis=ax))) for ax in range(k))
        assert s["surface_area"] == faces


@pytest.mark.parametrize("k", [1, 2, 3])
def test_operations_against_numpy(k):
    rng = np.random.default_rng(7 + k)
    a = rng.integers(0, 5, size=(8,) * k).astype(np.uint8)
    b = rng.integers(0, 5, size=(8,) * k).astype(np.uint8)
    ta, tb = ktree.Tree.from_dense(a), ktree.Tree.from_dense(b)
    o = (0,) * k
    np.testing.assert_array_equal(ta.select(2).to_dense(o, a.shape), a == 2)
    np.testing.assert_array_equal(ta.select(2, 3).to_dense(o, a.shape), (a >= 2) & (a <= 3))
    np.testing.assert_array_equal(ta.mask(tb).to_dense(o, a.shape), np.where(b != 0, a, 0))
    np.testing.assert_array_equal(ta.mask(tb.shape()).to_dense(o, a.shape), np.where(b != 0, a, 0))
    np.testing.assert_array_equal(ta.overlay(tb).to_dense(o, a.shape), np.where(b != 0, b, a))
    both = (a != 0) & (b != 0)
    for rule, f in [("first", lambda x, y: x), ("min", np.minimum), ("max", np.maximum),
                    ("sum", lambda x, y: np.minimum(x.astype(int) + y, 255).astype(np.uint8))]:
        expect = np.where(both, f(a, b), np.where(a != 0, a, b))
        np.testing.assert_array_equal(ta.combine(tb, rule).to_dense(o, a.shape), expect)
    relabelled = ta.relabel({1: 9, 2: None})
    np.testing.assert_array_equal(relabelled.to_dense(o, a.shape), np.where(a == 1, 9, np.where(a == 2, 0, a)))
    # Binary methods work on the shape.
    np.testing.assert_array_equal((ta | tb).to_dense(o, a.shape), (a != 0) | (b != 0))


def test_conversions_and_errors():
    t = ktree.Tree.from_dense(np.array([0, 300, 5], dtype=np.int64))
    assert t.dtype == "uint16"
    assert ktree.Tree.from_dense(np.array([0, -3, 5], dtype=np.int32)).dtype == "int8"
    assert ktree.Tree.from_dense(np.array([0.5, 0.0])).dtype == "float32"
    assert ktree.Tree.from_dense(np.array([True, False])).dtype is None
    with pytest.raises(ValueError, match="fit none"):
        ktree.Tree.from_dense(np.array([0, -1, 70000], dtype=np.int64))
    with pytest.raises(ValueError, match="(?i)nan"):
        ktree.Tree.from_dense(np.array([0.0, np.nan], dtype=np.float32))
    with pytest.raises(ValueError, match="combine"):
        t.combine(t, "avg")
    with pytest.raises(ValueError, match="no values"):
        ktree.Tree.from_dense(np.array([True])).values([[0]])
    with pytest.raises(ValueError):
        t.overlay(ktree.Tree.from_dense(np.array([1, 2], dtype=np.uint8)))
    with pytest.raises(ValueError):
        t.select(70000)


def test_equality_pickle_bytes_and_files(tmp_path):
    a = np.array([[0, 1], [2, 2]], dtype=np.uint8)
    t = ktree.Tree.from_dense(a)
    assert t == ktree.Tree.from_dense(a)
    assert hash(t) == hash(ktree.Tree.from_dense(a))
    assert t != t.shape()
    assert t != ktree.Tree.from_dense(a.astype(np.uint16))
    assert t != ktree.Tree.from_dense(np.array([[0, 1], [2, 3]], dtype=np.uint8))
    back = pickle.loads(pickle.dumps(t))
    assert back == t and back.dtype == "uint8"
    f = ktree.Tree.from_dense(a.astype(np.float32), background=2)
    again = pickle.loads(pickle.dumps(f))
    np.testing.assert_array_equal(again.to_dense((0, 0), (2, 2)), a)
    assert ktree.Tree.from_bytes(t.to_bytes()) == t
    path = tmp_path / "labels.ktree"
    t.save(path)
    assert ktree.Tree.load(path) == t
    with pytest.raises(ValueError, match=".ktree"):
        t.save(tmp_path / "labels.binvox")


@pytest.mark.parametrize("dtype", ["uint8", "uint16", "int8", "float32"])
def test_saved_nifti_holds_every_value_for_nibabel(tmp_path, dtype):
    from test_ktree import missing, python_importing

    python = python_importing("nibabel")
    if python is None:
        missing("nibabel", "install Debian's python3-nibabel")
    rng = np.random.default_rng(len(dtype))
    a = random_labels(rng, 3, dtype)
    a[0, 0, 0] = 3  # the bounding box starts at the origin
    t = ktree.Tree.from_dense(a)
    path = tmp_path / "labels.nii.gz"
    t.save(path)
    read = subprocess.run(
        [python, "-c", "import sys, numpy as np, nibabel as nib\n"
         "img = nib.load(sys.argv[1])\n"
         "np.save(sys.argv[2], np.asanyarray(img.dataobj))\n"
         "print(*map(float, img.header.get_zooms()[:3]))", str(path), str(tmp_path / "read.npy")],
        capture_output=True, text=True,
    )
    assert read.returncode == 0, read.stderr
    got = np.load(tmp_path / "read.npy")
    # The universe's voxels, unit voxels from the origin (Tree.save writes no other frame).
    want = t.to_dense((0, 0, 0), (t.side,) * 3)
    np.testing.assert_array_equal(got, want)
    assert got.dtype == want.dtype
    assert read.stdout.split() == ["1.0"] * 3
    with pytest.raises(ValueError, match="hold no values"):
        t.save(tmp_path / "labels.bt")


@pytest.mark.parametrize("k", [2, 3, 4])
@pytest.mark.parametrize("dtype", ["uint16", "float32"])
def test_transforms_keep_each_voxels_value(k, dtype):
    rng = np.random.default_rng(300 + k)
    side = 4 if k == 4 else 8
    a = random_labels(rng, k, dtype, side)
    a = np.pad(a, [(0, side - n) for n in a.shape])  # the whole universe, so numpy sees what ktree does
    t = ktree.Tree.from_dense(a)
    whole = lambda u: u.to_dense((0,) * k, a.shape)  # noqa: E731
    for turns in range(-1, 4):
        turned = t.rotate(90 * turns, (0, k - 1))
        assert turned.dtype == dtype
        np.testing.assert_array_equal(whole(turned), np.rot90(a, turns, axes=(0, k - 1)))
    offset = [1, -2] + [0] * (k - 2)
    moved = np.zeros_like(a)
    moved[1:, : side - 2] = a[:-1, 2:]
    np.testing.assert_array_equal(whole(t.translate(offset)), moved)
    doubled = a
    for axis in range(k):
        doubled = doubled.repeat(2, axis=axis)
    np.testing.assert_array_equal(whole(t.scale(2)), doubled[(slice(0, side),) * k])
    # Any angle: the voxels are those of the shape turned, each holding a value the tree had.
    tilted = t.rotate(30, (0, 1))
    assert tilted.shape() == t.shape().rotate(30, (0, 1))
    kept = whole(tilted)
    assert set(np.unique(kept)) <= set(np.unique(a)) | {0}


@pytest.mark.parametrize("k", [1, 2, 3])
def test_colours_from_dense_keep_their_channels(k):
    rng = np.random.default_rng(400 + k)
    shape = tuple(int(n) for n in rng.integers(1, 7, size=k))
    palette = np.array([[0, 0, 0], [255, 0, 0], [10, 200, 30]], dtype=np.uint8)
    a = palette[rng.integers(0, 3, size=shape)]
    t = ktree.Tree.from_dense(a, dtype="rgb")
    assert t.dtype == "rgb8" and t.k == k
    assert t.voxel_count == int(np.count_nonzero(a.any(axis=-1)))
    np.testing.assert_array_equal(t.to_dense((0,) * k, shape), a)
    points = np.argwhere(np.ones(shape, bool))
    np.testing.assert_array_equal(t.values(points), a[tuple(points.T)])
    # A grey background; the dtype named for a label array.
    grey = ktree.Tree.from_dense(a, dtype="rgb", background=255)
    assert grey.voxel_count == int(np.count_nonzero((a != 255).any(axis=-1)))
    assert ktree.Tree.from_dense(np.arange(8).reshape(2, 4), dtype="uint16").dtype == "uint16"
    with pytest.raises(ValueError, match="3 channels"):
        ktree.Tree.from_dense(np.zeros((4, 4), np.uint8), dtype="rgb")
    with pytest.raises(ValueError, match="0..255"):
        ktree.Tree.from_dense(np.full((2, 3), 300), dtype="rgb")
    with pytest.raises(ValueError, match="dtype"):
        ktree.Tree.from_dense(a, dtype="complex")
