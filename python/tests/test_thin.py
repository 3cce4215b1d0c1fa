"""The methods that hand the library's calls to Python unchanged, checked against numpy and the command-line
tool: counts and crops of boxes [lo, hi) against numpy slices, hashes of equal trees, the statistics against
`ktree stats --json --measures`, the viewer page against `ktree view`'s page byte for byte, point arrays of
every dtype and memory layout against the int64 C-ordered answer, and mesh placements as the library checks
them."""

import pickle
import subprocess

import numpy as np
import pytest
from test_ktree import CUBE_FACES, CUBE_VERTICES, cli, random_object, run_json, whole

import ktree

LEVELS = {1: 6, 2: 4, 3: 3, 4: 2}


@pytest.fixture
def rng():
    return np.random.default_rng(33)


def box_of_numpy(a, lo, hi):
    """The voxels of `a` inside the box [lo, hi), by numpy (outside the array: none)."""
    out = np.zeros_like(a)
    sl = tuple(slice(min(max(l, 0), n), min(max(h, 0), n)) for l, h, n in zip(lo, hi, a.shape))
    out[sl] = a[sl]
    return out


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_count_and_crop_against_numpy(rng, k):
    for _ in range(10):
        a = random_object(rng, k, LEVELS[k])
        t = ktree.Tree.from_dense(a)
        side = t.side
        for _ in range(10):
            lo = [int(v) for v in rng.integers(-3, side + 2, size=k)]
            hi = [int(v) for v in rng.integers(-3, side + 4, size=k)]
            expected = box_of_numpy(a, lo, hi)
            assert t.count(lo, hi) == int(expected.sum())
            cropped = t.crop(lo, hi)
            assert cropped.k == k and cropped.level == t.level
            np.testing.assert_array_equal(whole(cropped), expected)
            assert cropped == ktree.Tree.from_dense(expected, t.level)
        assert t.count([0] * k, [side] * k) == t.voxel_count
        assert t.crop([0] * k, [side] * k) == t
    with pytest.raises(ValueError, match=f"lo of a K = {k} tree has {k} numbers"):
        t.count([0] * (k + 1), [1] * k)
    with pytest.raises(ValueError, match=f"hi of a K = {k} tree has {k} numbers"):
        t.crop([0] * k, [1] * (k + 1))


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_equal_trees_hash_equal(rng, k):
    a = random_object(rng, k, LEVELS[k])
    t = ktree.Tree.from_dense(a)
    # The same object made four other ways.
    same = [
        ktree.Tree.from_rays(t.to_rays(), t.level),
        ktree.Tree.from_bytes(t.to_bytes()),
        pickle.loads(pickle.dumps(t)),
        (t | ktree.Tree.empty(k, t.level)),
    ]
    for s in same:
        assert s == t and s is not t
        assert hash(s) == hash(t)
    assert len({t, *same}) == 1
    other = t ^ ktree.Tree.from_dense(np.ones((1,) * k, dtype=bool), t.level)
    assert other != t
    assert len({t, other}) == 2
    assert {t: "a"}[same[0]] == "a"
    # The same voxels in a larger universe are another object.
    assert ktree.Tree.from_dense(a, t.level + 1) != t


def test_stats_dict_equals_the_cli_with_measures(tmp_path, rng):
    for k in (2, 3):
        t = ktree.Tree.from_dense(random_object(rng, k, LEVELS[k]))
        path = tmp_path / f"t{k}.ktree"
        t.save(path)
        expected = run_json("stats", path, "--measures")
        s = t.stats()
        assert list(s.keys()) == list(expected.keys())
        assert s == expected
        assert s["voxels"] == t.voxel_count
        lo, hi = t.bounding_box()
        assert s["bounding_box"] == [lo, hi]
    assert ktree.Tree.empty(3, 2).stats()["bounding_box"] is None


@pytest.mark.parametrize("k,camera", [(2, None), (3, None), (3, "front"), (3, (1.0, 2.0, 3.0)), (4, "top")])
def test_view_page_equals_the_cli(tmp_path, rng, k, camera):
    a = random_object(rng, k, LEVELS[k])
    a.flat[::7] = True  # never empty
    t = ktree.Tree.from_dense(a)
    path = tmp_path / "t.ktree"
    t.save(path)
    budget = 40
    mine = tmp_path / "mine.html"
    page = t.view(mine, budget=budget, camera=camera, title="t.ktree")
    cli_page = tmp_path / "cli.html"
    args = [cli(), "view", path, "--out", cli_page, "--budget", budget]
    if camera is not None:
        args += ["--camera", camera if isinstance(camera, str) else ",".join(map(str, camera))]
    subprocess.run(list(map(str, args)), check=True, capture_output=True)
    assert mine.read_bytes() == cli_page.read_bytes()
    assert page["bytes"] == len(mine.read_bytes())
    assert 0 < page["boxes"] <= budget
    assert page["complete"] == (page["coarse"] == 0)


def test_view_errors(tmp_path):
    with pytest.raises(ValueError, match="bintree"):
        ktree.Tree.full(1, 3).view(tmp_path / "a.html")
    with pytest.raises(ValueError, match="budget"):
        ktree.Tree.full(3, 3).view(tmp_path / "a.html", budget=0)
    with pytest.raises(ValueError, match="time axis"):
        ktree.Tree.full(4, 2).view(tmp_path / "a.html", time_axis=4)
    with pytest.raises(ValueError, match="view"):
        ktree.Tree.full(3, 3).view(tmp_path / "a.html", camera="sideways")
    plain = tmp_path / "plain"
    plain.write_text("")
    with pytest.raises(OSError):
        ktree.Tree.full(3, 3).view(plain / "a.html")
    assert list(tmp_path.iterdir()) == [plain]


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_point_arrays_of_every_dtype_and_layout(rng, k):
    a = random_object(rng, k, LEVELS[k])
    t = ktree.Tree.from_dense(a)
    points = rng.integers(-2, t.side + 2, size=(400, k))
    expected = t.contains(np.ascontiguousarray(points, dtype=np.int64))
    inside = np.all((points >= 0) & (points < t.side), axis=1)
    reference = np.zeros(len(points), dtype=bool)
    reference[inside] = a[tuple(points[inside].T)]
    np.testing.assert_array_equal(expected, reference)
    nonneg = np.clip(points, 0, None)
    nonneg_expected = t.contains(nonneg)
    variants = {
        "fortran": (np.asfortranarray(points), expected),
        "strided": (np.repeat(points, 2, axis=0)[::2], expected),
        "int32": (points.astype(np.int32), expected),
        "float": (points.astype(np.float64), expected),
        "list": (points.tolist(), expected),
        "uint32": (nonneg.astype(np.uint32), nonneg_expected),
        "uint32 fortran": (np.asfortranarray(nonneg.astype(np.uint32)), nonneg_expected),
        "uint32 strided": (np.repeat(nonneg.astype(np.uint32), 2, axis=0)[::2], nonneg_expected),
        "readonly": (np.require(nonneg, requirements="C"), nonneg_expected),
    }
    variants["readonly"][0].flags.writeable = False
    for name, (p, e) in variants.items():
        np.testing.assert_array_equal(t.contains(p), e, err_msg=name)
    # Distances and nearest voxels read their points the same way.
    np.testing.assert_array_equal(t.distance(np.asfortranarray(points)), t.distance(points))
    np.testing.assert_array_equal(t.nearest(points[::-1]), t.nearest(points)[::-1])


def test_points_and_meshes_in_any_layout(rng):
    p = rng.random((500, 3)) * 10
    t = ktree.Tree.from_points(p, 0.5)
    assert ktree.Tree.from_points(np.asfortranarray(p), 0.5) == t
    assert ktree.Tree.from_points(p.astype(np.float32).astype(np.float64), 0.5).k == 3
    assert ktree.Tree.from_points(np.repeat(p, 2, axis=0)[::2], 0.5) == t
    m = ktree.Tree.from_mesh_arrays(CUBE_VERTICES, CUBE_FACES, 3, transform=(4, 2, 1, 3))
    assert ktree.Tree.from_mesh_arrays(np.asfortranarray(CUBE_VERTICES), CUBE_FACES.astype(np.int32), 3, (4, 2, 1, 3)) == m


def test_mesh_placement_is_the_librarys(tmp_path):
    # A scale of 0 (or not finite) is refused as the command line's --transform is.
    for transform in [(0, 1, 2, 3), (-0.0, 1, 2, 3), (float("nan"), 0, 0, 0), (1, float("inf"), 0, 0)]:
        with pytest.raises(ValueError, match="s ≠ 0"):
            ktree.Tree.from_mesh_arrays(CUBE_VERTICES, CUBE_FACES, 3, transform=transform)
    # The same placement as the command-line tool's, for a mesh file.
    obj = tmp_path / "cube.obj"
    lines = [f"v {x} {y} {z}" for x, y, z in CUBE_VERTICES]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in CUBE_FACES]
    obj.write_text("\n".join(lines) + "\n")
    out = tmp_path / "cube.ktree"
    for transform in [None, (0.1 + 0.2, 1 / 3, 2.5, 1e-9)]:
        args = [cli(), "voxelize", obj, "--level", "4", "--out", out]
        if transform is None:
            args.append("--fit")
        else:
            args.append("--transform=" + ",".join(repr(v) for v in transform))
        subprocess.run(list(map(str, args)), check=True, capture_output=True)
        assert ktree.Tree.from_mesh(obj, 4, transform) == ktree.Tree.load(out)
