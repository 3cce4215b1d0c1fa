//! Quadric solids `Vᵀ Ξ V ≤ 0`, `V = [x₀ … x_{K−1}, 1]`, to rays, exactly (Akman & Franklin's section 5, AF10).
//!
//! **Which point of a voxel is tested.** The voxel `c` (covering `[c, c+1)` on each axis) is inside when its
//! *sample point* is: its centre `c + ½` by default ([`Sample::Centre`]) or its lowest corner `c`
//! ([`Sample::Corner`]). **Frames.** The matrix is either in voxel coordinates ([`Frame::Voxel`]: the universe is
//! `[0, U]^K`) or in the unit cube ([`Frame::UnitCube`]: the universe is `[0, 1]^K`, as in the paper).
//!
//! **Exactness.** Ξ has integer entries (named solids put their rational parameters on a common denominator).
//! A sample point is `X / W` with integers `X = 2c + 1` (centre) or `2c` (corner) and `W = 2` (voxel frame) or
//! `2U` (unit cube); `Vᵀ Ξ V` is homogeneous, so its sign at the point is the sign of the integer
//! `[X, W]ᵀ Ξ [X, W]`, evaluated in `i128` (sizes are checked first). Ties (`= 0`, the point on the surface) are
//! inside.
//!
//! **Work.** Columns are visited by a lexicographic binary subdivision of the column box (axis 0 first) that
//! discards a block of columns when a conservative lower bound of the form over the block is positive; a column
//! that is visited solves its quadratic in `z` exactly: a column holds zero, one or two runs. Blocks of at most
//! 16 columns are not tested as a whole, so the columns visited are those meeting the solid plus a thin band
//! around its projection. Such a block lies in one row (the columns differing only on the last column axis),
//! and along a row the quadratic's coefficients are polynomials of degree ≤ 2 in the column: they are stepped
//! from column to column by exact finite differences, from three columns solved in full per row. No voxel is
//! tested on its own. The general version of the core's direct ball
//! generator [`crate::rays::ball_rays`], which gives the same rays for a ball.

use super::{rational::gcd_i128, Rational, SolidError};
use crate::rays::{ColumnKeys, Normal, RaySet};
use crate::space::Universe;

/// Which coordinates a quadric's matrix is written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Frame {
    /// Voxel coordinates: the universe is `[0, U]^K`, voxel `c` covers `[c, c+1)`.
    #[default]
    Voxel,
    /// The unit cube: the universe is `[0, 1]^K` whatever its level (the paper's convention).
    UnitCube,
}

/// Which point of a voxel decides whether it is inside.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Sample {
    /// The voxel's centre `c + ½` (default).
    #[default]
    Centre,
    /// The voxel's lowest corner `c`.
    Corner,
}

/// Largest matrix size (K + 1 for K ≤ 4).
const N: usize = 5;

/// Blocks of at most this many columns are not tested as a whole: a block in one row is solved column after
/// column, stepping the quadratic in `z` by finite differences.
const ROW_COLUMNS: i64 = 16;

/// A quadric solid `Vᵀ Ξ V ≤ 0` with an integer symmetric `(K+1)×(K+1)` matrix Ξ.
///
/// ```
/// use ktree::solid::{Frame, Quadric, Rational, Sample};
/// // The disk of radius 4 centred in an 8×8 universe.
/// let disk = Quadric::<2>::ball([4.into(), 4.into()], 4.into(), Frame::Voxel).unwrap();
/// let rays = disk.to_rays(3, Sample::Centre, false).unwrap();
/// assert_eq!((rays.len(), rays.voxel_count()), (8, 52));
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Quadric<const K: usize> {
    xi: [[i128; N]; N],
    frame: Frame,
}

impl<const K: usize> Quadric<K> {
    /// A quadric from its symmetric matrix, `K + 1` rows of `K + 1` integers.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] if the matrix is not `(K+1)×(K+1)`, not symmetric, or zero.
    pub fn from_matrix(rows: &[Vec<i128>], frame: Frame) -> Result<Self, SolidError> {
        if K == 0 || K > 4 {
            return Err(SolidError::BadParameter(format!("K = {K} is not 1…4")));
        }
        if rows.len() != K + 1 || rows.iter().any(|r| r.len() != K + 1) {
            return Err(SolidError::BadParameter(format!(
                "a quadric in {K}-D needs a {0}×{0} matrix",
                K + 1
            )));
        }
        let mut xi = [[0i128; N]; N];
        for i in 0..=K {
            for j in 0..=K {
                if rows[i][j] != rows[j][i] {
                    return Err(SolidError::BadParameter(format!(
                        "the matrix is not symmetric: entry ({i},{j}) = {} but ({j},{i}) = {}",
                        rows[i][j], rows[j][i]
                    )));
                }
                if rows[i][j].unsigned_abs() > 1 << 100 {
                    return Err(SolidError::BadParameter("matrix entry too large".into()));
                }
                xi[i][j] = rows[i][j];
            }
        }
        Self::reduced(xi, frame)
    }

    /// A quadric from a symmetric matrix of rationals (scaled to integers by the common denominator).
    ///
    /// # Errors
    /// As [`Quadric::from_matrix`].
    pub fn from_rational_matrix(rows: &[Vec<Rational>], frame: Frame) -> Result<Self, SolidError> {
        let flat: Vec<Rational> = rows.iter().flatten().copied().collect();
        let (_, nums) = super::rational::common_denominator(&flat)?;
        let mut it = nums.into_iter();
        let ints: Vec<Vec<i128>> = rows
            .iter()
            .map(|r| r.iter().map(|_| it.next().unwrap_or(0)).collect())
            .collect();
        Self::from_matrix(&ints, frame)
    }

    fn reduced(mut xi: [[i128; N]; N], frame: Frame) -> Result<Self, SolidError> {
        let g = xi.iter().flatten().fold(0, |g, &v| gcd_i128(g, v));
        if g == 0 {
            return Err(SolidError::BadParameter(
                "the zero matrix is not a solid".into(),
            ));
        }
        for v in xi.iter_mut().flatten() {
            *v /= g;
        }
        Ok(Self { xi, frame })
    }

    /// The integer matrix (row `i`, column `j`), reduced by the gcd of its entries.
    pub fn matrix(&self) -> Vec<Vec<i128>> {
        (0..=K).map(|i| self.xi[i][..=K].to_vec()).collect()
    }

    /// The frame the matrix is written in.
    pub fn frame(&self) -> Frame {
        self.frame
    }

    /// The complement solid `Vᵀ(−Ξ)V ≤ 0` (its boundary is shared: surface points are in both).
    pub fn negated(&self) -> Self {
        let mut xi = self.xi;
        for v in xi.iter_mut().flatten() {
            *v = -*v;
        }
        Self {
            xi,
            frame: self.frame,
        }
    }

    /// Whether the voxel `point` is inside (its sample point satisfies `Vᵀ Ξ V ≤ 0`), evaluated exactly.
    /// This is the brute-force reference the ray generator is tested against.
    pub fn contains(&self, level: u32, sample: Sample, point: [u32; K]) -> bool {
        let s = i128::from(sample == Sample::Centre);
        let mut v = [0i128; N];
        for (x, &c) in v.iter_mut().zip(point.iter()) {
            *x = 2 * i128::from(c) + s;
        }
        v[K] = self.w(level);
        let mut q = 0i128;
        for i in 0..=K {
            for j in 0..=K {
                q += self.xi[i][j] * v[i] * v[j];
            }
        }
        q <= 0
    }

    fn w(&self, level: u32) -> i128 {
        match self.frame {
            Frame::Voxel => 2,
            Frame::UnitCube => 2i128 << level,
        }
    }

    /// The voxels of a universe of level `level` whose sample points lie in the solid, as rays (clipped to
    /// the universe), with outward unit normals at the run ends from the gradient when `normals` is set
    /// (ends cut by the universe's faces get `−z` at `z1 = 0` and `+z` at `z2 = U`).
    ///
    /// # Errors
    /// [`SolidError::Space`] for a bad level; [`SolidError::TooLarge`] when the coefficients are too large
    /// for exact `i128` evaluation at this level.
    pub fn to_rays(
        &self,
        level: u32,
        sample: Sample,
        normals: bool,
    ) -> Result<RaySet<K>, SolidError> {
        self.to_rays_limited(level, sample, normals, super::MAX_RAYS)
    }

    /// [`Quadric::to_rays`] stopping with [`SolidError::TooManyRays`] once more than `max_rays` runs are made.
    ///
    /// # Errors
    /// As [`Quadric::to_rays`].
    pub fn to_rays_limited(
        &self,
        level: u32,
        sample: Sample,
        normals: bool,
        max_rays: usize,
    ) -> Result<RaySet<K>, SolidError> {
        let side = Universe::<K>::new(level)?.side() as u32;
        self.generate(level, sample, normals, max_rays, 0..side)
    }

    /// The rays of the columns whose axis-0 coordinate lies in `x` (for `K = 1`, of the one column), as
    /// [`Quadric::to_rays`] makes them, without normals and without a cap on their number: a slab of the
    /// universe, for building a tree slab by slab.
    ///
    /// ```
    /// use ktree::solid::{Frame, Quadric, Rational, Sample};
    /// let ball = Quadric::<3>::ball([Rational::int(8); 3], Rational::int(6), Frame::Voxel).unwrap();
    /// let whole = ball.to_rays(4, Sample::Centre, false).unwrap();
    /// let slab = ball.slab_rays(4, Sample::Centre, 4..8).unwrap();
    /// assert_eq!(slab.iter().collect::<Vec<_>>(), whole.iter().filter(|r| (4..8).contains(&r.start[0])).collect::<Vec<_>>());
    /// ```
    ///
    /// # Errors
    /// As [`Quadric::to_rays`].
    pub fn slab_rays(
        &self,
        level: u32,
        sample: Sample,
        x: std::ops::Range<u32>,
    ) -> Result<RaySet<K>, SolidError> {
        self.generate(level, sample, false, usize::MAX, x)
    }

    fn generate(
        &self,
        level: u32,
        sample: Sample,
        normals: bool,
        max_rays: usize,
        x: std::ops::Range<u32>,
    ) -> Result<RaySet<K>, SolidError> {
        let universe = Universe::<K>::new(level)?;
        let largest = self.xi.iter().flatten().map(|v| v.abs()).max().unwrap_or(0);
        // |Vᵀ Ξ V| ≤ (K+1)² · max|Ξ| · max|V|², with max|V| ≤ 2U + 2.
        let vmax = 2.0 * universe.side() as f64 + 2.0;
        if (largest as f64) * 25.0 * vmax * vmax * 4.0 >= 2f64.powi(125) {
            return Err(SolidError::TooLarge { level, largest });
        }
        let side = universe.side() as i64;
        let mut gen = Generator::<K> {
            xi: self.xi,
            xf: std::array::from_fn(|i| std::array::from_fn(|j| self.xi[i][j] as f64)),
            s: i64::from(sample == Sample::Centre),
            w: self.w(level),
            side,
            level,
            columns: Vec::new(),
            runs: Vec::new(),
            normals: normals.then(Vec::new),
            max_rays,
            row_form: None,
        };
        if K == 1 {
            gen.column([0; K]);
        } else if x.start < x.end {
            let (mut lo, mut hi) = ([0; K], [side - 1; K]);
            lo[0] = i64::from(x.start);
            hi[0] = (i64::from(x.end) - 1).min(side - 1);
            gen.visit(lo, hi);
        }
        if gen.runs.len() > max_rays {
            return Err(SolidError::TooManyRays {
                level,
                limit: max_rays,
            });
        }
        Ok(RaySet::from_sorted_parts(
            universe,
            gen.columns,
            gen.runs,
            gen.normals,
        ))
    }
}

/// The quadratics in `z` of the columns of one row (the columns differing only on the last column axis), as
/// polynomials in the column's coordinate `i` on that axis: `b(i)` and `c(i)` have constant second differences.
#[derive(Debug, Clone, Copy)]
struct RowForm<const K: usize> {
    /// The row's column with coordinate 0 on the last column axis.
    fixed: [i64; K],
    /// At `i = 0`.
    first: Quad,
    /// `q(1) − q(0)` of `b` and `c`.
    delta: (i128, i128),
    /// The second differences of `b` and `c`.
    second: (i128, i128),
}

/// A column's quadratic and its forward differences, stepped one column at a time.
#[derive(Debug, Clone, Copy)]
struct RowStep {
    quad: Quad,
    delta: (i128, i128),
    second: (i128, i128),
}

impl RowStep {
    /// To the next column of the row.
    fn advance(&mut self) {
        self.quad.b += self.delta.0;
        self.quad.c += self.delta.1;
        self.delta.0 += self.second.0;
        self.delta.1 += self.second.1;
    }
}

impl<const K: usize> RowForm<K> {
    /// From the quadratics of the row's columns 0, 1 and 2.
    fn new(fixed: [i64; K], q: [Quad; 3]) -> Self {
        Self {
            fixed,
            first: q[0],
            delta: (q[1].b - q[0].b, q[1].c - q[0].c),
            second: (q[2].b - 2 * q[1].b + q[0].b, q[2].c - 2 * q[1].c + q[0].c),
        }
    }

    /// The quadratic and differences at column `i` (`q(i) = q(0) + i·Δ + i(i−1)/2·Δ²`), `None` if an
    /// intermediate product leaves `i128`.
    fn at(&self, i: i64) -> Option<RowStep> {
        let i = i128::from(i);
        let pairs = (i * (i - 1)) / 2;
        let value = |first: i128, delta: i128, second: i128| {
            first
                .checked_add(i.checked_mul(delta)?)?
                .checked_add(pairs.checked_mul(second)?)
        };
        let slope = |delta: i128, second: i128| delta.checked_add(i.checked_mul(second)?);
        Some(RowStep {
            quad: Quad {
                a: self.first.a,
                b: value(self.first.b, self.delta.0, self.second.0)?,
                c: value(self.first.c, self.delta.1, self.second.1)?,
            },
            delta: (
                slope(self.delta.0, self.second.0)?,
                slope(self.delta.1, self.second.1)?,
            ),
            second: self.second,
        })
    }
}

struct Generator<const K: usize> {
    xi: [[i128; N]; N],
    xf: [[f64; N]; N],
    s: i64,
    w: i128,
    side: i64,
    level: u32,
    columns: Vec<u64>,
    runs: Vec<(u32, u32)>,
    normals: Option<Vec<[Normal<K>; 2]>>,
    max_rays: usize,
    /// The row last solved, kept for the next block of the same row.
    row_form: Option<RowForm<K>>,
}

impl<const K: usize> Generator<K> {
    /// Visits the columns `lo..=hi` (axes 0 … K−2) in lexicographic order, skipping blocks that miss the solid.
    fn visit(&mut self, lo: [i64; K], hi: [i64; K]) {
        if self.runs.len() > self.max_rays {
            return; // reported by the caller
        }
        let columns: i64 = (0..K - 1).map(|a| hi[a] - lo[a] + 1).product();
        if columns > ROW_COLUMNS && self.misses(&lo, &hi) {
            return;
        }
        if columns <= ROW_COLUMNS && (0..K - 1).all(|a| a + 2 == K || lo[a] == hi[a]) {
            self.row(lo, hi[K - 2]);
            return;
        }
        match (0..K - 1).find(|&a| lo[a] < hi[a]) {
            None => self.column(lo),
            Some(a) => {
                let mid = lo[a] + (hi[a] - lo[a]) / 2;
                let mut h1 = hi;
                h1[a] = mid;
                self.visit(lo, h1);
                let mut l2 = lo;
                l2[a] = mid + 1;
                self.visit(l2, hi);
            }
        }
    }

    /// A conservative test that no sample point of the block (all of `z`) is inside: a lower bound of the
    /// form over the block from its value, gradient and curvature at the block's middle.
    fn misses(&self, lo: &[i64; K], hi: &[i64; K]) -> bool {
        let s = self.s as f64;
        let mut m = [0f64; N];
        let mut h = [0f64; N];
        for a in 0..K {
            let (l, u) = if a == K - 1 {
                (0, self.side - 1)
            } else {
                (lo[a], hi[a])
            };
            let (l, u) = ((2 * l) as f64 + s, (2 * u) as f64 + s);
            m[a] = 0.5 * (l + u);
            h[a] = 0.5 * (u - l);
        }
        m[K] = self.w as f64;
        let mut value = 0.0;
        let mut scale = 0.0;
        let mut lower = 0.0;
        for i in 0..=K {
            let mut g = 0.0;
            for j in 0..=K {
                g += self.xf[i][j] * m[j];
                scale += (self.xf[i][j] * m[j] * m[i]).abs();
            }
            value += g * m[i];
            lower -= 2.0 * g.abs() * h[i];
            for j in 0..=K {
                let t = self.xf[i][j] * h[i] * h[j];
                lower -= if i == j { (-t).max(0.0) } else { t.abs() };
            }
        }
        value + lower > 1e-9 * (scale + lower.abs()) + 1.0
    }

    /// Solves the columns from `lo` to `last` on the last column axis (the other axes fixed), stepping their
    /// quadratics in `z` by finite differences: along that axis `b` is linear and `c` quadratic in the column
    /// coordinate, so their second differences are constant and the stepping is exact.
    fn row(&mut self, lo: [i64; K], last: i64) {
        let axis = K - 2;
        let mut fixed = lo;
        fixed[axis] = 0;
        let form = match self.row_form {
            Some(form) if form.fixed == fixed => form,
            _ => {
                let nth = |i: i64| {
                    let mut col = fixed;
                    col[axis] = i;
                    col
                };
                let form = RowForm::new(fixed, [0, 1, 2].map(|i| self.column_quad(&nth(i))));
                self.row_form = Some(form);
                form
            }
        };
        let Some(mut step) = form.at(lo[axis]) else {
            // Beyond i128 (only for huge coefficients): solve each column on its own.
            for z in lo[axis]..=last {
                let mut col = lo;
                col[axis] = z;
                self.column(col);
            }
            return;
        };
        let mut col = lo;
        loop {
            self.solve_column(col, &step.quad);
            if col[axis] == last {
                break;
            }
            col[axis] += 1;
            step.advance();
        }
    }

    /// Solves one column exactly and appends its runs.
    fn column(&mut self, col: [i64; K]) {
        let q = self.column_quad(&col);
        self.solve_column(col, &q);
    }

    /// The sample points' homogeneous coordinates `[X, W]` of a column (its `z` entry left 0).
    fn column_point(&self, col: &[i64; K]) -> [i128; N] {
        let mut v = [0i128; N];
        for a in 0..K - 1 {
            v[a] = i128::from(2 * col[a] + self.s);
        }
        v[K] = self.w;
        v
    }

    /// The form along a column as an integer quadratic in its voxel coordinate `z`.
    fn column_quad(&self, col: &[i64; K]) -> Quad {
        let z = K - 1;
        let v = self.column_point(col);
        let az = self.xi[z][z];
        let mut bz = 0i128;
        let mut cz = 0i128;
        for i in (0..=K).filter(|&i| i != z) {
            bz += 2 * self.xi[z][i] * v[i];
            for j in (0..=K).filter(|&j| j != z) {
                cz += self.xi[i][j] * v[i] * v[j];
            }
        }
        let s = i128::from(self.s);
        // Z = 2z + s: q(z) = 4az z² + (4 az s + 2 bz) z + (az s² + bz s + cz).
        Quad {
            a: 4 * az,
            b: 4 * az * s + 2 * bz,
            c: az * s * s + bz * s + cz,
        }
    }

    /// Solves one column from its quadratic `q` in `z` and appends its runs.
    fn solve_column(&mut self, col: [i64; K], q: &Quad) {
        let (lo, hi) = (0i64, self.side - 1);
        // Small coefficients (the usual case) are solved in i64: |q(z)| < 2^62 for |z| ≤ 2^21 + 1.
        let fits = q.a.unsigned_abs() < 1 << 16
            && q.b.unsigned_abs() < 1 << 37
            && q.c.unsigned_abs() < 1 << 60;
        let (found, n) = if fits {
            Quad64 {
                a: q.a as i64,
                b: q.b as i64,
                c: q.c as i64,
            }
            .runs(lo, hi)
        } else {
            q.runs(lo, hi)
        };
        if n == 0 {
            return;
        }
        let mut point = [0u32; K];
        for a in 0..K - 1 {
            point[a] = col[a] as u32;
        }
        let key = ColumnKeys::<K>::new(self.level).pack(point);
        for &(z1, z2) in &found[..n] {
            self.columns.push(key);
            self.runs.push((z1 as u32, z2 as u32 + 1));
            if self.normals.is_some() {
                let v = self.column_point(&col);
                let n1 = self.normal(&v, q, z1, -1);
                let n2 = self.normal(&v, q, z2, 1);
                if let Some(ns) = self.normals.as_mut() {
                    ns.push([n1, n2]);
                }
            }
        }
    }

    /// The outward unit normal at the end voxel `zv` of a run; `dir` is −1 at `z1`, +1 at `z2`.
    fn normal(&self, v: &[i128; N], q: &Quad, zv: i64, dir: i64) -> Normal<K> {
        let mut axis_z = [0f32; K];
        axis_z[K - 1] = dir as f32;
        let beyond = zv + dir;
        if (beyond < 0 || beyond >= self.side) && q.at(beyond) <= 0 {
            return axis_z; // cut by the universe's face
        }
        let mut p = [0f64; N];
        for a in 0..=K {
            p[a] = v[a] as f64;
        }
        p[K - 1] = (2 * zv + self.s) as f64;
        let mut g = [0f32; K];
        let mut len = 0f64;
        for (i, gi) in g.iter_mut().enumerate() {
            let d: f64 = (0..=K).map(|j| self.xf[i][j] * p[j]).sum();
            *gi = d as f32;
            len += d * d;
        }
        if len == 0.0 || !len.is_finite() {
            return axis_z;
        }
        let inv = (1.0 / len.sqrt()) as f32;
        g.map(|x| x * inv)
    }
}

macro_rules! quadratic {
    ($name:ident, $t:ty) => {
        /// An integer quadratic `a z² + b z + c`.
        #[derive(Debug, Clone, Copy)]
        struct $name {
            a: $t,
            b: $t,
            c: $t,
        }

        impl $name {
            fn at(&self, z: i64) -> $t {
                let z = z as $t;
                (self.a * z + self.b) * z + self.c
            }

            /// For `a > 0`: the integers `z` in `[lo, hi]` with `q(z) ≤ 0` (an interval), exactly.
            fn convex_interval(&self, lo: i64, hi: i64) -> Option<(i64, i64)> {
                // Clearly no real root (the float discriminant is negative beyond its rounding error): q > 0.
                let (a, b, c) = (self.a as f64, self.b as f64, self.c as f64);
                let d = b * b - 4.0 * a * c;
                if d < -1e-9 * (b * b + (4.0 * a * c).abs()) - 1.0 {
                    return None;
                }
                let (r1, r2) = float_roots(a, b, d);
                let inside = |z: i64| self.at(z) <= 0;
                // Fast path: the rounded float roots, confirmed exactly (by convexity, q ≤ 0 at both ends of an
                // interval means on all of it; an end is the boundary when its outer neighbour is outside).
                if r1.is_finite() && r2.is_finite() && r1 <= r2 {
                    let l = ceil_within(r1, lo, hi);
                    let h = floor_within(r2, lo, hi);
                    if l <= h && inside(l) && inside(h) {
                        let left = if l == lo || !inside(l - 1) {
                            l
                        } else {
                            first_true(lo, l, r1.ceil(), inside)
                        };
                        let right = if h == hi || !inside(h + 1) {
                            h
                        } else {
                            -first_true(-hi, -h, -r2.floor(), |z| inside(-z))
                        };
                        return Some((left, right));
                    }
                }
                self.convex_interval_exact(lo, hi, r1, r2)
            }

            /// The general path of [`Quad::convex_interval`]: from an exact integer minimiser.
            fn convex_interval_exact(
                &self,
                lo: i64,
                hi: i64,
                r1: f64,
                r2: f64,
            ) -> Option<(i64, i64)> {
                // The integer minimiser over [lo, hi] is clamp(floor(−b / 2a)) or the next integer.
                let v = (-self.b).div_euclid(2 * self.a);
                let zm0 = i64::try_from(v.clamp(lo as $t, hi as $t)).ok()?;
                let zm = if zm0 < hi && self.at(zm0 + 1) < self.at(zm0) {
                    zm0 + 1
                } else {
                    zm0
                };
                if self.at(zm) > 0 {
                    return None;
                }
                let inside = |z: i64| self.at(z) <= 0;
                // Smallest z in [lo, zm] inside (inside is monotone false → true there); largest in [zm, hi].
                let left = first_true(lo, zm, r1.ceil(), inside);
                let right = -first_true(-hi, -zm, -r2.floor(), |z| inside(-z));
                Some((left, right))
            }

            /// For `a = 0`: the integers in `[lo, hi]` with `b z + c ≤ 0`.
            fn linear_interval(&self, lo: i64, hi: i64) -> Option<(i64, i64)> {
                let (lo128, hi128) = (lo as $t, hi as $t);
                let (l, h) = match self.b.signum() {
                    0 => {
                        if self.c <= 0 {
                            (lo128, hi128)
                        } else {
                            return None;
                        }
                    }
                    1 => (lo128, (-self.c).div_euclid(self.b).min(hi128)),
                    _ => {
                        // z ≥ −c / b with b < 0: z ≥ ceil(c / −b).
                        let d = -self.b;
                        ((self.c + d - 1).div_euclid(d).max(lo128), hi128)
                    }
                };
                (l <= h).then_some((l as i64, h as i64))
            }

            /// The runs (at most two) of integers `z` in `[lo, hi]` with `q(z) ≤ 0`.
            fn runs(&self, lo: i64, hi: i64) -> ([(i64, i64); 2], usize) {
                let mut found = [(0i64, 0i64); 2];
                let mut n = 0;
                if self.a > 0 {
                    if let Some(r) = self.convex_interval(lo, hi) {
                        found[0] = r;
                        n = 1;
                    }
                } else if self.a < 0 {
                    // Inside = [lo, hi] minus where q ≥ 1, which is where the convex −q + 1 ≤ 0.
                    let p = Self {
                        a: -self.a,
                        b: -self.b,
                        c: 1 - self.c,
                    };
                    match p.convex_interval(lo, hi) {
                        None => {
                            found[0] = (lo, hi);
                            n = 1;
                        }
                        Some((pl, ph)) => {
                            if pl > lo {
                                found[n] = (lo, pl - 1);
                                n += 1;
                            }
                            if ph < hi {
                                found[n] = (ph + 1, hi);
                                n += 1;
                            }
                        }
                    }
                } else if let Some(r) = self.linear_interval(lo, hi) {
                    found[0] = r;
                    n = 1;
                }
                (found, n)
            }
        }
    };
}

quadratic!(Quad, i128);
quadratic!(Quad64, i64);

/// `ceil(x)` clamped to `[lo, hi]`, for a finite `x` (without a call into libm: the clamped value is small,
/// so its truncation is exact).
fn ceil_within(x: f64, lo: i64, hi: i64) -> i64 {
    let x = x.max(lo as f64).min(hi as f64);
    let t = x as i64;
    t + i64::from((t as f64) < x)
}

/// `floor(x)` clamped to `[lo, hi]`, for a finite `x`.
fn floor_within(x: f64, lo: i64, hi: i64) -> i64 {
    let x = x.max(lo as f64).min(hi as f64);
    let t = x as i64;
    t - i64::from((t as f64) > x)
}

/// Float estimates of the roots of `a z² + b z + c` (with `a > 0`, discriminant `d`), in order; the vertex
/// twice when there is no real root.
fn float_roots(a: f64, b: f64, d: f64) -> (f64, f64) {
    let m = -b / (2.0 * a);
    if d.is_nan() || d < 0.0 || !d.is_finite() {
        return (m, m);
    }
    let h = d.sqrt() / (2.0 * a);
    (m - h, m + h)
}

/// The smallest `z` in `[lo, hi]` with `p(z)`, where `p` is monotone (false … true) and `p(hi)` holds; `guess`
/// is a float estimate (any value: it is only where the search starts).
fn first_true(lo: i64, hi: i64, guess: f64, p: impl Fn(i64) -> bool) -> i64 {
    let g = if guess.is_finite() {
        (guess.max(lo as f64).min(hi as f64)) as i64
    } else {
        hi
    };
    // Gallop from the guess to a bracket [a, b] with !p(a) (or a = lo − 1) and p(b).
    let (mut a, mut b);
    if p(g) {
        b = g;
        let mut step = 1i64;
        loop {
            let t = b - step;
            if t < lo {
                a = lo - 1;
                break;
            }
            if p(t) {
                b = t;
                step *= 2;
            } else {
                a = t;
                break;
            }
        }
    } else {
        a = g;
        let mut step = 1i64;
        loop {
            let t = a + step;
            if t >= hi {
                b = hi;
                break;
            }
            if p(t) {
                b = t;
                break;
            }
            a = t;
            step *= 2;
        }
    }
    while b - a > 1 {
        let m = a + (b - a) / 2;
        if p(m) {
            b = m;
        } else {
            a = m;
        }
    }
    b
}
