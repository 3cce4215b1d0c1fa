//! A placed mesh voxelized: the crossings of its triangles with the columns through the voxel centres,
//! exactly, as rays ([`TriangleMesh::to_rays`]) or slab by slab ([`MeshSource`]).

use std::borrow::Cow;
use std::convert::Infallible;
use std::ops::Range;

use super::{MeshTransform, TriangleMesh};
use crate::radix::radix_sort;
use crate::rays::source::default_split_depth;
use crate::rays::RaySet;
use crate::rays::{RaySource, SlabRuns};
use crate::solid::SolidError;
use crate::space::Universe;

/// Bits of sub-voxel precision of placed vertices.
const FRAC: u32 = 16;
/// The largest level for meshes: a crossing is packed as column (2L bits), position (L + 1) and sign (1).
pub const MAX_LEVEL: u32 = 20;
/// Placed coordinates must lie within ±2^22 voxels (keeps every product inside `i128`).
const LIMIT: f64 = (1u64 << 22) as f64;

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
/// use ktree::io::read_mesh;
/// use ktree::solid::mesh::{MeshSource, MeshTransform};
/// use ktree::stacking::{paper::stack, Builder};
/// use std::path::Path;
/// let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/meshes/bunny_npm.obj");
/// let bunny = read_mesh(&path).unwrap();
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
