"""Meshes as labels (`Tree.from_meshes`): several mesh files, or one OBJ file's groups, in one tree of labels
that equals, voxel for voxel, each mesh voxelized alone by `Tree.from_mesh` in the same placement and painted
in order (the later mesh wins); bad input is an error naming the file."""

import pickle
import subprocess

import numpy as np
import pytest
import trimesh

import ktree
from test_ktree import cli, run_json

# A box's corners i at (i & 1, i >> 1 & 1, i >> 2 & 1) and its triangles, counter-clockwise from outside.
CUBE = [[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
        [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]]


def obj_box(lo, hi, base=0, faces=12):
    lines = []
    for i in range(8):
        c = [hi[a] if i >> a & 1 else lo[a] for a in range(3)]
        lines.append("v {} {} {}".format(*c))
    for t in CUBE[:faces]:
        lines.append("f {} {} {}".format(*(base + v + 1 for v in t)))
    return "\n".join(lines) + "\n"


BOXES = [([0, 0, 0], [2, 2, 1]), ([1, 1, 0.5], [3, 1.5, 2]), ([0.5, 2.5, 0], [1.5, 3.5, 3])]
TRANSFORM = (4.0, 1.0, 2.0, 0.5)


def universe(tree):
    """The whole universe as a dense array."""
    return tree.to_dense(origin=(0, 0, 0), shape=(1 << tree.level,) * 3)


def painted(paths, level):
    """Each mesh alone by the binary voxelizer, painted in order."""
    side = 1 << level
    want = np.zeros((side,) * 3, np.uint8)
    for i, p in enumerate(paths):
        alone = universe(ktree.Tree.from_mesh(p, level, transform=TRANSFORM))
        assert alone.any(), p
        want[alone] = i + 1
    return want


def test_files_are_labels_in_order(tmp_path):
    paths = []
    for i, (lo, hi) in enumerate(BOXES):
        p = tmp_path / f"m{i}.obj"
        p.write_text(obj_box(lo, hi))
        paths.append(p)
    tree, names = ktree.Tree.from_meshes(paths, 5, transform=TRANSFORM)
    assert names == [str(p) for p in paths]
    assert tree.dtype == "uint8"
    np.testing.assert_array_equal(universe(tree), painted(paths, 5))
    # Another order: other winners where the boxes overlap.
    tree, _ = ktree.Tree.from_meshes(paths[::-1], 5, transform=TRANSFORM)
    np.testing.assert_array_equal(universe(tree), painted(paths[::-1], 5))


def test_one_obj_file_s_groups_are_labels(tmp_path):
    scene = ""
    paths = []
    for i, (lo, hi) in enumerate(BOXES):
        scene += f"g part{i}\n" + obj_box(lo, hi, base=8 * i)
        p = tmp_path / f"part{i}.obj"
        p.write_text(obj_box(lo, hi))
        paths.append(p)
    (tmp_path / "scene.obj").write_text(scene)
    tree, names = ktree.Tree.from_meshes([tmp_path / "scene.obj"], 5, transform=TRANSFORM)
    assert names == ["part0", "part1", "part2"]
    np.testing.assert_array_equal(universe(tree), painted(paths, 5))
    # Fitted: the union of the boxes.
    tree, _ = ktree.Tree.from_meshes([tmp_path / "scene.obj"], 4)
    assert sorted(tree.value_stats()) == [1, 2, 3]


def test_bad_input_names_the_file(tmp_path):
    scene = tmp_path / "scene.obj"
    scene.write_text("g shut\n" + obj_box([0] * 3, [1] * 3) + "g holed\n" + obj_box([2] * 3, [3] * 3, 8, 11))
    with pytest.raises(ValueError, match="scene.obj.*'holed'.*not closed"):
        ktree.Tree.from_meshes([scene], 4)
    with pytest.raises(OSError, match="missing.stl"):
        ktree.Tree.from_meshes([scene, tmp_path / "missing.stl"], 4)
    with pytest.raises(ValueError):
        ktree.Tree.from_meshes([], 4)


def test_labels_keep_their_names(tmp_path):
    """The names travel with the labels: through .ktree files both ways between Python and the command line,
    bytes and pickling, and the operations that keep the labels' meaning; relabel drops them."""
    scene = "".join(f"g part{i}\n" + obj_box(lo, hi, base=8 * i) for i, (lo, hi) in enumerate(BOXES))
    (tmp_path / "scene.obj").write_text(scene)
    tree, names = ktree.Tree.from_meshes([tmp_path / "scene.obj"], 5, transform=TRANSFORM)
    want = {1: "part0", 2: "part1", 3: "part2"}
    assert tree.label_names == want
    tree.save(tmp_path / "py.ktree")
    assert ktree.Tree.load(tmp_path / "py.ktree").label_names == want
    assert ktree.Tree.from_bytes(tree.to_bytes()).label_names == want
    assert pickle.loads(pickle.dumps(tree)).label_names == want
    # The command line reads Python's names, and Python the command line's.
    stats = run_json("stats", tmp_path / "py.ktree")
    assert {int(v): s["name"] for v, s in stats["values"].items()} == want
    out = tmp_path / "cli.ktree"
    subprocess.run(
        [cli(), "voxelize", str(tmp_path / "scene.obj"), "--labels", "--level", "5", "--fit", "--out", str(out)],
        check=True,
        capture_output=True,
    )
    assert ktree.Tree.load(out).label_names == want
    # Kept where the labels keep their meaning, dropped where they change.
    assert tree.mask(tree.shape()).label_names == want
    assert tree.translate((1, 0, 0)).label_names == want
    assert tree.relabel({1: 7}).label_names == {}
    assert tree.shape().label_names == {}
    renamed = tree.with_label_names({2: "post"})
    assert renamed.label_names == {2: "post"}
    assert renamed == tree  # the same voxels and values
    assert ktree.Tree.from_bytes(renamed.to_bytes()).label_names == {2: "post"}
    # Saved as a mesh, each label's part is named by its name (OBJ groups and materials, checked with
    # trimesh, which loads each material's part as its own geometry; glTF meshes).
    renamed.save(tmp_path / "parts.obj")
    scene = trimesh.load(tmp_path / "parts.obj", force="scene", group_material=True)
    materials = {g.visual.material.name for g in scene.geometry.values()}
    assert materials == {"label_1", "post", "label_3"}, materials
    tree.save(tmp_path / "parts.glb")
    glb = trimesh.load(tmp_path / "parts.glb", force="scene")
    assert set(glb.geometry) == set(want.values()), set(glb.geometry)
    with pytest.raises(ValueError, match="label 300"):
        tree.with_label_names({300: "too big"})
    with pytest.raises(ValueError, match="line break"):
        tree.with_label_names({1: "two\nlines"})
    with pytest.raises(ValueError, match="float32"):
        ktree.Tree.from_dense(np.ones((2, 2), np.float32)).with_label_names({1: "x"})
