"""The Python module checked against numpy references: dense arrays, Booleans, node counts by pooling, mass
by sums, transforms by array shifts and rotations, files by round trips, and the CLI's JSON keys. A test whose
tool is missing (the `ktree` binary, `setpriv` as root) is skipped, or fails when the environment variable
KTREE_REQUIRE_TOOLS is set to anything but empty or 0, as `.ci/run` sets it (see `missing`)."""

import errno
import json
import os
import shutil
import struct
import subprocess
import sys
import zlib
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

import ktree

ROOT = Path(__file__).resolve().parents[2]
LEVELS = {1: 6, 2: 4, 3: 3, 4: 2}  # side 64, 16, 8, 4: a few thousand voxels or fewer


def random_object(rng, k, level, density=0.5):
    """A random array with solid blocks of every size, so that full nodes appear at every level."""
    side = 2**level
    a = rng.random((side,) * k) < density * 0.3
    for _ in range(3):
        block = 2 ** rng.integers(0, level + 1)
        start = rng.integers(0, side // block, size=k) * block
        a[tuple(slice(s, s + block) for s in start)] = rng.random() < 0.7
    return a


def missing(needed, install):
    """A test without something it needs: fails, saying what to install, when KTREE_REQUIRE_TOOLS is set to
    anything but empty or 0 (as `.ci/run` sets it); otherwise skips."""
    message = f"needs {needed}: {install}"
    if os.environ.get("KTREE_REQUIRE_TOOLS", "") not in ("", "0"):
        pytest.fail(f"{message} (KTREE_REQUIRE_TOOLS is set: a missing tool is an error; unset it to skip)")
    pytest.skip(message)


def python_importing(module, extra=()):
    """An interpreter that imports `module` and numpy — those named in `extra`, this one, `python3` on the
    PATH or `/usr/bin/python3` (Debian's packages of OpenVDB and nibabel are for the system's) — or None."""
    found = [*extra, sys.executable, shutil.which("python3"), "/usr/bin/python3"]
    for python in filter(None, found):
        probe = subprocess.run([python, "-c", f"import {module}, numpy"], capture_output=True)
        if probe.returncode == 0:
            return python
    return None


def whole(t):
    """The tree's whole universe as a dense array (to_dense's default is the bounding box)."""
    return t.to_dense((0,) * t.k, (t.side,) * t.k)


@pytest.fixture
def rng():
    return np.random.default_rng(1234)


# --- dense arrays ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_dense_round_trip(rng, k):
    for _ in range(20):
        a = random_object(rng, k, LEVELS[k])
        t = ktree.Tree.from_dense(a)
        assert (t.k, t.level, t.side) == (k, LEVELS[k], 2 ** LEVELS[k])
        out = whole(t)
        assert out.dtype == np.bool_ and out.shape == a.shape
        np.testing.assert_array_equal(out, a)
        assert t.voxel_count == int(a.sum())


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_dense_indexing_is_x_y_z(k):
    # One voxel at x = 1 (all other coordinates 0): the tree must hold exactly the point (1, 0, ...).
    side = 4
    a = np.zeros((side,) * k, dtype=bool)
    point = (1,) + (0,) * (k - 1)
    a[point] = True
    t = ktree.Tree.from_dense(a)
    assert t.contains(list(point))
    assert sum(t.contains(list(p)) for p in np.ndindex(*a.shape)) == 1
    # A run along the last axis (the CLI's z) is a row of the ray array.
    rays = t.to_rays()
    np.testing.assert_array_equal(rays, [list(point[:-1]) + [point[-1], point[-1] + 1]])


def test_dense_non_square_is_placed_at_the_origin(rng):
    a = rng.random((5, 3, 7)) < 0.5
    t = ktree.Tree.from_dense(a)
    assert t.level == 3
    out = whole(t)
    np.testing.assert_array_equal(out[:5, :3, :7], a)
    assert out.sum() == a.sum()
    assert ktree.Tree.from_dense(a, level=5).level == 5
    with pytest.raises(ValueError, match="does not fit"):
        ktree.Tree.from_dense(a, level=2)


def test_dense_of_numbers_holds_values_whose_shape_is_non_zero():
    a = np.array([[0, 2], [0, 0]])
    t = ktree.Tree.from_dense(a)
    assert t.dtype == "uint8"
    np.testing.assert_array_equal(whole(t.shape()), a != 0)


@pytest.mark.parametrize("shape", [(2,) * 5, ()])
def test_dense_rejects_unsupported_dimensions(shape):
    with pytest.raises(ValueError, match="not supported"):
        ktree.Tree.from_dense(np.zeros(shape, dtype=bool))


def test_dense_too_large_is_an_error_not_an_allocation():
    with pytest.raises(ValueError):
        whole(ktree.Tree.full(3, 20))


# --- node counts against a numpy pooling --------------------------------------------------------------------


def pooled_counts(a):
    """Full, empty and partial nodes per level of the reduced tree of `a`, by pooling blocks in numpy."""
    k, side = a.ndim, a.shape[0]
    level = side.bit_length() - 1
    counts, parent_partial = [], None
    for depth in range(level + 1):
        block = 2 ** (level - depth)
        n = side // block
        blocks = a.reshape(sum(((n, block) for _ in range(k)), ()))
        inner_axes = tuple(range(1, 2 * k, 2))
        full, some = blocks.all(axis=inner_axes), blocks.any(axis=inner_axes)
        exists = np.ones_like(full) if parent_partial is None else parent_partial
        partial = some & ~full
        counts.append(
            {
                "level": depth,
                "full": int((full & exists).sum()),
                "empty": int((~some & exists).sum()),
                "partial": int((partial & exists).sum()),
            }
        )
        child = partial & exists
        for axis in range(k):
            child = child.repeat(2, axis=axis)
        parent_partial = child
    return counts


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_counts_per_level_against_pooling(rng, k):
    for _ in range(10):
        a = random_object(rng, k, LEVELS[k])
        s = ktree.Tree.from_dense(a).stats()
        expected = pooled_counts(a)
        per_level = [c for c in s["per_level"]]
        # The tree has no level below its last partial node; pooling reports empty levels there.
        assert per_level == expected[: len(per_level)]
        assert all(c["full"] + c["empty"] + c["partial"] == 0 for c in expected[len(per_level) :])
        for key in ("full", "empty", "partial"):
            assert s[key] == sum(c[key] for c in expected)
        assert s["nodes"] == s["full"] + s["empty"] + s["partial"]
        assert (s["k"], s["level"], s["rays"]) == (k, LEVELS[k], None)
        assert s["bytes_at_2_bits"] == (2 * s["nodes"] + 7) // 8


# --- Booleans --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_booleans_against_numpy(rng, k):
    for _ in range(10):
        a = random_object(rng, k, LEVELS[k])
        b = random_object(rng, k, LEVELS[k])
        ta, tb = ktree.Tree.from_dense(a), ktree.Tree.from_dense(b)
        np.testing.assert_array_equal(whole(ta | tb), np.logical_or(a, b))
        np.testing.assert_array_equal(whole(ta & tb), np.logical_and(a, b))
        np.testing.assert_array_equal(whole(ta - tb), np.logical_and(a, np.logical_not(b)))
        np.testing.assert_array_equal(whole(ta ^ tb), np.logical_xor(a, b))
        np.testing.assert_array_equal(whole(~ta), np.logical_not(a))
        assert (ta | tb) == ktree.Tree.from_dense(a | b)
        assert ta.interferes(tb) == bool((a & b).any())


def test_booleans_need_same_dimension_and_level():
    with pytest.raises(ValueError, match="same dimension"):
        ktree.Tree.empty(2, 3) | ktree.Tree.empty(3, 3)
    with pytest.raises(ValueError):
        ktree.Tree.empty(2, 3) & ktree.Tree.empty(2, 4)
    with pytest.raises(TypeError):
        ktree.Tree.empty(2, 3) | 1


# --- rays ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_rays_against_dense(rng, k):
    level = LEVELS[k]
    side = 2**level
    n = 30
    columns = rng.integers(0, side, size=(n, k - 1))
    z1 = rng.integers(0, side, size=n)
    z2 = np.minimum(side, z1 + rng.integers(1, side + 1, size=n))
    rays = np.column_stack([columns, z1, z2])
    a = np.zeros((side,) * k, dtype=bool)
    for row in rays:
        a[tuple(row[: k - 1]) + (slice(row[k - 1], row[k]),)] = True
    t = ktree.Tree.from_rays(rays, level)
    np.testing.assert_array_equal(whole(t), a)
    # Runs back out: maximal, so the round trip gives the same tree.
    assert ktree.Tree.from_rays(t.to_rays(), level) == t
    assert t.to_rays().shape[1] == k + 1


def test_bad_rays_are_value_errors():
    with pytest.raises(ValueError, match="ray 1"):
        ktree.Tree.from_rays([[0, 0, 1], [0, 3, 2]], 2)
    with pytest.raises(ValueError, match="ray 0"):
        ktree.Tree.from_rays([[9, 0, 1]], 2)
    with pytest.raises(ValueError, match="not a coordinate"):
        ktree.Tree.from_rays([[-1, 0, 1]], 2)
    with pytest.raises(ValueError, match="columns"):
        ktree.Tree.from_rays(np.zeros((1, 7), dtype=int), 2)


# --- mass ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_mass_against_numpy_sums(rng, k):
    for _ in range(5):
        a = random_object(rng, k, LEVELS[k])
        if not a.any():
            continue
        m = ktree.Tree.from_dense(a).mass()
        points = np.argwhere(a) + 0.5  # voxel x spans [x, x + 1)
        centroid = points.mean(axis=0)
        d = points - centroid
        moments = d.T @ d + np.eye(k) * len(points) / 12.0  # each unit voxel adds 1/12 on the diagonal
        assert m["k"] == k and m["volume"] == int(a.sum())
        np.testing.assert_allclose(m["centroid"], centroid, rtol=1e-12)
        np.testing.assert_allclose(m["central_moments"], moments, rtol=1e-9, atol=1e-9)
        inertia = np.trace(moments) * np.eye(k) - moments
        np.testing.assert_allclose(m["inertia_tensor"], inertia, rtol=1e-9, atol=1e-9)
        assert m["progressive"] is None and m["estimate"] is None


def test_mass_progressive_bounds_hold_the_volume(rng):
    a = random_object(rng, 3, 4)
    m = ktree.Tree.from_dense(a).mass(tolerance=0.0)
    assert m["progressive"][-1]["lower"] == m["progressive"][-1]["upper"] == a.sum()
    for level in m["progressive"]:
        assert level["lower"] <= a.sum() <= level["upper"]
    with pytest.raises(ValueError, match="tolerance"):
        ktree.Tree.from_dense(a).mass(tolerance=-1)


# --- transforms ------------------------------------------------------------------------------------------


def shifted(a, offset):
    """`a` moved by whole voxels, what leaves the array dropped."""
    out = np.zeros_like(a)
    src = tuple(slice(max(0, -o), a.shape[i] - max(0, o)) for i, o in enumerate(offset))
    dst = tuple(slice(max(0, o), a.shape[i] - max(0, -o)) for i, o in enumerate(offset))
    out[dst] = a[src]
    return out


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_translate_against_numpy(rng, k):
    a = random_object(rng, k, LEVELS[k])
    t = ktree.Tree.from_dense(a)
    for _ in range(5):
        offset = [int(x) for x in rng.integers(-3, 4, size=k)]
        np.testing.assert_array_equal(whole(t.translate(offset)), shifted(a, offset))
    with pytest.raises(ValueError, match=f"needs {k} numbers"):
        t.translate([1] * (k + 1))


@pytest.mark.parametrize("k", [2, 3, 4])
def test_quarter_turns_against_rot90(rng, k):
    a = random_object(rng, k, LEVELS[k])
    t = ktree.Tree.from_dense(a)
    for axes in [(0, 1), (1, 0), (0, k - 1)]:
        for turns in range(-1, 5):
            np.testing.assert_array_equal(
                whole(t.rotate(90 * turns, axes)), np.rot90(a, turns, axes=axes)
            )


def test_named_axes_in_3d(rng):
    a = random_object(rng, 3, 3)
    t = ktree.Tree.from_dense(a)
    assert t.rotate(90, "z") == t.rotate(90, (0, 1))
    assert t.rotate(90, "x") == t.rotate(90, (1, 2))
    assert t.rotate(90, "y") == t.rotate(90, (2, 0))
    with pytest.raises(ValueError):
        ktree.Tree.from_dense(a[0]).rotate(90, "z")


def test_rotation_by_any_angle_keeps_the_object_near(rng):
    a = np.zeros((16, 16, 16), dtype=bool)
    a[4:12, 4:12, 4:12] = True
    turned = ktree.Tree.from_dense(a).rotate(45, "z")
    volume = turned.voxel_count
    assert 0.8 * a.sum() <= volume <= 1.2 * a.sum()
    m = turned.mass()
    np.testing.assert_allclose(m["centroid"], [8, 8, 8], atol=0.5)


def test_scale_against_repeat(rng):
    a = random_object(rng, 3, 3)
    t = ktree.Tree.from_dense(a)
    doubled = a.repeat(2, axis=0).repeat(2, axis=1).repeat(2, axis=2)[:8, :8, :8]
    np.testing.assert_array_equal(whole(t.scale(2)), doubled)
    assert t.scale(Fraction(2, 1)) == t.scale(2) == t.scale(2.0)
    assert t.scale(1) == t
    with pytest.raises(ValueError):
        t.scale(-1.5)


def test_affine_matrices(rng):
    a = random_object(rng, 2, 4)
    t = ktree.Tree.from_dense(a)
    assert t.affine(np.eye(3)) == t
    move = np.array([[1, 0, 3], [0, 1, -2], [0, 0, 1]], dtype=float)
    np.testing.assert_array_equal(whole(t.affine(move)), shifted(a, [3, -2]))
    with pytest.raises(ValueError, match="3 x 3"):
        t.affine(np.eye(4))
    # A last row other than 0 0 1 is a projective map; it still gives a tree of the same universe.
    assert t.affine([[1, 0, 0], [0, 1, 0], [0.001, 0, 1]]).level == t.level


# --- interference ----------------------------------------------------------------------------------------


def test_collide_against_numpy(rng):
    for _ in range(10):
        a = random_object(rng, 3, 3)
        b = random_object(rng, 3, 3)
        r = ktree.Tree.from_dense(a).collide(ktree.Tree.from_dense(b))
        assert r["collide"] == bool((a & b).any())
        assert r["overlap_voxels"] == int((a & b).sum())
        if r["collide"]:
            assert r["min_separation"] == 0.0
        elif a.any() and b.any():
            pa, pb = np.argwhere(a), np.argwhere(b)
            d = np.sqrt(((pa[:, None, :] - pb[None, :, :]) ** 2).sum(axis=2)).min()
            assert r["min_separation"] == pytest.approx(d)


def test_first_contact_along_time():
    a = np.zeros((8, 8, 8, 8), dtype=bool)
    b = np.zeros_like(a)
    for t in range(8):
        a[t, 2:4, 2:4, t] = True  # moving along x over time
        b[5:7, 2:4, 2:4, t] = True  # standing still
    r = ktree.Tree.from_dense(a).collide(ktree.Tree.from_dense(b), time_axis=3)
    assert r["collide"] and r["first_contact"] == 5


# --- pictures --------------------------------------------------------------------------------------------


def ball(level, radius):
    side = 2**level
    c = np.arange(side) + 0.5 - side / 2
    x, y, z = np.meshgrid(c, c, c, indexing="ij")
    return x * x + y * y + z * z <= radius * radius


def test_render_shape_dtype_and_visibility():
    t = ktree.Tree.from_dense(ball(5, 10))
    image = t.render(width=64, height=48)
    assert image.shape == (48, 64, 3) and image.dtype == np.uint8
    background = np.all(image == 255, axis=2)
    assert (~background).sum() > 0.2 * 64 * 48  # the ball covers much of the frame
    assert not (~background)[0].any() and not (~background)[-1].any()  # framed with a margin
    empty = ktree.Tree.empty(3, 5).render(width=16, height=16)
    assert np.all(empty == 255)
    top = t.render("top", 32, 32, perspective=40.0)
    assert top.shape == (32, 32, 3) and (top != 255).any()
    assert t.render([1.0, 2.0, 3.0], 16, 16).shape == (16, 16, 3)


def test_render_other_dimensions():
    disk = ball(4, 5)[:, :, 8]
    picture = ktree.Tree.from_dense(disk).render(width=64, height=64)
    assert picture.shape[2] == 3 and picture.dtype == np.uint8 and len(np.unique(picture.reshape(-1, 3), axis=0)) > 1
    moving = np.zeros((8, 8, 8, 8), dtype=bool)
    for t in range(8):
        moving[t : t + 2, 2:5, 2:5, t] = True
    strip = ktree.Tree.from_dense(moving).render(width=32, height=32, frames=4)
    assert strip.ndim == 3 and strip.shape[0] == 32 and strip.shape[2] == 3
    with pytest.raises(ValueError, match="bintree"):
        ktree.Tree.from_dense(np.ones(4, dtype=bool)).render()
    with pytest.raises(ValueError):
        ktree.Tree.from_dense(ball(4, 5)).render(width=0, height=10)
    with pytest.raises(ValueError, match="view"):
        ktree.Tree.from_dense(ball(4, 5)).render("sideways")


def test_lines_svg():
    t = ktree.Tree.from_dense(ball(4, 5))
    svg = t.lines(width=200, height=100)
    assert svg.lstrip().startswith("<svg") or "<svg" in svg[:200]
    assert "</svg>" in svg and svg.count("<line") + svg.count("<path") > 0
    assert t.lines("top", method="pairwise") != ""
    with pytest.raises(ValueError, match="octree"):
        ktree.Tree.empty(2, 3).lines()
    with pytest.raises(ValueError, match="method"):
        t.lines(method="magic")


# --- meshes and volumes ----------------------------------------------------------------------------------

CUBE_VERTICES = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float
)
CUBE_FACES = np.array(
    [
        [0, 2, 1], [0, 3, 2],  # z = 0, seen from below
        [4, 5, 6], [4, 6, 7],  # z = 1
        [0, 1, 5], [0, 5, 4],  # y = 0
        [2, 3, 7], [2, 7, 6],  # y = 1
        [1, 2, 6], [1, 6, 5],  # x = 1
        [0, 4, 7], [0, 7, 3],  # x = 0
    ]
)  # fmt: skip


def test_mesh_arrays_against_a_box():
    t = ktree.Tree.from_mesh_arrays(CUBE_VERTICES, CUBE_FACES, 3, transform=(4, 2, 1, 3))
    expected = np.zeros((8, 8, 8), dtype=bool)
    expected[2:6, 1:5, 3:7] = True  # voxels whose centres are inside [2, 6] x [1, 5] x [3, 7]
    np.testing.assert_array_equal(whole(t), expected)
    fitted = ktree.Tree.from_mesh_arrays(CUBE_VERTICES, CUBE_FACES, 3)
    assert fitted.voxel_count == 6**3  # scaled into the universe with one voxel of margin
    with pytest.raises(ValueError, match="face 0"):
        ktree.Tree.from_mesh_arrays(CUBE_VERTICES, [[0, 1, 8]], 3)
    with pytest.warns(UserWarning, match="not closed"):
        ktree.Tree.from_mesh_arrays(CUBE_VERTICES, CUBE_FACES[:-1], 3, transform=(4, 2, 1, 3))


def test_mesh_file_equals_mesh_arrays(tmp_path):
    obj = tmp_path / "cube.obj"
    lines = [f"v {x} {y} {z}" for x, y, z in CUBE_VERTICES]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in CUBE_FACES]
    obj.write_text("\n".join(lines) + "\n")
    from_file = ktree.Tree.from_mesh(obj, 4, transform=(8, 3, 4, 5))
    assert from_file == ktree.Tree.from_mesh_arrays(CUBE_VERTICES, CUBE_FACES, 4, (8, 3, 4, 5))
    assert from_file.voxel_count == 8**3
    with pytest.raises(OSError):
        ktree.Tree.from_mesh(tmp_path / "missing.obj", 4)
    # A malformed file: one line naming the file once, and the line.
    bad = tmp_path / "bad.ply"
    bad.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float\nend_header\n")
    with pytest.raises(ValueError) as e:
        ktree.Tree.from_mesh(bad, 4)
    assert str(e.value) == f"{bad}:5: unexpected PLY header line 'property float'"


def test_real_mesh_from_data_folder():
    meshes = sorted((ROOT / "data" / "meshes").glob("*.obj")) + sorted((ROOT / "data" / "meshes").glob("*.stl"))
    assert meshes, f"no mesh in {ROOT / 'data' / 'meshes'} (the meshes are part of the repository)"
    t = ktree.Tree.from_mesh(str(meshes[0]), 6)
    assert t.k == 3 and t.voxel_count > 0
    assert t.render(width=32, height=32).shape == (32, 32, 3)


def test_volume_against_threshold(tmp_path, rng):
    values = rng.integers(0, 100, size=(5, 6, 7)).astype(np.uint8)  # indexed [x, y, z]
    (tmp_path / "v.json").write_text(json.dumps({"shape_xyz": [5, 6, 7], "dtype": "uint8"}))
    (tmp_path / "v.raw").write_bytes(values.tobytes(order="F"))  # samples x fastest
    t = ktree.Tree.from_volume(tmp_path / "v.json", 60)
    assert t.level == 3
    np.testing.assert_array_equal(whole(t)[:5, :6, :7], values >= 60)
    assert t.voxel_count == int((values >= 60).sum())
    moved = ktree.Tree.from_volume(tmp_path / "v.json", label=7, level=4, offset=(1, 2, 3))
    np.testing.assert_array_equal(whole(moved)[1:6, 2:8, 3:10], values == 7)
    with pytest.raises(ValueError, match="exactly one"):
        ktree.Tree.from_volume(tmp_path / "v.json")
    with pytest.raises(OSError):
        ktree.Tree.from_volume(tmp_path / "none.json", 1)


# --- files -----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("k", [1, 2, 3, 4])
@pytest.mark.parametrize("ext", ["ktree", "rays"])
def test_save_load_round_trip(tmp_path, rng, k, ext):
    t = ktree.Tree.from_dense(random_object(rng, k, LEVELS[k]))
    path = tmp_path / f"object.{ext}"
    t.save(path)
    assert ktree.Tree.load(path) == t
    assert ktree.Tree.load(str(path)) == t
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary file left


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_bytes_and_pickle_round_trip(tmp_path, rng, k):
    import pickle

    t = ktree.Tree.from_dense(random_object(rng, k, LEVELS[k]))
    t.save(tmp_path / "t.ktree")
    assert t.to_bytes() == (tmp_path / "t.ktree").read_bytes()
    assert ktree.Tree.from_bytes(t.to_bytes()) == t
    assert pickle.loads(pickle.dumps(t)) == t
    with pytest.raises(ValueError, match="<bytes>: byte"):
        ktree.Tree.from_bytes(t.to_bytes()[:-1])


def test_file_errors_name_the_file(tmp_path):
    with pytest.raises(OSError):
        ktree.Tree.load(tmp_path / "missing.ktree")
    bad = tmp_path / "bad.ktree"
    bad.write_bytes(b"KTREE\0" + bytes(20))
    with pytest.raises(ValueError, match="bad.ktree"):
        ktree.Tree.load(bad)
    rays = tmp_path / "bad.rays"
    rays.write_text("3 4\n0 0 5\n")
    with pytest.raises(ValueError, match="bad.rays"):
        ktree.Tree.load(rays)
    with pytest.raises(ValueError, match="x.unknown: unknown extension"):
        ktree.Tree.empty(2, 2).save(tmp_path / "x.unknown")
    with pytest.raises(OSError):
        ktree.Tree.empty(2, 2).save(bad / "x.ktree")  # a file where a folder should be


def test_every_format_saves_and_loads_the_same_tree(tmp_path):
    a = np.zeros((16, 16, 16), bool)
    a[2:11, 3:9, 5:14] = True
    a[12, 12, 12] = True
    t = ktree.Tree.from_dense(a)
    for ext in ["ktree", "rays", "binvox", "bt", "vdb"]:
        path = tmp_path / f"t.{ext}"
        t.save(path)
        back = ktree.Tree.load(path)
        assert np.array_equal(whole(back), a), ext


# --- the command-line tool's JSON ------------------------------------------------------------------------


def cli():
    """The `ktree` binary: $KTREE_BIN, else one built in the workspace's target folder, else one on the PATH;
    without one, `missing`."""
    if os.environ.get("KTREE_BIN"):
        return os.environ["KTREE_BIN"]
    for profile in ("release", "debug"):
        path = ROOT / "target" / profile / "ktree"
        if path.exists():
            return str(path)
    found = shutil.which("ktree")
    if found is None:
        missing("the ktree binary", "build it (cargo build -p ktree-cli) or set KTREE_BIN to it")
    return found


def rgb_tree(tmp_path, colours):
    """A tree of colours at level 3 made by `ktree voxelize --value rgb` of a point in each voxel of `colours`
    (a (8, 8, 8, 3) uint8 array, black: no point), written to `tmp_path / "c.ktree"`."""
    points = np.argwhere(colours.any(axis=-1))
    lines = [f"{x + 0.5} {y + 0.5} {z + 0.5} {' '.join(map(str, colours[x, y, z]))}" for x, y, z in points]
    ply = tmp_path / "c.ply"
    ply.write_text(
        "ply\nformat ascii 1.0\n"
        f"element vertex {len(lines)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n" + "\n".join(lines) + "\n"
    )
    src = tmp_path / "c.ktree"
    subprocess.run(
        [cli(), "voxelize", str(ply), "--voxel-size", "1", "--origin", "0,0,0", "--level", "3",
         "--value", "rgb", "--out", str(src)],
        check=True, capture_output=True, text=True,
    )
    return src


def run_json(*args):
    binary = cli()
    out = subprocess.run([binary, *map(str, args), "--json"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def read_png_rgb(path):
    """An 8-bit RGB, non-interlaced PNG as an (height, width, 3) array (enough for the CLI's images)."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    assert (depth, colour, interlace) == (8, 2, 0)
    raw = np.frombuffer(zlib.decompress(idat), dtype=np.uint8).reshape(height, 1 + 3 * width)
    out = np.zeros((height, 3 * width), dtype=np.int64)
    for y in range(height):
        kind, line = raw[y, 0], raw[y, 1:].astype(np.int64)
        up = out[y - 1] if y > 0 else np.zeros(3 * width, dtype=np.int64)
        if kind in (0, 2):
            out[y] = (line + (up if kind == 2 else 0)) % 256
            continue
        row = np.zeros(3 * width, dtype=np.int64)
        for x in range(3 * width):
            left = row[x - 3] if x >= 3 else 0
            upper_left = up[x - 3] if x >= 3 else 0
            if kind == 1:
                pred = left
            elif kind == 3:
                pred = (left + up[x]) // 2
            else:
                p = left + up[x] - upper_left
                pa, pb, pc = abs(p - left), abs(p - up[x]), abs(p - upper_left)
                pred = left if pa <= pb and pa <= pc else (up[x] if pb <= pc else upper_left)
            row[x] = (line[x] + pred) % 256
        out[y] = row
    return out.astype(np.uint8).reshape(height, width, 3)


def test_render_equals_the_cli_image(tmp_path):
    binary = cli()
    t = ktree.Tree.from_dense(ball(5, 9)) - ktree.Tree.from_dense(ball(5, 6)).translate([6, 0, 4])
    t.save(tmp_path / "t.ktree")
    for view in ("iso", "front"):
        png = tmp_path / f"{view}.png"
        args = [binary, "render", tmp_path / "t.ktree", "--camera", view, "--size", "48x40", "--out", png]
        subprocess.run(list(map(str, args)), check=True, capture_output=True)
        np.testing.assert_array_equal(t.render(view, 48, 40), read_png_rgb(png))


def test_stats_keys_and_values_equal_the_cli(tmp_path, rng):
    t = ktree.Tree.from_dense(random_object(rng, 3, 4))
    path = tmp_path / "t.ktree"
    t.save(path)
    # Tree.stats measures the surface area and the Euler number, as `--measures` asks the CLI to.
    expected = run_json("stats", path, "--measures")
    assert list(t.stats().keys()) == list(expected.keys())
    assert t.stats() == expected


def test_mass_and_collide_keys_equal_the_cli(tmp_path, rng):
    a = ktree.Tree.from_dense(random_object(rng, 3, 4))
    b = ktree.Tree.from_dense(random_object(rng, 3, 4))
    a.save(tmp_path / "a.ktree")
    b.save(tmp_path / "b.ktree")
    mass = run_json("mass", tmp_path / "a.ktree")
    assert set(a.mass().keys()) == set(mass.keys())
    assert a.mass()["volume"] == mass["volume"]
    np.testing.assert_allclose(a.mass()["centroid"], mass["centroid"])
    collide = run_json("collide", tmp_path / "a.ktree", tmp_path / "b.ktree")
    assert a.collide(b) == collide


# --- the module ------------------------------------------------------------------------------------------


def test_module_surface():
    assert ktree.__version__
    t = ktree.Tree.full(2, 3)
    assert t.voxel_count == 64 and t.node_count == 1
    assert "k=2" in repr(t) and "level=3" in repr(t)
    assert ktree.Tree.__doc__ and ktree.Tree.from_dense.__doc__ and ktree.Tree.render.__doc__
    assert t == ktree.Tree.from_dense(np.ones((8, 8), dtype=bool))
    assert t != ktree.Tree.empty(2, 3)
    assert not t.contains([8, 0])
    with pytest.raises(ValueError, match="2 coordinates"):
        t.contains([1])


def test_readme_session_runs(monkeypatch, capsys):
    text = (ROOT / "README.md").read_text()
    session = text.split("```python\n", 1)[1].split("```", 1)[0]
    assert len(session.strip().splitlines()) == 5
    monkeypatch.chdir(ROOT)
    exec(compile(session, "README.md", "exec"), {})
    printed = capsys.readouterr().out.split()
    assert int(printed[0]) > 1 and printed[-1] == "3)"  # nodes ... (300, 400, 3)


def test_calls_from_threads_agree_with_serial_calls(rng):
    # Long calls release the GIL: several threads then run inside the library at once.
    from concurrent.futures import ThreadPoolExecutor

    arrays = [random_object(rng, 3, 4) for _ in range(8)]

    def work(a):
        t = ktree.Tree.from_dense(a)
        return whole(t | t.rotate(90, "z")), t.render(width=24, height=24)

    serial = [work(a) for a in arrays]
    with ThreadPoolExecutor(max_workers=4) as pool:
        parallel = list(pool.map(work, arrays))
    for (d1, i1), (d2, i2) in zip(serial, parallel):
        np.testing.assert_array_equal(d1, d2)
        np.testing.assert_array_equal(i1, i2)


@pytest.mark.parametrize(
    "name", ["missing.ktree", "missing.rays", "missing.vdb", "missing.bt", "missing.binvox", "missing.obj", "missing.nii"]
)
def test_a_missing_file_raises_file_not_found_with_its_name(tmp_path, name):
    path = tmp_path / name
    with pytest.raises(FileNotFoundError) as caught:
        ktree.Tree.load(str(path))
    assert caught.value.filename == str(path)
    assert name in str(caught.value)


LOAD_ERROR = """
import json, sys, ktree
try:
    ktree.Tree.load(sys.argv[1])
    print(json.dumps(["loaded", None]))
except Exception as e:
    print(json.dumps([type(e).__name__, getattr(e, "filename", None)]))
"""


def load_error(path):
    """What `Tree.load(path)` raises: (the exception's type name, its filename). Root reads files whatever
    their mode, so as root the load runs in a child process still root but without the capabilities that
    let it (CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH, dropped by util-linux's `setpriv`)."""
    if os.geteuid() != 0:
        try:
            ktree.Tree.load(path)
        except Exception as e:
            return type(e).__name__, getattr(e, "filename", None)
        return "loaded", None
    setpriv = shutil.which("setpriv")
    if setpriv is None:
        missing("setpriv to drop root's file capabilities", "install util-linux")
    caps = "-dac_override,-dac_read_search"
    out = subprocess.run(
        [setpriv, f"--inh-caps={caps}", f"--bounding-set={caps}", "--", sys.executable, "-c", LOAD_ERROR, path],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stderr
    return tuple(json.loads(out.stdout))


@pytest.mark.parametrize("name", ["locked.ktree", "locked.vdb", "locked.bt"])
def test_an_unreadable_file_raises_permission_error(tmp_path, name):
    path = tmp_path / name
    ktree.Tree.from_dense(np.ones((2, 2, 2), dtype=bool)).save(str(path))
    path.chmod(0)
    assert load_error(str(path)) == ("PermissionError", str(path))


def test_saving_into_a_file_in_place_of_a_folder_raises_an_os_error(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    with pytest.raises(OSError) as caught:
        ktree.Tree.from_dense(np.ones((2, 2), dtype=bool)).save(str(blocker / "out.ktree"))
    assert caught.value.filename == str(blocker / "out.ktree")
    assert not isinstance(caught.value, ValueError)
    # The system's own error, its errno kept (Linux: ENOTDIR).
    if sys.platform.startswith("linux"):
        assert isinstance(caught.value, NotADirectoryError)
        assert caught.value.errno == errno.ENOTDIR
