"""Meshes and VTK files out, checked by other libraries: trimesh (watertight, consistently wound, the volume
and the Euler number of the voxels) and VTK (the .vtu and .htg files read back with their cell counts,
bounds and volume; for trees with values, the cell data `value` — its VTK type, its components and each
cell's value against the numpy array the tree was made of)."""

import subprocess

import numpy as np
import pytest
import trimesh
import vtk
from vtk.util.numpy_support import vtk_to_numpy

import ktree


def euler_6(a):
    """The Euler characteristic of the voxels of `a`, face-adjacent voxels connected (voxels − face pairs
    + full 2×2 squares − full 2×2×2 blocks), plus one for each point where only two opposite voxels of the
    eight around it are empty (a 2-manifold surface joins the six full ones there)."""
    p = np.pad(a.astype(bool), 1)
    chi = 0
    for mask in range(8):
        block = np.ones(tuple(s - 1 for s in p.shape), dtype=bool)
        for o in range(8):
            if o & ~mask:
                continue
            sl = tuple(slice((o >> i) & 1, p.shape[i] - 1 + ((o >> i) & 1)) for i in range(3))
            block &= p[sl]
        chi += (-1) ** bin(mask).count("1") * int(block.sum())
    # Corners with exactly two opposite empty voxels.
    octants = [
        p[tuple(slice((o >> i) & 1, p.shape[i] - 1 + ((o >> i) & 1)) for i in range(3))] for o in range(8)
    ]
    full = sum(o.astype(int) for o in octants)
    for e in range(4):
        chi += int(((full == 6) & ~octants[e] & ~octants[7 - e]).sum())
    return chi


def random_object(rng, level, density):
    side = 2**level
    a = rng.random((side,) * 3) < density
    block = 2 ** rng.integers(0, level)
    start = rng.integers(0, side // block, size=3) * block
    a[tuple(slice(s, s + block) for s in start)] = True
    return a


@pytest.mark.parametrize("seed", range(12))
def test_to_mesh_is_watertight_with_the_exact_volume_and_euler_number(seed):
    rng = np.random.default_rng(seed)
    a = random_object(rng, 3, [0.1, 0.4, 0.8][seed % 3])
    t = ktree.Tree.from_dense(a)
    vertices, faces = t.to_mesh()
    assert vertices.dtype == np.float64 and vertices.shape[1] == 3
    assert faces.dtype == np.int64 and faces.shape[1] == 3
    m = trimesh.Trimesh(vertices, faces, process=False)
    assert m.is_watertight
    assert m.is_winding_consistent
    assert m.volume == t.voxel_count
    assert m.euler_number == 2 * euler_6(a)


def test_to_mesh_in_world_units_and_two_cubes_touching_at_an_edge():
    a = np.zeros((4, 4, 4), dtype=bool)
    a[0, 0, 0] = a[1, 1, 0] = True
    vertices, faces = ktree.Tree.from_dense(a).to_mesh(voxel_size=0.5, origin=[1, 2, 3])
    m = trimesh.Trimesh(vertices, faces, process=False)
    assert m.is_watertight and m.is_winding_consistent
    assert m.volume == 2 * 0.125
    assert m.euler_number == 4  # two spheres
    assert m.bounds.tolist() == [[1, 2, 3], [2, 3, 3.5]]
    with pytest.raises(ValueError, match="K = 2"):
        ktree.Tree.from_dense(np.ones((2, 2), dtype=bool)).to_mesh()
    with pytest.raises(ValueError, match="voxel_size"):
        ktree.Tree.from_dense(a).to_mesh(voxel_size=0)


def test_save_writes_meshes_trimesh_reads(tmp_path):
    rng = np.random.default_rng(7)
    a = random_object(rng, 3, 0.3)
    t = ktree.Tree.from_dense(a)
    for ext in ["ply", "obj", "stl", "glb"]:
        path = tmp_path / f"t.{ext}"
        t.save(path)
        loaded = trimesh.load(path, force="mesh", process=False)
        assert abs(abs(loaded.volume) - t.voxel_count) < 1e-6, ext
        if ext == "ply":
            assert loaded.is_watertight and loaded.is_winding_consistent
            assert loaded.volume == t.voxel_count
            assert loaded.euler_number == 2 * euler_6(a)


def read_vtk(path):
    if path.suffix == ".vtu":
        r = vtk.vtkXMLUnstructuredGridReader()
    else:
        r = vtk.vtkXMLHyperTreeGridReader()
    r.SetFileName(str(path))
    r.Update()
    data = r.GetOutput()
    if path.suffix == ".htg":
        to_grid = vtk.vtkHyperTreeGridToUnstructuredGrid()
        to_grid.SetInputData(data)
        to_grid.Update()
        data = to_grid.GetOutput()
    sizes = vtk.vtkCellSizeFilter()
    sizes.SetInputData(data)
    sizes.Update()
    return data, sizes.GetOutput()


@pytest.mark.parametrize("k", [2, 3])
def test_vtk_reads_the_vtu_and_htg_back(tmp_path, k):
    rng = np.random.default_rng(k)
    level = 4 if k == 2 else 3
    a = rng.random((2**level,) * k) < 0.4
    a[(0,) * k] = True
    t = ktree.Tree.from_dense(a)
    leaves = t.stats()["full"]
    for ext in ["vtu", "htg"]:
        path = tmp_path / f"t.{ext}"
        t.save(path)
        data, sized = read_vtk(path)
        assert data.GetNumberOfCells() == leaves, ext
        key = "Volume" if k == 3 else "Area"
        assert vtk_to_numpy(sized.GetCellData().GetArray(key)).sum() == t.voxel_count, ext
        assert vtk_to_numpy(data.GetCellData().GetArray("side")).max() <= 2**level
        levels = vtk_to_numpy(data.GetCellData().GetArray("level"))
        assert levels.min() >= 0 and levels.max() <= level
        lo = np.argwhere(a).min(axis=0)
        hi = np.argwhere(a).max(axis=0) + 1
        bounds = np.array(data.GetBounds()).reshape(3, 2)
        # Bounds of the cells: the full voxels' box (to_dense's axes are the tree's axes).
        assert bounds[:k, 0].tolist() == lo.tolist() or bounds[:k, 0].tolist() == lo[::-1].tolist()
        assert sorted(bounds[:k, 1].tolist()) == sorted(hi.tolist())


def test_to_mesh_smooth_is_watertight_near_the_voxels_volume():
    side = 32
    centres = np.indices((side,) * 3) + 0.5 - side / 2
    a = (centres**2).sum(axis=0) <= (side / 2) ** 2
    t = ktree.Tree.from_dense(a)
    m = trimesh.Trimesh(*t.to_mesh(smooth=True), process=False)
    assert m.is_watertight and m.is_winding_consistent
    assert abs(m.volume - t.voxel_count) < 0.01 * t.voxel_count
    exact = trimesh.Trimesh(*t.to_mesh(), process=False)
    assert m.volume != exact.volume


# --- trees with values: the cell data `value` -------------------------------------------------------------

VTK_TYPES = {"uint8": vtk.VTK_UNSIGNED_CHAR, "uint16": vtk.VTK_UNSIGNED_SHORT, "int8": vtk.VTK_SIGNED_CHAR,
             "float32": vtk.VTK_FLOAT, "rgb8": vtk.VTK_UNSIGNED_CHAR}


def convert(src, out):
    from test_ktree import cli

    subprocess.run([cli(), "convert", str(src), str(out)], check=True, capture_output=True, text=True)


def check_cells_hold(data, dense, k, components):
    """Each cell of `data` (voxels of side 1 from 0) covers voxels of `dense` that all hold its `value`, and
    the cells cover every voxel with a value: the cell's centre and extent give the voxels."""
    values = vtk_to_numpy(data.GetCellData().GetArray("value"))
    if components == 1:
        values = values.reshape(-1, 1)
    covered = np.zeros(dense.shape[:k], bool)
    for c in range(data.GetNumberOfCells()):
        b = np.array(data.GetCell(c).GetBounds()).reshape(3, 2)[:k]
        box = tuple(slice(int(round(lo)), int(round(hi))) for lo, hi in b)
        centre = tuple(int((lo + hi) / 2) for lo, hi in b)
        want = dense[centre].reshape(-1)
        np.testing.assert_array_equal(values[c], want)
        region = dense[box].reshape(-1, components)
        assert (region == want).all(), (c, box)
        assert not covered[box].any()
        covered[box] = True
    np.testing.assert_array_equal(covered, (dense != 0).reshape(dense.shape[:k] + (-1,)).any(axis=-1))


def read_value_files(tmp_path, write, k, dtype, components, dense):
    """`write(path)` writes the tree of `dense` as `path` (.vtu, .htg): VTK reads back every value."""
    for ext in ["vtu", "htg"]:
        path = tmp_path / f"v.{ext}"
        write(path)
        if ext == "htg":
            r = vtk.vtkXMLHyperTreeGridReader()
            r.SetFileName(str(path))
            r.Update()
            grid = r.GetOutput()
            raw = grid.GetCellData().GetArray("value")
            assert raw.GetDataType() == VTK_TYPES[dtype] and raw.GetNumberOfComponents() == components
            assert raw.GetNumberOfTuples() == grid.GetNumberOfCells()
        data, _ = read_vtk(path)
        array = data.GetCellData().GetArray("value")
        assert array is not None, ext
        assert array.GetDataType() == VTK_TYPES[dtype], ext
        assert array.GetNumberOfComponents() == components, ext
        if ext == "vtu":
            # The active scalars (VTK's hyper tree grid reader does not read CellData's Scalars).
            assert data.GetCellData().GetScalars().GetName() == "value"
        check_cells_hold(data, dense, k, components)
        if ext == "htg" and dtype == "float32":
            # A vertex without a value (one with children, or an empty leaf) holds NaN.
            nan = np.isnan(vtk_to_numpy(raw)).sum()
            assert nan == grid.GetNumberOfCells() - data.GetNumberOfCells()


@pytest.mark.parametrize("k", [2, 3])
@pytest.mark.parametrize("dtype", ["uint8", "uint16", "int8", "float32"])
@pytest.mark.parametrize("by", ["convert", "save"])
def test_vtk_reads_the_values_of_a_tree_with_values(tmp_path, k, dtype, by):
    rng = np.random.default_rng(10 * k + len(dtype))
    level = 4 if k == 2 else 3
    a = rng.integers(0, 4, size=(2**level,) * k)
    # Blocks of one value, so that leaves of several voxels are cells too.
    a[(slice(0, 2**level // 2),) * k] = 2
    a = a.astype(dtype)
    if dtype == "float32":
        a = a * np.float32(0.1)
        a[(1,) * k] = np.float32(-2.5e-7)
        a[(2,) * k] = np.inf
        # The last vertex of the .htg (the last voxel, empty, in a block with a value) holds NaN.
        a[(-1,) * k] = 0
        a[(-2,) + (-1,) * (k - 1)] = np.float32(0.3)
    elif dtype == "int8":
        a[(1,) * k] = -128
    t = ktree.Tree.from_dense(a)
    src = tmp_path / "v.ktree"
    t.save(src)
    write = (lambda out: convert(src, out)) if by == "convert" else t.save
    read_value_files(tmp_path, write, k, dtype, 1, a)


def test_vtk_reads_the_colours_of_a_point_cloud(tmp_path):
    from test_ktree import rgb_tree

    rng = np.random.default_rng(7)
    side = 8
    colours = rng.integers(1, 3, size=(side, side, side, 3)).astype(np.uint8) * 120
    colours[rng.random((side,) * 3) < 0.5] = 0  # no point: an empty voxel
    colours[:4, :4, :4] = [10, 20, 30]
    src = rgb_tree(tmp_path, colours)
    read_value_files(tmp_path, lambda out: convert(src, out), 3, "rgb8", 3, colours)
