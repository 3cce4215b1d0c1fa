//! Triangle meshes to rays: OBJ (tobj), STL ASCII and binary (stl_io) and PLY (ply-rs).
//!
//! **Placement.** A vertex `v` goes to voxel coordinates `s·v + t` ([`MeshTransform`]), computed in `f64` and then
//! rounded to the nearest multiple of 2^−16 voxel; every later step is exact integer arithmetic, so a result
//! is reproducible bit for bit. [`MeshTransform::fit`] scales and centres a mesh into the universe with a one-voxel
//! margin.
//!
//! **Inside rule.** A voxel is inside when its centre is: the column through the centre `(x+½, y+½)` is
//! crossed by the triangles whose projection covers it, each crossing counted `+1` where the triangle faces
//! down (`−z`: the column enters) and `−1` where it faces up, and a centre is inside when the sum of the
//! crossings below it is non-zero (non-zero winding rule; a centre exactly on the surface is inside).
//! **Ties.** Whether a column passing exactly through a vertex or along an edge is covered is decided by
//! simulation of simplicity: the column is treated as moved by an infinitesimal `(ε, ε²)`, which never lies on
//! an edge. Every point of the plane is then covered by the same number of up- and down-facing triangles of a
//! closed mesh, so watertight meshes never leak. Triangles whose projection has zero area are skipped (the
//! moved column never meets them). In effect a centre on the surface is inside where the column crosses the
//! surface there (closed along z), and where the column only touches the surface — a vertical face, a
//! silhouette edge or vertex — the moved column decides: a box `[lo, hi]` covers the centres in
//! `[lo, hi)` across x and y and `[lo, hi]` along z.
//!
//! **Open meshes.** [`MeshRays::open_edges`] counts edges not shared by exactly two triangles; the rule above
//! is still applied, column by column, so a hole can make some columns leak (runs to the universe's face) or
//! lose runs. Callers should warn (the CLI does).
//!
//! **Work:** `O(triangles + rays)` plus a radix sort of the crossings: each triangle visits only the columns
//! in its bounding box.
//!
//! **Slab by slab.** [`MeshSource`] gives the same runs one slab of columns at a time, from the triangles
//! its index lists for the slab, for building trees out of core without holding the whole ray set.
//!
//! ```
//! use ktree::solid::mesh::{MeshTransform, TriangleMesh};
//! use std::path::Path;
//! let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/meshes/bunny_npm.obj");
//! let bunny = TriangleMesh::read(&path).unwrap();
//! let placement = MeshTransform::fit(&bunny, 6).unwrap(); // scaled and centred into a 64³ universe
//! let voxels = bunny.to_rays(6, &placement).unwrap();
//! assert_eq!(voxels.open_edges, bunny.open_edges());
//! assert!(voxels.rays.voxel_count() > 1000);
//! ```

use std::borrow::Cow;
use std::convert::Infallible;
use std::ops::Range;
use std::path::Path;

use super::SolidError;
use crate::radix::radix_sort;
use crate::rays::source::default_split_depth;
use crate::rays::RaySet;
use crate::rays::{RaySource, SlabRuns};
use crate::space::Universe;

/// Bits of sub-voxel precision of placed vertices.
const FRAC: u32 = 16;
/// The largest level for meshes: a crossing is packed as column (2L bits), position (L + 1) and sign (1).
pub const MAX_LEVEL: u32 = 20;
/// Placed coordinates must lie within ±2^22 voxels (keeps every product inside `i128`).
const LIMIT: f64 = (1u64 << 22) as f64;

/// The mesh file extensions [`TriangleMesh::read`] knows.
const MESH_FORMATS: [&str; 3] = ["obj", "stl", "ply"];

/// A triangle mesh: vertex positions and triangles as vertex indices, checked when made (finite vertices,
/// indices in range, at least one triangle).
///
/// ```
/// use ktree::solid::mesh::TriangleMesh;
/// let v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let t = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
/// let tetrahedron = TriangleMesh::new(v.clone(), t).unwrap();
/// assert!((tetrahedron.signed_volume() - 1.0 / 6.0).abs() < 1e-12);
/// assert!(TriangleMesh::new(v, vec![[0, 1, 4]]).is_err()); // no vertex 4
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleMesh {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

/// Where a mesh goes in the universe: voxel coordinate = `scale · v + translate`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshTransform {
    /// Uniform scale.
    pub scale: f64,
    /// Translation, in voxels.
    pub translate: [f64; 3],
}

impl MeshTransform {
    /// Parses `s,tx,ty,tz`.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] for anything else.
    pub fn parse(text: &str) -> Result<Self, SolidError> {
        let v: Vec<f64> = text
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| {
                SolidError::BadParameter(format!("transform '{text}': expected s,tx,ty,tz"))
            })?;
        if v.len() != 4 || !v.iter().all(|x| x.is_finite()) || v[0] == 0.0 {
            return Err(SolidError::BadParameter(format!(
                "transform '{text}': expected four finite numbers s,tx,ty,tz with s ≠ 0"
            )));
        }
        Ok(Self {
            scale: v[0],
            translate: [v[1], v[2], v[3]],
        })
    }

    /// Uniform scale and centring of `mesh` into a universe of level `level`, one voxel of margin each side.
    ///
    /// # Errors
    /// [`SolidError::Space`] for a bad level; [`SolidError::BadParameter`] for an empty or flat mesh.
    pub fn fit(mesh: &TriangleMesh, level: u32) -> Result<Self, SolidError> {
        let (lo, hi) = mesh
            .bounds()
            .ok_or_else(|| SolidError::BadParameter("the mesh has no vertex".into()))?;
        let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
        let side = Universe::<3>::new(level)?.side() as f64;
        if extent.is_nan() || extent <= 0.0 || side <= 2.0 {
            return Err(SolidError::BadParameter(
                "cannot fit: the mesh has no extent or the universe is smaller than 4 voxels"
                    .into(),
            ));
        }
        let scale = (side - 2.0) / extent;
        let translate = std::array::from_fn(|a| side / 2.0 - scale * (lo[a] + hi[a]) / 2.0);
        Ok(Self { scale, translate })
    }

    /// `s,tx,ty,tz` (what [`MeshTransform::parse`] reads).
    pub fn to_arg(&self) -> String {
        format!(
            "{},{},{},{}",
            self.scale, self.translate[0], self.translate[1], self.translate[2]
        )
    }

    /// The voxel coordinates of `v`.
    pub fn apply(&self, v: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|a| self.scale * v[a] + self.translate[a])
    }
}

/// Where a mesh goes in the universe, for [`KTree::from_mesh`](crate::KTree::from_mesh).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Placement {
    /// Scaled uniformly and centred into the universe with one voxel of margin each side
    /// ([`MeshTransform::fit`]).
    Fit,
    /// Voxel coordinate = `scale · v + translate`.
    Transform(MeshTransform),
}

impl Placement {
    /// The transform this placement gives `mesh` in a universe of level `level`.
    ///
    /// # Errors
    /// As [`MeshTransform::fit`].
    pub fn transform(&self, mesh: &TriangleMesh, level: u32) -> Result<MeshTransform, SolidError> {
        match self {
            Self::Fit => MeshTransform::fit(mesh, level),
            Self::Transform(t) => Ok(*t),
        }
    }
}

/// The rays of a mesh and what was noticed on the way.
#[derive(Debug, Clone)]
pub struct MeshRays {
    /// The voxels whose centres are inside.
    pub rays: RaySet<3>,
    /// Edges not shared by exactly two triangles (0 for a closed 2-manifold mesh).
    pub open_edges: usize,
    /// Triangles skipped because their projection along z has zero area.
    pub vertical_triangles: usize,
}

impl TriangleMesh {
    /// Reads a mesh, choosing the format by extension: `.obj`, `.stl` (ASCII or binary), `.ply`.
    ///
    /// # Errors
    /// [`SolidError::Io`] when the file cannot be read, [`SolidError::Parse`] naming the file (and the line
    /// where the parser tells it) otherwise.
    pub fn read(path: &Path) -> Result<Self, SolidError> {
        let format = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        if !MESH_FORMATS.contains(&format.as_str()) {
            return Self::from_bytes(&[], &format, path);
        }
        let bytes = std::fs::read(path).map_err(|source| SolidError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_bytes(&bytes, &format, path)
    }

    /// Parses a mesh held in memory; `format` is the extension without the dot (`obj`, `stl`, `ply`, any case),
    /// `file` names the input in errors. [`TriangleMesh::read`] reads a file and calls this.
    ///
    /// ```
    /// use std::path::Path;
    /// use ktree::solid::mesh::TriangleMesh;
    /// let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    /// let mesh = TriangleMesh::from_bytes(obj, "obj", Path::new("mem.obj")).unwrap();
    /// assert_eq!(mesh.triangles().len(), 1);
    /// assert!(TriangleMesh::from_bytes(b"f 1 2 9\n", "obj", Path::new("bad.obj")).is_err());
    /// ```
    ///
    /// # Errors
    /// [`SolidError::Parse`] naming `file` and what is wrong.
    pub fn from_bytes(bytes: &[u8], format: &str, file: &Path) -> Result<Self, SolidError> {
        let parse = |what: String| SolidError::Parse {
            path: file.to_path_buf(),
            what,
        };
        let mesh = match format.to_ascii_lowercase().as_str() {
            "obj" => {
                let opts = tobj::LoadOptions {
                    triangulate: true,
                    single_index: false,
                    ignore_points: true,
                    ignore_lines: true,
                };
                let (models, _) = tobj::load_obj_buf(&mut &bytes[..], &opts, |_| {
                    Err(tobj::LoadError::OpenFileFailed)
                })
                .map_err(|e| parse(format!("OBJ: {e}")))?;
                let mut mesh = Self {
                    vertices: Vec::new(),
                    triangles: Vec::new(),
                };
                for m in models {
                    let base = mesh.vertices.len() as u32;
                    let p = &m.mesh.positions;
                    mesh.vertices.extend(
                        p.chunks_exact(3)
                            .map(|c| [f64::from(c[0]), f64::from(c[1]), f64::from(c[2])]),
                    );
                    mesh.triangles.extend(
                        m.mesh
                            .indices
                            .chunks_exact(3)
                            .map(|t| [base + t[0], base + t[1], base + t[2]]),
                    );
                }
                mesh
            }
            "stl" => {
                let m = stl_io::read_stl(&mut std::io::Cursor::new(bytes))
                    .map_err(|e| parse(format!("STL: {e}")))?;
                Self {
                    vertices: m.vertices.iter().map(|v| v.0.map(f64::from)).collect(),
                    triangles: m
                        .faces
                        .iter()
                        .map(|f| f.vertices.map(|i| i as u32))
                        .collect(),
                }
            }
            "ply" => read_ply(bytes).map_err(parse)?,
            other => {
                return Err(parse(format!(
                    "unknown mesh format '.{other}' (known: .obj, .stl, .ply)"
                )))
            }
        };
        Self::new(mesh.vertices, mesh.triangles).map_err(|e| parse(e.to_string()))
    }

    /// A mesh of `vertices` and `triangles` (three indices into `vertices` each, counter-clockwise seen from
    /// outside).
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] when a vertex is not finite, a triangle refers to a missing vertex, or
    /// there is no triangle.
    pub fn new(vertices: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Result<Self, SolidError> {
        let mesh = Self {
            vertices,
            triangles,
        };
        mesh.validate().map_err(SolidError::BadParameter)?;
        Ok(mesh)
    }

    /// The vertex positions.
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }

    /// The triangles, three indices into [`TriangleMesh::vertices`] each.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    fn validate(&self) -> Result<(), String> {
        let n = self.vertices.len();
        if let Some((i, t)) = self
            .triangles
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&v| v as usize >= n))
        {
            return Err(format!(
                "triangle {i} refers to vertex {t:?} but there are {n} vertices"
            ));
        }
        if let Some(i) = self
            .vertices
            .iter()
            .position(|v| !v.iter().all(|x| x.is_finite()))
        {
            return Err(format!("vertex {i} is not finite"));
        }
        if self.triangles.is_empty() {
            return Err("no triangle".into());
        }
        Ok(())
    }

    /// The axis-aligned bounding box `(lo, hi)`, `None` without vertices.
    pub fn bounds(&self) -> Option<([f64; 3], [f64; 3])> {
        let first = *self.vertices.first()?;
        Some(self.vertices.iter().fold((first, first), |(lo, hi), v| {
            (
                std::array::from_fn(|a| lo[a].min(v[a])),
                std::array::from_fn(|a| hi[a].max(v[a])),
            )
        }))
    }

    fn corners(&self, t: &[u32; 3]) -> [[f64; 3]; 3] {
        t.map(|i| self.vertices[i as usize])
    }

    /// The signed volume enclosed (positive for outward orientation), by the divergence theorem.
    pub fn signed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = self.corners(t);
                dot(a, cross(b, c)) / 6.0
            })
            .sum()
    }

    /// The total surface area.
    pub fn surface_area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = self.corners(t);
                let n = cross(sub(b, a), sub(c, a));
                dot(n, n).sqrt() / 2.0
            })
            .sum()
    }

    /// The number of edges not shared by exactly two triangles.
    pub fn open_edges(&self) -> usize {
        // Every edge as one sortable key (lower vertex, higher vertex); equal edges end up side by side.
        let bits = u64::BITS - (self.vertices.len() as u64).leading_zeros();
        let mut edges: Vec<u64> = self
            .triangles
            .iter()
            .flat_map(|t| {
                (0..3).map(move |k| {
                    let (a, b) = (u64::from(t[k]), u64::from(t[(k + 1) % 3]));
                    a.min(b) << bits | a.max(b)
                })
            })
            .collect();
        radix_sort(&mut edges, 2 * bits, &mut Vec::new());
        edges
            .chunk_by(|a, b| a == b)
            .filter(|uses| uses.len() != 2)
            .count()
    }

    /// The voxels of a level-`level` octree universe whose centres are inside the placed mesh, as rays.
    ///
    /// # Errors
    /// [`SolidError::Space`] for a bad level, [`SolidError::BadParameter`] above [`MAX_LEVEL`];
    /// [`SolidError::BadParameter`] when a placed vertex lies farther than 2^22 voxels from the origin.
    pub fn to_rays(&self, level: u32, placement: &MeshTransform) -> Result<MeshRays, SolidError> {
        let placed = Placed::new(self, level, placement)?;
        let mut events = Vec::new();
        let mut vertical = 0;
        for t in &self.triangles {
            match placed.prepare(t) {
                Some(tri) => placed.crossings(&tri, 0..placed.side, &mut events),
                None => vertical += 1,
            }
        }
        let (columns, runs) = placed.runs(events);
        Ok(MeshRays {
            rays: RaySet::from_sorted_parts(placed.universe, columns, runs, None),
            open_edges: self.open_edges(),
            vertical_triangles: vertical,
        })
    }
}

/// A mesh's vertices placed in a universe, in fixed point (`FRAC` bits below the voxel).
#[derive(Debug, Clone)]
struct Placed {
    universe: Universe<3>,
    side: i64,
    fixed: Vec<[i64; 3]>,
}

/// A triangle ready to be crossed by columns: its corners counter-clockwise in the plane, whether it faces
/// up, twice its projected area, and the columns its bounding box holds (`x0..=x1`, `y0..=y1`).
#[derive(Debug, Clone, Copy)]
struct Prepared {
    p: [[i64; 3]; 3],
    exit: bool,
    area: i128,
    x: (i64, i64),
    y: (i64, i64),
}

impl Placed {
    fn new(mesh: &TriangleMesh, level: u32, placement: &MeshTransform) -> Result<Self, SolidError> {
        let universe = Universe::<3>::new(level)?;
        if level > MAX_LEVEL {
            return Err(SolidError::BadParameter(format!(
                "meshes are voxelized up to level {MAX_LEVEL} (crossings are packed in 64 bits), not {level}"
            )));
        }
        let one = 1i64 << FRAC;
        let mut fixed = Vec::with_capacity(mesh.vertices.len());
        for (i, v) in mesh.vertices.iter().enumerate() {
            let p = placement.apply(*v);
            if !p.iter().all(|x| x.abs() < LIMIT) {
                return Err(SolidError::BadParameter(format!(
                    "vertex {i} is placed at {p:?}, more than 2^22 voxels away: check the transform"
                )));
            }
            fixed.push(p.map(|x| (x * one as f64).round() as i64));
        }
        Ok(Self {
            universe,
            side: universe.side() as i64,
            fixed,
        })
    }

    /// The columns whose centres `(2x+1)·half` lie in `[lo, hi]`, clipped to the universe.
    fn range(&self, lo: i64, hi: i64) -> (i64, i64) {
        let half = 1i64 << (FRAC - 1);
        let a = (lo - half).div_euclid(2 * half) + i64::from((lo - half).rem_euclid(2 * half) != 0);
        let b = (hi - half).div_euclid(2 * half);
        (a.max(0), b.min(self.side - 1))
    }

    /// The triangle `t` ready to be crossed, `None` when its projection has zero area.
    fn prepare(&self, t: &[u32; 3]) -> Option<Prepared> {
        let [a, b, c] = t.map(|i| self.fixed[i as usize]);
        let area = orient(a, b, c);
        if area == 0 {
            return None;
        }
        // Counter-clockwise order in the plane; faces up (exit, −1) when the given order was ccw.
        let (p, exit) = if area > 0 {
            ([a, b, c], true)
        } else {
            ([a, c, b], false)
        };
        let bound = |axis: usize| {
            self.range(
                p.iter().map(|v| v[axis]).min().unwrap_or(0),
                p.iter().map(|v| v[axis]).max().unwrap_or(0),
            )
        };
        Some(Prepared {
            p,
            exit,
            area: area.abs(),
            x: bound(0),
            y: bound(1),
        })
    }

    /// Appends the crossings of `tri` with the columns of its bounding box whose x lies in `x`, each packed
    /// as column, position along z, and sign (see [`Placed::runs`]).
    fn crossings(&self, tri: &Prepared, x: Range<i64>, events: &mut Vec<u64>) {
        let level = self.universe.level();
        let pos_bits = level + 1;
        let one = 1i64 << FRAC;
        let half = one / 2;
        let Prepared { p, exit, area, .. } = *tri;
        let (x0, x1) = (tri.x.0.max(x.start), tri.x.1.min(x.end - 1));
        if x0 > x1 || tri.y.0 > tri.y.1 {
            return;
        }
        // Everything below is linear in the column centre, so it is evaluated at the first column and then
        // stepped: the three edge functions, and the height's numerator as a quotient and remainder.
        let first = [(2 * x0 + 1) * half, (2 * tri.y.0 + 1) * half, 0];
        let edges = [(p[0], p[1]), (p[1], p[2]), (p[2], p[0])];
        let e_first = edges.map(|(a, b)| orient(a, b, first));
        let e_dx = edges.map(|(a, b)| -i128::from(b[1] - a[1]) * i128::from(one));
        let e_dy = edges.map(|(a, b)| i128::from(b[0] - a[0]) * i128::from(one));
        // Height at the column: (e1 z0 + e2 z1 + e0 z2) / area, in 1/2^16 voxel; its voxel index below the
        // centre is ⌊(num − area·half) / (area·one)⌋.
        let z = p.map(|v| i128::from(v[2]));
        let numerator = |e: [i128; 3]| e[1] * z[0] + e[2] * z[1] + e[0] * z[2];
        let d = area * i128::from(one);
        let mut row = Quotient::new(numerator(e_first) - area * i128::from(half), d);
        // A step is only divided out where it is taken (most triangles span few columns).
        let step = |e: [i128; 3], taken: bool| {
            if taken {
                Quotient::new(numerator(e), d)
            } else {
                Quotient { q: 0, r: 0 }
            }
        };
        let (step_x, step_y) = (step(e_dx, x1 > x0), step(e_dy, tri.y.1 > tri.y.0));
        let mut e_row = e_first;
        for x in x0..=x1 {
            let (mut e, mut height) = (e_row, row);
            for y in tri.y.0..=tri.y.1 {
                if (0..3).all(|k| covers(e[k], edges[k].0, edges[k].1)) {
                    // Leaving: the first voxel whose centre is above the height; entering: the first
                    // voxel whose centre is at or above it.
                    let pos = if exit {
                        height.q + 1
                    } else {
                        height.q + i128::from(height.r != 0)
                    };
                    let pos = pos.clamp(0, i128::from(self.side)) as u64;
                    let col = ((x as u64) << level) | y as u64;
                    events.push((((col << pos_bits) | pos) << 1) | u64::from(!exit));
                }
                for k in 0..3 {
                    e[k] += e_dy[k];
                }
                height.add(step_y, d);
            }
            for k in 0..3 {
                e_row[k] += e_dx[k];
            }
            row.add(step_x, d);
        }
    }

    /// The runs of the columns crossed by `events`, in [`RaySet`] order: a centre is inside where the
    /// winding of the crossings below it is non-zero.
    fn runs(&self, mut events: Vec<u64>) -> (Vec<u64>, Vec<(u32, u32)>) {
        let level = self.universe.level();
        let col_bits = 2 * level;
        let pos_bits = level + 1;
        let side = self.side as u64;
        radix_sort(&mut events, col_bits + pos_bits + 1, &mut Vec::new());
        let mut columns = Vec::new();
        let mut runs = Vec::new();
        let mut i = 0;
        while i < events.len() {
            let col = events[i] >> (pos_bits + 1);
            let mut winding = 0i64;
            let mut start = None;
            while i < events.len() && events[i] >> (pos_bits + 1) == col {
                let pos = (events[i] >> 1) & ((1 << pos_bits) - 1);
                while i < events.len() && events[i] >> 1 == (col << pos_bits) | pos {
                    winding += if events[i] & 1 == 1 { 1 } else { -1 };
                    i += 1;
                }
                match (start, winding != 0) {
                    (None, true) => start = Some(pos),
                    (Some(s), false) => {
                        if s < pos {
                            columns.push(col);
                            runs.push((s as u32, pos as u32));
                        }
                        start = None;
                    }
                    _ => {}
                }
            }
            if let Some(s) = start {
                // Only on open meshes: the column never closes; it runs to the universe's face.
                if s < side {
                    columns.push(col);
                    runs.push((s as u32, side as u32));
                }
            }
        }
        (columns, runs)
    }
}

/// A placed mesh producing its rays slab by slab for [`Builder::to_file`](crate::stacking::Builder::to_file)
/// and [`Builder::build`](crate::stacking::Builder::build): the triangles are indexed by the buckets of
/// columns (along axis 0, one cell of the default split depth wide) their projections overlap, and a
/// slab's runs come from its buckets' triangles alone, by the rule of [`TriangleMesh::to_rays`] — they
/// equal the runs of that slab in [`TriangleMesh::to_rays`]. No whole ray set is held: the source keeps
/// the placed vertices, the triangles and the index.
///
/// ```
/// use ktree::solid::mesh::{MeshSource, MeshTransform, TriangleMesh};
/// use ktree::stacking::{paper::stack, Builder};
/// use std::path::Path;
/// let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/meshes/bunny_npm.obj");
/// let bunny = TriangleMesh::read(&path).unwrap();
/// let placement = MeshTransform::fit(&bunny, 6).unwrap();
/// let source = MeshSource::new(&bunny, 6, &placement).unwrap();
/// let whole = bunny.to_rays(6, &placement).unwrap().rays;
/// assert_eq!(Builder::new(&source).split_depth(2).build().unwrap(), stack(&whole));
/// ```
#[derive(Debug, Clone)]
pub struct MeshSource {
    placed: Placed,
    triangles: Vec<[u32; 3]>,
    /// Columns `[b·2^bucket_bits, (b+1)·2^bucket_bits)` along axis 0 make bucket `b`.
    bucket_bits: u32,
    /// The triangles overlapping bucket `b` are `ids[starts[b]..starts[b + 1]]`.
    starts: Vec<usize>,
    ids: Vec<u32>,
    vertical: usize,
}

impl MeshSource {
    /// The mesh placed in a universe of level `level` by `placement` (as [`TriangleMesh::to_rays`]).
    ///
    /// # Errors
    /// As [`TriangleMesh::to_rays`].
    pub fn new(
        mesh: &TriangleMesh,
        level: u32,
        placement: &MeshTransform,
    ) -> Result<Self, SolidError> {
        let placed = Placed::new(mesh, level, placement)?;
        let bucket_bits = level - default_split_depth(3, level);
        let buckets = 1usize << (level - bucket_bits);
        let mut spans = Vec::with_capacity(mesh.triangles.len());
        let mut vertical = 0;
        let mut counts = vec![0usize; buckets + 1];
        for (i, t) in mesh.triangles.iter().enumerate() {
            let Some(tri) = placed.prepare(t) else {
                vertical += 1;
                continue;
            };
            if tri.x.0 > tri.x.1 || tri.y.0 > tri.y.1 {
                continue;
            }
            let (b0, b1) = (
                (tri.x.0 >> bucket_bits) as usize,
                (tri.x.1 >> bucket_bits) as usize,
            );
            for c in &mut counts[b0 + 1..=b1 + 1] {
                *c += 1;
            }
            spans.push((i as u32, b0, b1));
        }
        for b in 0..buckets {
            counts[b + 1] += counts[b];
        }
        let starts = counts.clone();
        let mut ids = vec![0u32; counts[buckets]];
        for (i, b0, b1) in spans {
            for at in &mut counts[b0..=b1] {
                ids[*at] = i;
                *at += 1;
            }
        }
        Ok(Self {
            placed,
            triangles: mesh.triangles.clone(),
            bucket_bits,
            starts,
            ids,
            vertical,
        })
    }

    /// Triangles skipped because their projection along z has zero area.
    pub fn vertical_triangles(&self) -> usize {
        self.vertical
    }

    /// The bytes the source holds: placed vertices, triangles and the index.
    pub fn heap_bytes(&self) -> u64 {
        (std::mem::size_of_val(&self.placed.fixed[..])
            + std::mem::size_of_val(&self.triangles[..])
            + std::mem::size_of_val(&self.starts[..])
            + std::mem::size_of_val(&self.ids[..])) as u64
    }

    fn buckets(&self) -> usize {
        self.starts.len() - 1
    }
}

impl RaySource<3> for MeshSource {
    type Error = Infallible;

    fn universe(&self) -> Universe<3> {
        self.placed.universe
    }

    fn slab(&self, x: Range<u32>) -> Result<SlabRuns<'_>, Infallible> {
        let (lo, hi) = (i64::from(x.start), i64::from(x.end).min(self.placed.side));
        let mut events = Vec::new();
        if lo < hi {
            let first = (lo >> self.bucket_bits) as usize;
            let last = ((hi - 1) >> self.bucket_bits) as usize;
            for b in first..=last.min(self.buckets() - 1) {
                for &i in &self.ids[self.starts[b]..self.starts[b + 1]] {
                    let Some(tri) = self.placed.prepare(&self.triangles[i as usize]) else {
                        continue;
                    };
                    // A triangle in several of the slab's buckets is crossed once, from the first.
                    if b != first.max((tri.x.0 >> self.bucket_bits) as usize) {
                        continue;
                    }
                    self.placed.crossings(&tri, lo..hi, &mut events);
                }
            }
        }
        let (keys, runs) = self.placed.runs(events);
        Ok(SlabRuns {
            keys: Cow::Owned(keys),
            runs: Cow::Owned(runs),
        })
    }

    /// The slabs that hold a bucket with a triangle.
    fn occupied_slabs(&self, m: u32) -> Vec<u32> {
        let level = self.placed.universe.level();
        let t = level - m.min(level);
        let mut slabs: Vec<u32> = Vec::new();
        for b in (0..self.buckets()).filter(|&b| self.starts[b] < self.starts[b + 1]) {
            let first = (b as u64) << self.bucket_bits >> t;
            let last = (((b as u64 + 1) << self.bucket_bits) - 1) >> t;
            let from = slabs.last().map_or(first, |&s| first.max(u64::from(s) + 1));
            slabs.extend((from..=last).map(|s| s as u32));
        }
        slabs
    }
}

/// `n = q·d + r` with `0 ≤ r < d` (`d > 0`), kept exact while `n` moves by steps: one division a
/// triangle instead of one a crossing.
#[derive(Debug, Clone, Copy)]
struct Quotient {
    q: i128,
    r: i128,
}

impl Quotient {
    fn new(n: i128, d: i128) -> Self {
        let q = n.div_euclid(d);
        Self { q, r: n - q * d }
    }

    /// Adds the numerator of `step` (of the same divisor `d`).
    #[inline]
    fn add(&mut self, step: Quotient, d: i128) {
        self.q += step.q;
        self.r += step.r;
        if self.r >= d {
            self.r -= d;
            self.q += 1;
        }
    }
}

/// Twice the signed area of `(a, b, c)` projected on the xy-plane, exactly.
fn orient(a: [i64; 3], b: [i64; 3], c: [i64; 3]) -> i128 {
    i128::from(b[0] - a[0]) * i128::from(c[1] - a[1])
        - i128::from(b[1] - a[1]) * i128::from(c[0] - a[0])
}

/// Whether the column moved by `(ε, ε²)` is on the inner side of the edge `p → q` of a ccw triangle.
fn covers(e: i128, p: [i64; 3], q: [i64; 3]) -> bool {
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    e > 0 || (e == 0 && (dy < 0 || (dy == 0 && dx > 0)))
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn read_ply(mut bytes: &[u8]) -> Result<TriangleMesh, String> {
    use ply_rs::ply::Property;
    // The header is read and checked before `ply-rs` sees it: a number on a `format` or `element` line
    // beyond `u64` makes it panic, an element without properties or more entries than bytes makes it loop
    // and allocate beyond the input.
    let header = super::cloud::PlyHeader::parse(bytes)?;
    header.check_counts(bytes)?;
    let parser = ply_rs::parser::Parser::<ply_rs::ply::DefaultElement>::new();
    let ply = parser
        .read_ply(&mut bytes)
        .map_err(|e| format!("PLY: {e}"))?;
    let scalar = |p: &Property| -> Option<f64> {
        Some(match *p {
            Property::Char(v) => f64::from(v),
            Property::UChar(v) => f64::from(v),
            Property::Short(v) => f64::from(v),
            Property::UShort(v) => f64::from(v),
            Property::Int(v) => f64::from(v),
            Property::UInt(v) => f64::from(v),
            Property::Float(v) => f64::from(v),
            Property::Double(v) => v,
            _ => return None,
        })
    };
    let mut mesh = TriangleMesh {
        vertices: Vec::new(),
        triangles: Vec::new(),
    };
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or("PLY: no 'vertex' element")?;
    for (i, v) in vertices.iter().enumerate() {
        let mut p = [0.0; 3];
        for (a, name) in ["x", "y", "z"].iter().enumerate() {
            p[a] = v
                .get(*name)
                .and_then(scalar)
                .ok_or_else(|| format!("PLY: vertex {i} has no numeric '{name}'"))?;
        }
        mesh.vertices.push(p);
    }
    let faces = ply.payload.get("face").ok_or("PLY: no 'face' element")?;
    for (i, f) in faces.iter().enumerate() {
        let list = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .ok_or_else(|| format!("PLY: face {i} has no 'vertex_indices'"))?;
        let idx: Vec<i64> = match list {
            Property::ListChar(v) => v.iter().map(|&x| i64::from(x)).collect(),
            Property::ListUChar(v) => v.iter().map(|&x| i64::from(x)).collect(),
            Property::ListShort(v) => v.iter().map(|&x| i64::from(x)).collect(),
            Property::ListUShort(v) => v.iter().map(|&x| i64::from(x)).collect(),
            Property::ListInt(v) => v.iter().map(|&x| i64::from(x)).collect(),
            Property::ListUInt(v) => v.iter().map(|&x| i64::from(x)).collect(),
            _ => {
                return Err(format!(
                    "PLY: face {i}: vertex indices are not an integer list"
                ))
            }
        };
        if idx.len() < 3 || idx.iter().any(|&x| x < 0 || x > i64::from(u32::MAX)) {
            return Err(format!("PLY: face {i}: bad vertex index list {idx:?}"));
        }
        for k in 1..idx.len() - 1 {
            mesh.triangles
                .push([idx[0] as u32, idx[k] as u32, idx[k + 1] as u32]);
        }
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::TriangleMesh;
    use std::collections::BTreeMap;

    /// The count of edges not used exactly twice equals a plain tally in a map, on meshes of random
    /// triangles over few vertices (so edges are shared once, twice, or more).
    #[test]
    fn open_edges_equal_a_tally() {
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        let mut next = |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % n) as u32
        };
        for vertices in [3u32, 4, 7, 40, 1000] {
            for triangles in [1usize, 2, 5, 50, 500] {
                let corners = (0..vertices).map(|i| [f64::from(i), 0.0, 0.0]).collect();
                let tris: Vec<[u32; 3]> = (0..triangles)
                    .map(|_| [0; 3].map(|_| next(u64::from(vertices))))
                    .collect();
                let mut tally = BTreeMap::new();
                for t in &tris {
                    for k in 0..3 {
                        let (a, b) = (t[k], t[(k + 1) % 3]);
                        *tally.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                    }
                }
                let want = tally.values().filter(|&&n| n != 2).count();
                let mesh = TriangleMesh::new(corners, tris).unwrap();
                assert_eq!(
                    mesh.open_edges(),
                    want,
                    "{vertices} vertices, {triangles} triangles"
                );
            }
        }
    }
}
