"""k-trees (bintrees, quadtrees, octrees, 4-D trees) with numpy arrays in and out.

Coordinates are ``[x, y, z, ...]`` as in the ``ktree`` command-line tool: a dense array ``a`` has
``a[x, y, z]`` for voxel (x, y, z), and rays run along the last axis. Long calls release the GIL; errors
are ``ValueError`` (bad input) or ``OSError`` (files: ``FileNotFoundError``, ``PermissionError``, … as the
system says, with ``filename`` set) with the library's message.
"""

from fractions import Fraction
from os import PathLike
from typing import Any, ClassVar, Literal, NamedTuple, NotRequired, Optional, Sequence, Tuple, TypedDict, Union, final

import numpy as np
import numpy.typing as npt

__version__: str
__all__ = ["MapHistory", "MapRayHits", "OccupancyMap", "RayHits", "Tree", "__version__"]

_Path = Union[str, PathLike[str]]
_View = Union[str, Sequence[float]]
_Shape = Literal["ball", "box", "cross"]

_Index = Union[int, slice]

class RayHits(NamedTuple):
    """What Tree.cast_rays returns: per ray, whether it hit, the first full voxel entered (-1s for a
    miss), t (inf for a miss), and the axis and sign of the face entered (-1 and 0 for a miss or an
    origin inside a full voxel; sign -1 is the face at voxel[axis], entered moving up the axis)."""

    hit: npt.NDArray[np.bool_]
    voxel: npt.NDArray[np.int64]
    t: npt.NDArray[np.float64]
    axis: npt.NDArray[np.int8]
    sign: npt.NDArray[np.int8]

class MapRayHits(NamedTuple):
    """What OccupancyMap.cast_rays returns: per ray, whether it hit an occupied voxel, the world centre
    of the voxel where it ended (for OUTSIDE the last voxel in the map, NaN when the origin is outside it),
    that voxel's keys (-1 where NaN) and why it ended:
    OccupancyMap.OCCUPIED (a hit), UNKNOWN, BEYOND_RANGE or OUTSIDE."""

    hit: npt.NDArray[np.bool_]
    end: npt.NDArray[np.float64]
    key: npt.NDArray[np.int64]
    reason: npt.NDArray[np.uint8]

class _LevelCounts(TypedDict):
    level: int
    full: int
    empty: int
    partial: int

class _Stats(TypedDict):
    k: int
    level: int
    rays: Optional[int]
    full: int
    empty: int
    partial: int
    nodes: int
    bytes_at_2_bits: int
    memory_bytes: int
    voxels: int
    bounding_box: Optional[list[list[int]]]
    per_level: list[_LevelCounts]
    surface_area: int
    euler_number: NotRequired[int]

class _ViewPage(TypedDict):
    boxes: int
    coarse: int
    complete: bool
    bytes: int

class _ProgressiveLevel(TypedDict):
    level: int
    lower: int
    upper: int
    nodes_touched: int

class _Mass(TypedDict):
    k: int
    volume: int
    centroid: list[float]
    central_moments: list[list[float]]
    inertia_tensor: list[list[float]]
    nodes: int
    progressive: Optional[list[_ProgressiveLevel]]
    estimate: Optional[float]
    surface_area: int
    euler_number: NotRequired[int]

class _Collision(TypedDict):
    collide: bool
    overlap_cells: int
    overlap_voxels: int
    first_contact: Optional[int]
    min_separation: Optional[float]

class _ValueStats(TypedDict):
    voxels: int
    bounding_box: tuple[list[int], list[int]]
    centroid: list[float]
    surface_area: int

@final
class Tree:
    """A k-tree of dimension K = 1...4 over a universe of side 2**level; immutable, compared by content.

    A tree made from a numeric array holds a value per voxel (`dtype`); the value methods (values,
    to_dense, select, mask, overlay, combine, relabel, value_stats) use the values, every other method
    works on its shape (the voxels with a value) and returns trees without values."""

    @staticmethod
    def from_dense(
        array: npt.ArrayLike,
        level: Optional[int] = None,
        background: float = 0.0,
        dtype: Optional[str] = None,
    ) -> Tree:
        """The tree of an array indexed [x, y, z, ...] (K = ndim), placed at the origin of a universe of
        level `level` (default: the smallest holding the longest axis). A boolean array gives a tree without
        values; a numeric one a tree with values (uint8, uint16, uint32, int8, float32; other integers the
        smallest of these holding them, float64 float32) where voxels equal to `background` are empty.
        `dtype` names the value type instead; "rgb" takes the last axis as 3 colour channels (K = ndim - 1)."""
    @staticmethod
    def empty(k: int, level: int) -> Tree:
        """The empty tree."""
    @staticmethod
    def full(k: int, level: int) -> Tree:
        """The whole universe."""
    @staticmethod
    def from_rays(rays: npt.ArrayLike, level: int) -> Tree:
        """The tree of an (n, K + 1) integer array of runs: the column's K - 1 coordinates, z1, z2
        (covering z1 <= z < z2 on the last axis)."""
    @staticmethod
    def from_mesh(
        path: _Path, level: int, transform: Optional[Tuple[float, float, float, float]] = None
    ) -> Tree:
        """The octree of an OBJ, STL or PLY mesh; `transform` (s, tx, ty, tz) maps v to s*v + t, default: fit."""
    @staticmethod
    def from_meshes(
        paths: Sequence[_Path],
        level: int,
        transform: Optional[Tuple[float, float, float, float]] = None,
    ) -> tuple[Tree, list[str]]:
        """One octree of labels from mesh files placed together: file i is label i + 1 (a single OBJ file:
        each group/object), the later mesh winning where they overlap; the tree and each label's name."""
    @staticmethod
    def from_mesh_arrays(
        vertices: npt.ArrayLike,
        faces: npt.ArrayLike,
        level: int,
        transform: Optional[Tuple[float, float, float, float]] = None,
    ) -> Tree:
        """The octree of a mesh given as (n, 3) vertices and (m, 3) triangle indices."""
    @staticmethod
    def from_points(
        points: npt.ArrayLike,
        voxel_size: float,
        origin: Optional[Tuple[float, float, float]] = None,
        level: Optional[int] = None,
        values: Optional[npt.ArrayLike] = None,
        reduce: Literal["mean", "max", "min", "mode", "count"] = "mean",
    ) -> Tree:
        """The octree of the voxels holding points of an (n, 3) array: voxel floor((p - origin) / voxel_size),
        origin default the points' minimum corner, level default the smallest holding every voxel. With
        `values` ((n,) numbers or (n, 3) uint8 colours) each voxel holds its points' values reduced by
        `reduce` ("mean", "max", "min", "mode"); "count" gives each voxel its number of points (uint32)."""
    @staticmethod
    def from_volume(
        path: _Path,
        threshold: Optional[float] = None,
        *,
        label: Optional[float] = None,
        level: Optional[int] = None,
        offset: Optional[Tuple[int, int, int]] = None,
    ) -> Tree:
        """The octree of a volume file (.json sidecar, .raw, .nii, .nii.gz): samples >= threshold (or == label),
        sample (0, 0, 0) at voxel `offset` (default (0, 0, 0))."""
    @staticmethod
    def load(path: _Path) -> Tree:
        """Reads a tree file, the format chosen by the extension."""
    def save(self, path: _Path) -> None:
        """Writes the tree atomically, the format chosen by the extension (meshes: the tree's boundary; a tree
        with values: the surface of each value, a label's part named by its name in label_names)."""
    def to_bytes(self) -> bytes:
        """The tree in the .ktree format (version 2: 2 bits a node, checksums per level; version 3 with
        values)."""
    @staticmethod
    def from_bytes(data: bytes, background: float = 0.0) -> Tree:
        """The tree of .ktree bytes (`background`: of a tree with values' dense arrays)."""
    def __reduce__(self) -> tuple[Any, tuple[bytes, float]]: ...
    @property
    def dtype(self) -> Optional[str]:
        """The value type ("uint8", "uint16", "uint32", "int8", "float32", "rgb8"), None without values."""
    @property
    def label_names(self) -> dict[int, str]:
        """The labels' names (kept by .ktree files, from_meshes, with_label_names); empty without names."""
    def with_label_names(self, names: dict[int, str]) -> Tree:
        """This tree with its integer labels named by `names` (replacing the names it had)."""
    def shape(self) -> Tree:
        """The voxels holding a value, as a tree without values."""
    def values(self, points: npt.ArrayLike, background: Optional[float] = None) -> npt.NDArray[Any]:
        """The values at an (n, K) integer array of points (the background where empty)."""
    def select(self, value: Any, hi: Any = None) -> Tree:
        """The voxels holding `value` (or a value in value..=hi), as a tree without values."""
    def mask(self, tree: Tree) -> Tree:
        """The values of the voxels inside `tree`."""
    def overlay(self, tree: Tree) -> Tree:
        """`tree`'s values where it has them, this tree's elsewhere."""
    def combine(self, tree: Tree, rule: Literal["first", "min", "max", "sum"]) -> Tree:
        """The voxels of either tree; where both hold a value, `rule` decides."""
    def relabel(self, mapping: dict[Any, Any]) -> Tree:
        """Values replaced by `mapping` (a value mapped to None is removed); the labels' names are dropped."""
    def value_stats(self) -> dict[Any, _ValueStats]:
        """Per value: voxels, bounding_box (lo, hi), centroid, surface_area."""
    @property
    def k(self) -> int:
        """The dimension K."""
    @property
    def level(self) -> int:
        """The universe level L."""
    @property
    def side(self) -> int:
        """The universe's side, 2**level."""
    @property
    def voxel_count(self) -> int:
        """Voxels inside the object."""
    @property
    def node_count(self) -> int:
        """Nodes of the tree."""
    def to_dense(
        self,
        origin: Optional[Sequence[int]] = None,
        shape: Optional[Sequence[int]] = None,
        background: Optional[float] = None,
    ) -> npt.NDArray[Any]:
        """The voxels of a window (`shape` from `origin`; default the bounding box, not the universe)
        as a boolean array indexed [x, y, z, ...]; voxels outside the universe are False. For a tree with
        values, its values with `background` (default: the one it was made with) where empty."""
    def signed_distance(
        self, origin: Optional[Sequence[int]] = None, shape: Optional[Sequence[int]] = None
    ) -> npt.NDArray[np.float32]:
        """Signed distances of a window (default the bounding box) as a float32 array indexed
        [x, y, z, ...]: scipy's edt(~a) - edt(a) on the whole universe, negative inside."""
    def to_rays(self) -> npt.NDArray[np.int64]:
        """The voxels as maximal runs: an (n, K + 1) array as from_rays reads."""
    def contains(self, points: npt.ArrayLike) -> Union[bool, npt.NDArray[np.bool_]]:
        """Whether voxels are inside: one point (K integers) or an (N, K) array."""
    def __getitem__(
        self, key: Union[_Index, Tuple[_Index, ...]], /
    ) -> Union[bool, npt.NDArray[np.bool_]]:
        """tree[x, y, z]: one voxel; with slices, the dense window of those voxels."""
    def bounding_box(self) -> Optional[Tuple[list[int], list[int]]]:
        """(lo, hi) of the full voxels, hi exclusive; None when empty."""
    def count(self, lo: Sequence[int], hi: Sequence[int]) -> int:
        """The number of full voxels in the box [lo, hi) (K integers each, hi exclusive)."""
    def crop(self, lo: Sequence[int], hi: Sequence[int]) -> Tree:
        """The object cut to the box [lo, hi), in the same universe."""
    def cells(self) -> npt.NDArray[np.int64]:
        """The full leaves as an (n, K + 1) array: corner coordinates, then side."""
    def cast_rays(
        self, origins: npt.ArrayLike, directions: npt.ArrayLike, max_t: float = ...
    ) -> RayHits:
        """The first full voxel each ray origin + t * direction (0 <= t <= max_t) enters."""
    def distance(self, points: npt.ArrayLike) -> Union[float, npt.NDArray[np.float64]]:
        """Distance between voxel centres to the nearest full voxel: 0 inside, inf when empty."""
    def nearest(self, points: npt.ArrayLike) -> npt.NDArray[np.int64]:
        """A nearest full voxel per point (rows of -1 when empty; ties: the smallest Morton key)."""
    def stats(self) -> _Stats:
        """Node counts, voxels, bounding box and measures, with the keys of `ktree stats --json --measures`."""
    def translate(self, offset: Sequence[float]) -> Tree:
        """Translated by K numbers (exact for integers)."""
    def rotate(self, degrees: float, axes: Union[str, Tuple[int, int], None] = None) -> Tree:
        """Rotated about the universe's centre in the plane (i, j) (default (0, 1)) or about 'x', 'y', 'z'."""
    def scale(self, factor: Union[int, float, Fraction]) -> Tree:
        """Scaled about the origin corner (exact for ints and Fractions)."""
    def affine(self, matrix: npt.ArrayLike) -> Tree:
        """Mapped by a homogeneous (K + 1) x (K + 1) matrix (projective if the last row is not 0 ... 0 1)."""
    def mass(self, tolerance: Optional[float] = None) -> _Mass:
        """Volume, centroid and second moments, with the keys of `ktree mass --json`."""
    def dilate(self, r: float, shape: _Shape = "ball") -> Tree:
        """The voxels within the element of radius r of a full voxel (scipy's binary_dilation)."""
    def erode(self, r: float, shape: _Shape = "ball") -> Tree:
        """The voxels whose element lies in the object, outside empty (binary_erosion, border_value=0)."""
    def opening(self, r: float, shape: _Shape = "ball") -> Tree:
        """The dilation of the erosion."""
    def closing(self, r: float, shape: _Shape = "ball") -> Tree:
        """The erosion of the dilation, unbounded by the universe, then clipped to it."""
    def components(self, connectivity: int = 1) -> list[Tree]:
        """The connected components, largest first (scipy's label with generate_binary_structure)."""
    def largest_component(self, connectivity: int = 1) -> Tree:
        """The largest connected component (empty if there is none)."""
    def surface_area(self) -> int:
        """The number of (K - 1)-faces between full and empty voxels, outside empty."""
    def euler_number(self, connectivity: Optional[int] = None) -> int:
        """The Euler number as scikit-image's measure.euler_number (connectivity 1 or K, default K)."""
    def interferes(self, other: Tree) -> bool:
        """Whether the objects share a voxel."""
    def collide(self, other: Tree, time_axis: Optional[int] = None) -> _Collision:
        """Interference, with the keys of `ktree collide --json`."""
    def to_mesh(
        self, voxel_size: float = 1.0, origin: Optional[Sequence[float]] = None, smooth: bool = False
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
        """The boundary of an octree as a closed triangle mesh: vertices (n, 3) float64, faces (m, 3) int64.

        smooth=True: a smooth surface for display (surface nets), not the exact boundary."""
    def render(
        self,
        view: Optional[_View] = None,
        width: int = 512,
        height: int = 512,
        *,
        perspective: Optional[float] = None,
        time_axis: int = 3,
        frames: int = 6,
    ) -> npt.NDArray[np.uint8]:
        """An RGB image of shape (height, width, 3) (K = 2: the cells; K = 4: a strip of time slices)."""
    def lines(
        self,
        view: Optional[_View] = None,
        width: int = 800,
        height: int = 800,
        *,
        stroke: float = 1.0,
        method: str = "bucketed",
    ) -> str:
        """An SVG line drawing of an octree with hidden lines removed."""
    def view(
        self,
        path: _Path,
        *,
        budget: int = 100000,
        camera: Optional[_View] = None,
        time_axis: int = 3,
        title: str = "ktree",
    ) -> _ViewPage:
        """Writes the interactive 3-D viewer page (HTML, as `ktree view`) of a K = 2, 3 or 4 tree."""
    def __or__(self, other: Tree, /) -> Tree: ...
    def __and__(self, other: Tree, /) -> Tree: ...
    def __sub__(self, other: Tree, /) -> Tree: ...
    def __xor__(self, other: Tree, /) -> Tree: ...
    def __ror__(self, other: Tree, /) -> Tree: ...
    def __rand__(self, other: Tree, /) -> Tree: ...
    def __rsub__(self, other: Tree, /) -> Tree: ...
    def __rxor__(self, other: Tree, /) -> Tree: ...
    def __invert__(self) -> Tree: ...
    def __eq__(self, other: object, /) -> bool: ...
    def __hash__(self) -> int: ...

@final
class MapHistory:
    """A 3-D map's history as one 4-D tree: time is the fourth axis, one position a step, and voxel
    (x, y, z, t) holds the state key (x, y, z) took at step t (OccupancyMap.FREE or OCCUPIED) where it
    changed; empty where nothing changed."""

    @property
    def steps(self) -> int:
        """The number of steps."""
    @property
    def tree(self) -> Tree:
        """The 4-D tree with uint8 values (level 16, at the map's keys and steps)."""
    def at(self, step: int) -> Tree:
        """The map's states after a step: a 3-D tree with uint8 values FREE and OCCUPIED."""
    def static_map(self) -> Tree:
        """The voxels occupied at some step and never observed free."""
    def moved(self) -> Tree:
        """The voxels occupied at some step and observed free at another."""
    def dynamic(self) -> Tree:
        """Where and when voxels that are free at some step became occupied, as a 4-D tree."""
    def save(self, path: _Path) -> None:
        """Writes the history as a .ktree file (the 4-D tree, the map's resolution and the number of
        steps; as `ktree map --history` writes), atomically."""
    @staticmethod
    def load(path: _Path) -> MapHistory:
        """Reads a history saved by save or written by `ktree map --history`."""
    @property
    def resolution(self) -> float:
        """The side of the maps' voxels."""
    def __eq__(self, other: object, /) -> bool: ...

@final
class OccupancyMap:
    """An occupancy map of dimension 2 or 3 from range scans, with OctoMap's semantics: voxels of side
    `resolution` keyed as OctoMap keys them (2**16 a side; key k along an axis covers world coordinates
    [(k - 32768) * resolution, (k - 32767) * resolution)), each unknown, free or occupied by its log-odds.

    The parts are trees in a level-16 universe whose voxel coordinates are the keys."""

    UNKNOWN: ClassVar[int]
    FREE: ClassVar[int]
    OCCUPIED: ClassVar[int]
    BEYOND_RANGE: ClassVar[int]
    OUTSIDE: ClassVar[int]
    def __new__(
        cls,
        resolution: float,
        dim: int = 3,
        prob_hit: float = 0.7,
        prob_miss: float = 0.4,
        clamp_min: float = 0.1192,
        clamp_max: float = 0.971,
        occupancy: float = 0.5,
        history: bool = False,
    ) -> OccupancyMap:
        """An empty map; the sensor model's probabilities default to OctoMap's. With `history=True` (3-D
        maps) the state after each `insert` is kept as a step of `history()`."""
    def history(self) -> MapHistory:
        """The map's history (a map made with history=True): one step for each insert so far."""
    def insert(
        self, points: npt.ArrayLike, origin: Sequence[float], max_range: Optional[float] = None
    ) -> int:
        """Integrates a scan: (N, dim) world points (as float32) seen from `origin`, rays cut at
        `max_range` (a point beyond it is no hit), as OctoMap's insertPointCloud. Returns the number of
        voxels updated."""
    def forget_outside(self, centre: Sequence[float], radius: float) -> None:
        """Forgets the voxels whose centres lie farther than `radius` from `centre` (world coordinates):
        they become unknown and lose their colours; the others keep their log-odds. Refused for a map
        that keeps a history."""
    def set_colours(self, points: npt.ArrayLike, colours: npt.ArrayLike) -> int:
        """Colours the observed voxels holding (N, 3) world points with (N, 3) uint8 colours, each voxel
        the mean of its points' colours (points in unknown voxels colour nothing), as OctoMap's
        ColorOcTree; kept by save to .ot and load. Returns the number of voxels coloured."""
    def colours(self) -> Optional[Tree]:
        """The voxels' colours as a tree with rgb values at the map's keys, or None for a map given none."""
    def states(self, points: npt.ArrayLike) -> npt.NDArray[np.uint8]:
        """The states (UNKNOWN, FREE, OCCUPIED) of the voxels holding (N, dim) world points."""
    def cast_rays(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        ignore_unknown: bool = False,
        max_range: Optional[float] = None,
    ) -> MapRayHits:
        """Casts rays through a 3-D map as OctoMap's castRay: from each origin's voxel along its
        direction ((N, 3) arrays, or 3 numbers shared by all rays; as float32) to the first occupied
        voxel (a hit), an unknown voxel (unless ignore_unknown), the first voxel whose centre is beyond
        max_range, or the map's edge. Non-finite coordinates, a zero direction or a max_range that is not
        positive are a ValueError."""
    def keys(self, points: npt.ArrayLike) -> npt.NDArray[np.int64]:
        """The (N, dim) keys of the voxels holding (N, dim) world points (rows of -1 outside the map)."""
    def occupied(self) -> Tree:
        """The occupied voxels, as a tree at the map's keys."""
    def free(self) -> Tree:
        """The free voxels (observed, not occupied), as a tree."""
    def unknown(self) -> Tree:
        """The unknown voxels (never observed), as a tree."""
    def log_odds(self) -> Tree:
        """The log-odds of the observed voxels, as a tree with float32 values (unknown voxels empty)."""
    def save(self, path: _Path) -> None:
        """Writes a 3-D map as OctoMap's .ot (every log-odds; a ColorOcTree with its colours if it has
        some) or .bt (free and occupied), or as a .ktree of its log-odds with its world frame (as `ktree
        map` writes), atomically."""
    @staticmethod
    def load(
        path: _Path,
        prob_hit: float = 0.7,
        prob_miss: float = 0.4,
        clamp_min: float = 0.1192,
        clamp_max: float = 0.971,
        occupancy: float = 0.5,
    ) -> OccupancyMap:
        """Reads a 3-D map from OctoMap's .ot or .bt file or a .ktree map, with the sensor model of these
        probabilities."""
    @property
    def resolution(self) -> float:
        """The side of a voxel."""
    @property
    def dim(self) -> int:
        """The dimension (2 or 3)."""
