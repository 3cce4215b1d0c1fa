"""Trees with values saved as OpenVDB typed grids (`Tree.save("x.vdb")`) and loaded back, checked against
OpenVDB's own Python module (Debian's `python3-openvdb`: `pyopenvdb`, or `openvdb` in newer releases) run in
the interpreter that imports it — `$KTREE_PYTHON_OPENVDB`, this one, `python3` on the PATH or
`/usr/bin/python3` — with arrays passed as `.npy` files. Without it the OpenVDB checks are skipped, or fail
when KTREE_REQUIRE_TOOLS is set to anything but empty or 0 (see `test_ktree.missing`)."""

import os
import subprocess

import numpy as np
import pytest

import ktree
from test_ktree import missing, python_importing


def openvdb_python():
    """The interpreter that imports OpenVDB's module, and the module's name; None when there is none."""
    for module in ("pyopenvdb", "openvdb"):
        python = python_importing(module, [os.environ.get("KTREE_PYTHON_OPENVDB")])
        if python is not None:
            return python, module
    return None


def run_openvdb(script, *args):
    """Runs `script` with OpenVDB's module imported as `vdb` and numpy as `np`: its standard output."""
    found = openvdb_python()
    if found is None:
        missing("OpenVDB's Python module", "install Debian's python3-openvdb")
    python, module = found
    code = f"import sys\nimport numpy as np\nimport {module} as vdb\n{script}"
    done = subprocess.run([python, "-c", code, *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done.stdout


def labelled(dtype):
    """A 16³ array with an 8³ block of one value (a tile of a 16³ node) and scattered voxels, none 0."""
    a = np.zeros((16, 16, 16), dtype=dtype)
    a[8:, 8:, 8:] = 3
    x, y, z = np.indices(a.shape)
    spots = (x * 7 + y * 3 + z) % 5 == 0
    a[spots & (a == 0)] = ((x + 2 * y) % 9 + 1)[spots & (a == 0)]
    if dtype == np.float32:
        a = np.where(a != 0, a * 0.25 - 5.125, 0).astype(np.float32)
    return a


@pytest.mark.parametrize("dtype", ["uint8", "uint16", "int8", "float32"])
def test_saved_vdb_loads_back_with_its_values(tmp_path, dtype):
    a = labelled(np.dtype(dtype))
    if dtype == "uint16":
        a[a == 3] = 3000
    if dtype == "int8":
        a[a == 3] = -7
    t = ktree.Tree.from_dense(a)
    path = tmp_path / "labels.vdb"
    t.save(path)
    back = ktree.Tree.load(path)
    assert back.dtype == dtype
    np.testing.assert_array_equal(back.to_dense((0, 0, 0), a.shape), a)


def test_a_float_grid_saved_by_ktree_holds_every_value_in_openvdb(tmp_path):
    a = labelled(np.float32)
    path = tmp_path / "density.vdb"
    ktree.Tree.from_dense(a).save(path)
    out = tmp_path / "dense.npy"
    tiles = run_openvdb(
        "g = vdb.read(sys.argv[1], 'ktree')\n"
        "assert type(g).__name__ == 'FloatGrid' and g.gridClass != vdb.GridClass.LEVEL_SET\n"
        "d = np.zeros((16, 16, 16), np.float32)\n"
        "on = np.zeros((16, 16, 16), bool)\n"
        "tiles = 0\n"
        "for t in g.iterOnValues():\n"
        "    (x0, y0, z0), (x1, y1, z1) = t['min'], t['max']\n"
        "    d[x0:x1 + 1, y0:y1 + 1, z0:z1 + 1] = t['value']\n"
        "    on[x0:x1 + 1, y0:y1 + 1, z0:z1 + 1] = True\n"
        "    tiles += t['count'] > 1\n"
        "np.save(sys.argv[2], np.where(on, d, np.nan))\n"
        "print(tiles)",
        path,
        out,
    )
    assert tiles.strip() == "1"  # the 8³ block
    seen = np.load(out)
    np.testing.assert_array_equal(np.isnan(seen), a == 0)
    np.testing.assert_array_equal(seen[a != 0], a[a != 0])


def test_a_float_grid_written_by_openvdb_loads_with_every_value(tmp_path):
    a = labelled(np.float32)
    src = tmp_path / "dense.npy"
    np.save(src, a)
    path = tmp_path / "openvdb.vdb"
    # Copied in at index −8 (the block then fills a 16³ node's 8³ child: a tile once pruned), written with
    # OpenVDB's default compression (Blosc, active mask).
    run_openvdb(
        "g = vdb.FloatGrid()\ng.name = 'density'\n"
        "g.copyFromArray(np.load(sys.argv[1]), ijk=(-8, -8, -8))\ng.prune()\n"
        "assert sum(t['count'] > 1 for t in g.iterOnValues()) == 1\n"
        "vdb.write(sys.argv[2], grids=[g])",
        src,
        path,
    )
    t = ktree.Tree.load(path)
    assert t.dtype == "float32"
    # Negative indices moved to 0: grid index −8 is voxel 0.
    np.testing.assert_array_equal(t.to_dense((0, 0, 0), a.shape), a)
