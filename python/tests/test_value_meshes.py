"""The surfaces of a tree's values written by `ktree convert` (.ply, .obj with its .mtl, .glb), read by trimesh:
per value a watertight surface enclosing the value's voxels (its volume against numpy's count), coloured by
the palette (labels), the ramp (floats) or the colours themselves; the PLY with every face once."""

import colorsys
import subprocess

import numpy as np
import pytest
import trimesh

import ktree

VOXEL = 0.5


def label_colour(label):
    """ktree's palette (`display::palette::label_colour`): hues a golden angle apart."""
    hue = (label * 0.618_033_988_749_895) % 1.0
    return np.array([round(c * 255) for c in colorsys.hsv_to_rgb(hue, 0.65, 0.95)])


def ramp(t):
    """ktree's ramp for floats: viridis's colours at 0, ¼, ½, ¾ and 1, linear between them."""
    stops = np.array([[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]], float)
    t = min(max(t, 0.0), 1.0) * 4
    i = min(int(t), 3)
    return np.round(stops[i] + (t - i) * (stops[i + 1] - stops[i])).astype(int)


def labels(rng, side=8):
    """Labels 1 to 4 in blocks touching each other and the universe's side, 0 the background."""
    a = np.zeros((side,) * 3, np.uint16)
    for _ in range(10):
        lo = rng.integers(0, side, size=3)
        hi = np.minimum(lo + rng.integers(1, 5, size=3), side)
        a[tuple(slice(l, h) for l, h in zip(lo, hi))] = rng.integers(0, 5)
    return a


def convert(tmp_path, a, name):
    from test_ktree import cli

    src = tmp_path / "v.ktree"
    ktree.Tree.from_dense(a).save(src)
    out = tmp_path / name
    subprocess.run(
        [cli(), "convert", str(src), str(out), "--voxel-size", str(VOXEL)],
        check=True, capture_output=True, text=True,
    )
    return out


def values_of(a):
    """The values of `a` other than the background, with their voxel counts."""
    flat = a.reshape(-1, 3) if a.ndim == 4 else a.reshape(-1)
    keep = flat.any(axis=-1) if a.ndim == 4 else flat != 0
    values, counts = np.unique(flat[keep], axis=0, return_counts=True)
    return values, counts


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("ext", ["obj", "glb"])
@pytest.mark.parametrize("by", ["convert", "save"])
def test_each_label_is_a_watertight_group_of_its_volume_and_colour(tmp_path, seed, ext, by):
    a = labels(np.random.default_rng(seed))
    if by == "convert":
        out, voxel = convert(tmp_path, a, f"labels.{ext}"), VOXEL
    else:
        # Tree.save: voxels of side 1 from the origin.
        out, voxel = tmp_path / f"saved.{ext}", 1.0
        ktree.Tree.from_dense(a).save(out)
    scene = trimesh.load(out, process=False)
    values, counts = values_of(a)
    assert sorted(scene.geometry) == sorted(f"label_{v}" for v in values)
    for v, n in zip(values, counts):
        m = scene.geometry[f"label_{v}"]
        assert m.is_watertight and m.is_winding_consistent
        assert m.volume == pytest.approx(n * voxel**3)
        material = m.visual.material
        if ext == "obj":
            colour = np.asarray(material.diffuse)[:3]
            np.testing.assert_allclose(colour, label_colour(int(v)), atol=1)
        else:
            # glTF's factors are linear: back to sRGB.
            linear = np.asarray(material.baseColorFactor)[:3] / 255.0
            srgb = np.where(linear <= 0.0031308, linear * 12.92, 1.055 * linear ** (1 / 2.4) - 0.055) * 255
            np.testing.assert_allclose(srgb, label_colour(int(v)), atol=3)


def ply_faces(path):
    m = trimesh.load(path, process=False)
    return m, m.metadata["_ply_raw"]["face"]["data"]


@pytest.mark.parametrize("seed", range(4))
def test_the_ply_has_every_face_once_and_each_label_bounded_by_its_faces(tmp_path, seed):
    a = labels(np.random.default_rng(10 + seed))
    m, faces = ply_faces(convert(tmp_path, a, "labels.ply"))
    label, back, empty = faces["label"], faces["label_back"], faces["back_empty"] == 1
    # Once: no face between two labels from the larger one's side.
    assert np.all(empty | (label < back))
    np.testing.assert_array_equal(m.visual.face_colors[:, :3], [label_colour(int(v)) for v in label])
    # The face areas between each pair against numpy's count of voxel faces (from the smaller label).
    p = np.pad(a, 1)
    want = {}
    for axis in range(3):
        lo = np.take(p, range(0, p.shape[axis] - 1), axis=axis).ravel()
        hi = np.take(p, range(1, p.shape[axis]), axis=axis).ravel()
        for x, y in zip(lo[lo != hi], hi[lo != hi]):
            x, y = (x, y) if (x < y and x != 0) or y == 0 else (y, x)
            want[(int(x), int(y))] = want.get((int(x), int(y)), 0) + 1
    got = {}
    for v, w, e, area in zip(label, back, empty, m.area_faces):
        key = (int(v), 0 if e else int(w))
        got[key] = got.get(key, 0) + area / VOXEL**2
    assert got.keys() == want.keys()
    for key in want:
        assert got[key] == pytest.approx(want[key])
    # Each label's volume from its faces and, turned over, those of the labels behind.
    values, counts = values_of(a)
    for v, n in zip(values, counts):
        own = m.faces[label == v]
        behind = m.faces[~empty & (back == v)][:, ::-1]
        part = trimesh.Trimesh(m.vertices, np.vstack([own, behind]), process=False)
        assert part.volume == pytest.approx(n * VOXEL**3)


def test_colours_and_floats_colour_their_faces(tmp_path):
    from test_ktree import cli, rgb_tree

    a = labels(np.random.default_rng(3))
    palette = np.array([[0, 0, 0], [200, 10, 10], [10, 200, 10], [10, 10, 200], [120, 120, 0]], np.uint8)
    src = rgb_tree(tmp_path, palette[a])
    out = tmp_path / "rgb.ply"
    subprocess.run([cli(), "convert", str(src), str(out)], check=True, capture_output=True, text=True)
    m, faces = ply_faces(out)
    assert "red_back" in faces.dtype.names
    # Each face the colour of the voxel inside it.
    inside = np.floor(m.triangles_center - 0.25 * m.face_normals).astype(int)
    np.testing.assert_array_equal(m.visual.face_colors[:, :3], palette[a[tuple(inside.T)]])

    f = (a * 0.5).astype(np.float32)
    m, faces = ply_faces(convert(tmp_path, f, "f.ply"))
    lo, hi = f[f != 0].min(), f[f != 0].max()
    want = [ramp((v - lo) / (hi - lo)) for v in faces["value"]]
    np.testing.assert_allclose(m.visual.face_colors[:, :3], want, atol=1)
