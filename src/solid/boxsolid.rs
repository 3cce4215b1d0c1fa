//! Axis-aligned boxes to rays: the product of one exact integer range per axis.

use super::rational::common_denominator;
use super::{Frame, Rational, Sample, SolidError};
use crate::rays::{ColumnKeys, RaySet};
use crate::space::Universe;

/// The closed box `lo ≤ x ≤ hi` (each axis), tested at the voxel's sample point like a quadric.
///
/// ```
/// use ktree::solid::{BoxSolid, Frame, Sample};
/// let b = BoxSolid::<3>::new([1.into(), 1.into(), 2.into()], [3.into(), 4.into(), 6.into()], Frame::Voxel).unwrap();
/// // Centres c + ½ in [1, 3] × [1, 4] × [2, 6]: c in 1..=2, 1..=3, 2..=5.
/// assert_eq!(b.to_rays(3, Sample::Centre, false).unwrap().voxel_count(), 2 * 3 * 4);
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BoxSolid<const K: usize> {
    lo: [Rational; K],
    hi: [Rational; K],
    frame: Frame,
}

impl<const K: usize> BoxSolid<K> {
    /// The box between the corners `lo` and `hi`.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] if `lo > hi` on some axis.
    pub fn new(lo: [Rational; K], hi: [Rational; K], frame: Frame) -> Result<Self, SolidError> {
        for a in 0..K {
            if lo[a].to_f64() > hi[a].to_f64() {
                return Err(SolidError::BadParameter(format!(
                    "box: lower corner {} above upper corner {} on axis {a}",
                    lo[a], hi[a]
                )));
            }
        }
        Ok(Self { lo, hi, frame })
    }

    /// Whether the voxel's sample point is in the box (exact).
    pub fn contains(&self, level: u32, sample: Sample, point: [u32; K]) -> bool {
        let ranges = match self.ranges(level, sample) {
            Ok(r) => r,
            Err(_) => return false,
        };
        (0..K).all(|a| {
            let c = i64::from(point[a]);
            ranges[a].0 <= c && c <= ranges[a].1
        })
    }

    /// Per axis, the voxel range `[c_min, c_max]` (possibly empty, not clipped).
    fn ranges(&self, level: u32, sample: Sample) -> Result<[(i64, i64); K], SolidError> {
        let mut all = self.lo.to_vec();
        all.extend_from_slice(&self.hi);
        let (d, p) = common_denominator(&all)?;
        let w: i128 = match self.frame {
            Frame::Voxel => 2,
            Frame::UnitCube => 2i128 << level,
        };
        let s = i128::from(sample == Sample::Centre);
        let mut out = [(0i64, -1i64); K];
        for a in 0..K {
            // lo·W ≤ (2c + s)·D ≤ hi·W.
            let lo_n = p[a] * w - s * d;
            let hi_n = p[K + a] * w - s * d;
            let den = 2 * d;
            let cmin = -((-lo_n).div_euclid(den));
            let cmax = hi_n.div_euclid(den);
            let clamp = |v: i128| v.clamp(-(1 << 40), 1 << 40) as i64;
            out[a] = (clamp(cmin), clamp(cmax));
        }
        Ok(out)
    }

    /// The box's voxels as rays, normals `∓z` at the run ends when asked.
    ///
    /// # Errors
    /// [`SolidError::Space`] for a bad level.
    pub fn to_rays(
        &self,
        level: u32,
        sample: Sample,
        normals: bool,
    ) -> Result<RaySet<K>, SolidError> {
        let side = Universe::<K>::new(level)?.side() as u32;
        self.generate(level, sample, normals, super::MAX_RAYS, 0..side)
    }

    /// The rays of the columns whose axis-0 coordinate lies in `x` (for `K = 1`, of the one column), as
    /// [`BoxSolid::to_rays`] makes them, without normals and without a cap on their number.
    ///
    /// # Errors
    /// [`SolidError::Space`] for a bad level.
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
        let side = universe.side() as i64;
        let mut r = self.ranges(level, sample)?;
        for x in r.iter_mut() {
            *x = (x.0.max(0), x.1.min(side - 1));
        }
        if K > 1 {
            r[0] = (
                r[0].0.max(i64::from(x.start)),
                r[0].1.min(i64::from(x.end) - 1),
            );
        }
        let count = r[..K - 1]
            .iter()
            .map(|&(l, h)| (h - l + 1).max(0) as u128)
            .product::<u128>();
        if count > max_rays as u128 {
            return Err(SolidError::TooManyRays {
                level,
                limit: max_rays,
            });
        }
        let mut columns = Vec::new();
        let mut runs = Vec::new();
        if r.iter().all(|&(l, h)| l <= h) {
            let mut col: [i64; K] = std::array::from_fn(|a| r[a].0);
            'outer: loop {
                let key = ColumnKeys::<K>::new(level).pack(col.map(|c| c as u32));
                columns.push(key);
                runs.push((r[K - 1].0 as u32, r[K - 1].1 as u32 + 1));
                let mut axis = K - 1;
                loop {
                    if axis == 0 {
                        break 'outer;
                    }
                    axis -= 1;
                    col[axis] += 1;
                    if col[axis] <= r[axis].1 {
                        break;
                    }
                    col[axis] = r[axis].0;
                }
            }
        }
        let normals = normals.then(|| {
            let mut n1 = [0f32; K];
            n1[K - 1] = -1.0;
            let mut n2 = [0f32; K];
            n2[K - 1] = 1.0;
            vec![[n1, n2]; runs.len()]
        });
        Ok(RaySet::from_sorted_parts(universe, columns, runs, normals))
    }
}
