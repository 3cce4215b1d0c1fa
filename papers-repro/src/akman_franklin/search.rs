//! AF5–AF7: which objects did the paper use? For each candidate family (shape, placement, universe level,
//! inside convention) the ray count is a step function of the size parameter; we find every parameter
//! interval that gives exactly the paper's ray count, list the distinct voxel objects inside that interval,
//! and stack each to compare its obel counts with the paper's.
//!
//! Measures are exact: a voxel is inside the object of parameter `T` when its measure `m(v) ≤ T`, with `m`
//! an exact rational in doubled coordinates (voxel centre `2c + 1`, lower corner `2c`). For balls
//! `m = Σ (X_i − C_i)²` and `T = (2r)²`; for paraboloids opening up from the apex `m = d² / (Z − C_z)` and
//! `T = (2r)² / (2h)` for radius `r` at height `h` above the apex.

use ktree::rays::RaySet;
use ktree::solid::{Frame, Quadric, Sample};
use ktree::stacking::paper::stack;

/// A rational `num / den` with `den ≥ 0`; `den = 0` is +∞.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Q {
    /// Numerator.
    pub num: i128,
    /// Denominator.
    pub den: i128,
}

impl Q {
    const INF: Q = Q { num: 1, den: 0 };

    fn le(self, o: Q) -> bool {
        self.num * o.den <= o.num * self.den
    }

    fn cmp(self, o: Q) -> std::cmp::Ordering {
        (self.num * o.den).cmp(&(o.num * self.den))
    }

    /// The value as a float.
    pub fn to_f64(self) -> f64 {
        self.num as f64 / self.den as f64
    }
}

/// Which point(s) of a voxel decide.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Convention {
    /// The voxel's centre is inside.
    Centre,
    /// The voxel's lowest corner is inside (integer voxel coordinates).
    Corner,
    /// Some point of the voxel is inside (the voxel meets the solid).
    Any,
    /// Every point of the voxel is inside.
    Whole,
}

impl Convention {
    /// All conventions searched.
    pub const ALL: [Convention; 4] = [Self::Centre, Self::Corner, Self::Any, Self::Whole];

    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Centre => "centre",
            Self::Corner => "lower corner",
            Self::Any => "voxel meets solid",
            Self::Whole => "whole voxel inside",
        }
    }
}

/// The shape of a family.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// A ball centred at `C` (doubled coordinates).
    Ball,
    /// A paraboloid opening up along z from the apex `C`.
    Paraboloid,
}

/// One family of candidate objects.
#[derive(Debug, Clone)]
pub struct Family {
    /// The shape.
    pub shape: Shape,
    /// A name for the placement.
    pub placement: &'static str,
    /// Centre or apex in doubled coordinates (`2·x`).
    pub centre2: [i64; 3],
    /// Universe level.
    pub level: u32,
    /// Inside convention.
    pub convention: Convention,
}

/// An interval of the parameter that gives the wanted ray count, and what it holds.
#[derive(Debug, Clone)]
pub struct Hit {
    /// The family.
    pub family: Family,
    /// Smallest parameter with the wanted count (inclusive).
    pub from: Q,
    /// Parameter where the count first exceeds it (exclusive).
    pub to: Q,
    /// Distinct voxel objects in `[from, to)`.
    pub objects: usize,
    /// Obel counts `(full, empty, partial)` and voxel counts of the objects stacked (all, or an even sample).
    pub stacked: Vec<(Q, u64, u64, u64, u128)>,
    /// Per stacked object, its node counts per level.
    pub per_level: Vec<Vec<ktree::LevelCounts>>,
}

/// The counts `(full, partial)` of `per_level`'s tree if no full node above tree level `m` were merged
/// (each such node expanded into a complete subtree down to level `m`); empty nodes are unchanged.
pub fn unmerged_above(per_level: &[ktree::LevelCounts], m: u32) -> (u64, u64) {
    let (mut full, mut partial) = (0u64, 0u64);
    for c in per_level {
        partial += c.partial;
        if c.level < m {
            let fan = 8u64.pow(m - c.level);
            full += c.full * fan;
            partial += c.full * (fan - 1) / 7;
        } else {
            full += c.full;
        }
    }
    (full, partial)
}

fn axis_range(conv: Convention, v: i64, c: i64) -> (i64, i64) {
    // The doubled coordinates the convention looks at on one axis: (nearest, farthest) distance to c.
    let (lo, hi) = (2 * v, 2 * v + 2);
    match conv {
        Convention::Centre => ((2 * v + 1 - c).abs(), (2 * v + 1 - c).abs()),
        Convention::Corner => ((lo - c).abs(), (lo - c).abs()),
        Convention::Any | Convention::Whole => {
            let near = if c < lo {
                lo - c
            } else if c > hi {
                c - hi
            } else {
                0
            };
            let far = (lo - c).abs().max((hi - c).abs());
            (near, far)
        }
    }
}

impl Family {
    fn side(&self) -> i64 {
        1 << self.level
    }

    /// The exact measure of voxel `(x, y, z)`.
    pub fn measure(&self, x: i64, y: i64, z: i64) -> Q {
        let c = self.centre2;
        let pick = |(near, far): (i64, i64)| {
            if self.convention == Convention::Whole {
                far
            } else {
                near
            }
        };
        let dx = i128::from(pick(axis_range(self.convention, x, c[0])));
        let dy = i128::from(pick(axis_range(self.convention, y, c[1])));
        match self.shape {
            Shape::Ball => {
                let dz = i128::from(pick(axis_range(self.convention, z, c[2])));
                Q {
                    num: dx * dx + dy * dy + dz * dz,
                    den: 1,
                }
            }
            Shape::Paraboloid => {
                // Height above the apex: the point's own (centre, corner), the top (any), the bottom (whole).
                let zz = match self.convention {
                    Convention::Centre => 2 * z + 1,
                    Convention::Corner | Convention::Whole => 2 * z,
                    Convention::Any => 2 * z + 2,
                };
                let h = i128::from(zz - c[2]);
                let d2 = dx * dx + dy * dy;
                if h > 0 {
                    Q { num: d2, den: h }
                } else if h == 0 && d2 == 0 {
                    Q { num: 0, den: 1 }
                } else {
                    Q::INF
                }
            }
        }
    }

    /// Per column (lexicographic), the smallest measure along z and where it is reached.
    pub fn column_minima(&self) -> Vec<(Q, i64)> {
        let u = self.side();
        let mut out = Vec::with_capacity((u * u) as usize);
        for x in 0..u {
            for y in 0..u {
                let mut best = (Q::INF, 0);
                for z in 0..u {
                    let m = self.measure(x, y, z);
                    if !best.0.le(m) {
                        best = (m, z);
                    }
                }
                out.push(best);
            }
        }
        out
    }

    /// The object `{m ≤ t}` as rays. Measures are unimodal along z (convex solids), so each column's run is
    /// found by two binary searches from the column's minimum.
    pub fn rays(&self, minima: &[(Q, i64)], t: Q) -> RaySet<3> {
        let u = self.side();
        let mut rays = Vec::new();
        for x in 0..u {
            for y in 0..u {
                let (m, k) = minima[(x * u + y) as usize];
                if !m.le(t) {
                    continue;
                }
                let inside = |z: i64| self.measure(x, y, z).le(t);
                // First inside in [0, k]; last inside in [k, u).
                let (mut a, mut b) = (-1i64, k);
                while b - a > 1 {
                    let mid = (a + b) / 2;
                    if inside(mid) {
                        b = mid;
                    } else {
                        a = mid;
                    }
                }
                let first = b;
                let (mut a, mut b) = (k, u);
                while b - a > 1 {
                    let mid = (a + b) / 2;
                    if inside(mid) {
                        a = mid;
                    } else {
                        b = mid;
                    }
                }
                rays.push(ktree::Ray::new(
                    [x as u32, y as u32, first as u32],
                    a as u32 + 1,
                ));
            }
        }
        RaySet::from_rays(self.level, rays).expect("inside the universe")
    }

    /// The same object through the quadric pipeline, for the conventions a quadric's sample point covers
    /// (centre, lower corner); `None` for the others.
    pub fn quadric_rays(&self, t: Q) -> Option<RaySet<3>> {
        let sample = match self.convention {
            Convention::Centre => Sample::Centre,
            Convention::Corner => Sample::Corner,
            _ => return None,
        };
        let c: Vec<i128> = self.centre2.iter().map(|&v| i128::from(v)).collect();
        // In real coordinates x = X/2: forms in 2x − C.
        let mut m = vec![vec![0i128; 4]; 4];
        let mut square = |coef: i128, l: [i128; 4]| {
            for i in 0..4 {
                for j in 0..4 {
                    m[i][j] += coef * l[i] * l[j];
                }
            }
        };
        match self.shape {
            Shape::Ball => {
                // Σ (2x_i − C_i)² − T ≤ 0 (T an integer).
                for a in 0..3 {
                    let mut l = [0; 4];
                    l[a] = 2;
                    l[3] = -c[a];
                    square(1, l);
                }
                m[3][3] -= t.num;
            }
            Shape::Paraboloid => {
                // den·((2x − Cx)² + (2y − Cy)²) − num·(2z − Cz) ≤ 0.
                for a in 0..2 {
                    let mut l = [0; 4];
                    l[a] = 2;
                    l[3] = -c[a];
                    square(t.den, l);
                }
                m[2][3] -= t.num;
                m[3][2] -= t.num;
                m[3][3] += t.num * c[2];
            }
        }
        let q = Quadric::<3>::from_matrix(&m, Frame::Voxel).ok()?;
        q.to_rays(self.level, sample, false).ok()
    }
}

/// Finds the parameter interval of `family` with exactly `want` rays, and stacks up to `cap` of its objects.
pub fn search(family: &Family, want: usize, cap: usize) -> Option<Hit> {
    let column_minima = family.column_minima();
    let mut minima: Vec<Q> = column_minima
        .iter()
        .map(|m| m.0)
        .filter(|q| q.den > 0)
        .collect();
    if minima.len() < want || want == 0 {
        return None;
    }
    minima.sort_by(|a, b| a.cmp(*b));
    let from = minima[want - 1];
    let to = minima.get(want).copied().unwrap_or(Q::INF);
    if !from.le(to) || to.le(from) {
        return None; // a tie: the count jumps over `want`
    }
    // Distinct measures in [from, to): each starts a different voxel object.
    let u = family.side();
    let mut values = Vec::new();
    for x in 0..u {
        for y in 0..u {
            for z in 0..u {
                let m = family.measure(x, y, z);
                if from.le(m) && !to.le(m) {
                    values.push(m);
                }
            }
        }
    }
    values.sort_by(|a, b| a.cmp(*b));
    values.dedup_by(|a, b| a.cmp(*b).is_eq());
    let picks: Vec<Q> = if values.len() <= cap {
        values.clone()
    } else {
        (0..cap)
            .map(|i| values[i * (values.len() - 1) / (cap - 1).max(1)])
            .collect()
    };
    let mut stacked = Vec::new();
    let mut per_level = Vec::new();
    for t in picks {
        let rays = family.rays(&column_minima, t);
        assert_eq!(rays.len(), want, "the search's ray count");
        if let Some(q) = family.quadric_rays(t) {
            assert_eq!(
                q, rays,
                "the quadric pipeline and the exact measure disagree"
            );
        }
        let tree = stack(&rays);
        let c = tree.counts();
        stacked.push((t, c.full, c.empty, c.partial, rays.voxel_count()));
        per_level.push(tree.counts_per_level());
    }
    Some(Hit {
        family: family.clone(),
        from,
        to,
        objects: values.len(),
        stacked,
        per_level,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AF5 search at L = 5 finds the 1/8 sphere with exactly 833 rays, built alike through the exact
    /// measure and the quadric module, and its tree counts are what stacking gives.
    #[test]
    fn af5_hit_at_level_5() {
        let f = Family {
            shape: Shape::Ball,
            placement: "corner",
            centre2: [0, 0, 0],
            level: 5,
            convention: Convention::Centre,
        };
        let hit = search(&f, 833, 8).expect("a hit");
        assert!(hit.from.le(hit.to) && !hit.to.le(hit.from));
        let t = hit.stacked[0].0;
        let rays = f.rays(&f.column_minima(), t);
        assert_eq!(rays.len(), 833);
        assert_eq!(f.quadric_rays(t).expect("centre convention"), rays);
        // Fewer rays just below the interval, more at its end.
        let below = Q {
            num: hit.from.num - 1,
            den: 1,
        };
        assert!(f.rays(&f.column_minima(), below).len() < 833);
        assert!(f.rays(&f.column_minima(), hit.to).len() > 833);
        let c = stack(&rays).counts();
        assert_eq!(
            (c.full, c.empty, c.partial),
            (hit.stacked[0].1, hit.stacked[0].2, hit.stacked[0].3)
        );
    }

    #[test]
    fn paraboloid_measures_match_the_quadric() {
        for convention in [Convention::Centre, Convention::Corner] {
            let f = Family {
                shape: Shape::Paraboloid,
                placement: "centre",
                centre2: [16, 16, 0],
                level: 4,
                convention,
            };
            for t in [
                Q { num: 7, den: 1 },
                Q { num: 31, den: 3 },
                Q { num: 2, den: 5 },
            ] {
                assert_eq!(
                    f.quadric_rays(t).unwrap(),
                    f.rays(&f.column_minima(), t),
                    "{convention:?} {t:?}"
                );
            }
        }
    }
}
