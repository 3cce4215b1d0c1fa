"""Meshes and VTK files out, checked by other libraries: trimesh (watertight, consistently wound, the volume
and the Euler number of the voxels) and VTK (the .vtu and .htg files read back with their cell counts,
bounds and volume)."""

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
