//! Named quadrics — ball, ellipsoid, paraboloid, cylinder, cone, half-space — built from rational parameters
//! as sums of squared integer linear forms, so that the matrix is exact.

use super::rational::common_denominator;
use super::{Frame, Quadric, Rational, SolidError};

/// Accumulates `2·Q` as an integer matrix: squares `coef·(l·V)²` and linear terms `l·V`.
struct Builder<const K: usize> {
    m: Vec<Vec<i128>>,
}

impl<const K: usize> Builder<K> {
    fn new() -> Self {
        Self {
            m: vec![vec![0; K + 1]; K + 1],
        }
    }

    fn square(&mut self, coef: i128, l: &[i128]) -> Result<(), SolidError> {
        for i in 0..=K {
            for j in 0..=K {
                let t = checked(&[2, coef, l[i], l[j]])?;
                self.m[i][j] = self.m[i][j].checked_add(t).ok_or_else(too_large)?;
            }
        }
        Ok(())
    }

    fn linear(&mut self, l: &[i128]) -> Result<(), SolidError> {
        for (i, &li) in l[..K].iter().enumerate() {
            self.m[i][K] = self.m[i][K].checked_add(li).ok_or_else(too_large)?;
            self.m[K][i] = self.m[i][K];
        }
        self.m[K][K] = self.m[K][K]
            .checked_add(checked(&[2, l[K]])?)
            .ok_or_else(too_large)?;
        Ok(())
    }

    fn finish(self, frame: Frame) -> Result<Quadric<K>, SolidError> {
        Quadric::from_matrix(&self.m, frame)
    }
}

fn too_large() -> SolidError {
    SolidError::BadParameter("parameters too large or too precise for an exact matrix".into())
}

fn checked(factors: &[i128]) -> Result<i128, SolidError> {
    factors
        .iter()
        .try_fold(1i128, |p, &f| p.checked_mul(f))
        .filter(|p| p.unsigned_abs() < 1 << 100)
        .ok_or_else(too_large)
}

/// The linear form `D·x_i − p` (a coordinate minus a parameter, all over the denominator `D`).
fn offset<const K: usize>(axis: usize, d: i128, p: i128) -> Vec<i128> {
    let mut l = vec![0; K + 1];
    l[axis] = d;
    l[K] = -p;
    l
}

fn unit<const K: usize>() -> Vec<i128> {
    let mut l = vec![0; K + 1];
    l[K] = 1;
    l
}

fn positive(name: &str, r: Rational) -> Result<(), SolidError> {
    if r.num() <= 0 {
        return Err(SolidError::BadParameter(format!(
            "{name} must be positive, got {r}"
        )));
    }
    Ok(())
}

fn check_axis<const K: usize>(axis: usize) -> Result<(), SolidError> {
    if axis >= K {
        return Err(SolidError::BadParameter(format!(
            "axis {axis} does not exist in {K}-D"
        )));
    }
    Ok(())
}

impl<const K: usize> Quadric<K> {
    /// The closed ball `Σ (x_i − c_i)² ≤ r²` (a disk in 2-D, an interval in 1-D, a hypersphere's inside in 4-D).
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] for a non-positive radius or parameters too large for an exact matrix.
    pub fn ball(centre: [Rational; K], radius: Rational, frame: Frame) -> Result<Self, SolidError> {
        positive("radius", radius)?;
        let mut all = centre.to_vec();
        all.push(radius);
        let (d, p) = common_denominator(&all)?;
        let mut b = Builder::<K>::new();
        for (i, &c) in p[..K].iter().enumerate() {
            b.square(1, &offset::<K>(i, d, c))?;
        }
        b.square(-checked(&[p[K], p[K]])?, &unit::<K>())?;
        b.finish(frame)
    }

    /// The axis-aligned ellipsoid `Σ ((x_i − c_i) / a_i)² ≤ 1`.
    ///
    /// # Errors
    /// As [`Quadric::ball`].
    pub fn ellipsoid(
        centre: [Rational; K],
        semi_axes: [Rational; K],
        frame: Frame,
    ) -> Result<Self, SolidError> {
        for &a in &semi_axes {
            positive("semi-axis", a)?;
        }
        let mut all = centre.to_vec();
        all.extend_from_slice(&semi_axes);
        let (d, p) = common_denominator(&all)?;
        // Multiply through by P = Π a_j²: Σ (P / a_i²)(D x_i − c_i)² − P ≤ 0.
        let sq: Vec<i128> = (0..K)
            .map(|i| checked(&[p[K + i], p[K + i]]))
            .collect::<Result<_, _>>()?;
        let prod = checked(&sq)?;
        let mut b = Builder::<K>::new();
        for (i, (&c, &a2)) in p[..K].iter().zip(&sq).enumerate() {
            b.square(prod / a2, &offset::<K>(i, d, c))?;
        }
        b.square(-prod, &unit::<K>())?;
        b.finish(frame)
    }

    /// The solid paraboloid opening along the last axis from `apex`: `h·Σ_{i<K−1} (x_i − a_i)² ≤ r²·(z − a_z)`,
    /// whose cross-section at height `h` above the apex is the ball of radius `r`.
    ///
    /// # Errors
    /// As [`Quadric::ball`].
    pub fn paraboloid(
        apex: [Rational; K],
        radius: Rational,
        height: Rational,
        frame: Frame,
    ) -> Result<Self, SolidError> {
        positive("radius", radius)?;
        positive("height", height)?;
        let mut all = apex.to_vec();
        all.push(radius);
        all.push(height);
        let (d, p) = common_denominator(&all)?;
        let (r, h) = (p[K], p[K + 1]);
        // Over D: h Σ (D x_i − a_i)² − r² (D z − a_z) ≤ 0 (both sides scaled by D³).
        let mut b = Builder::<K>::new();
        for (i, &c) in p[..K - 1].iter().enumerate() {
            b.square(h, &offset::<K>(i, d, c))?;
        }
        let r2 = checked(&[r, r])?;
        let lin: Vec<i128> = offset::<K>(K - 1, d, p[K - 1])
            .iter()
            .map(|&x| checked(&[-2, r2, x]))
            .collect::<Result<_, _>>()?;
        b.linear(&lin)?;
        b.finish(frame)
    }

    /// The infinite solid cylinder of radius `r` around the line through `centre` along `axis`:
    /// `Σ_{i≠axis} (x_i − c_i)² ≤ r²` (clipped by the universe; `centre[axis]` is ignored).
    ///
    /// # Errors
    /// As [`Quadric::ball`], and for an axis `≥ K`.
    pub fn cylinder(
        axis: usize,
        centre: [Rational; K],
        radius: Rational,
        frame: Frame,
    ) -> Result<Self, SolidError> {
        check_axis::<K>(axis)?;
        positive("radius", radius)?;
        let mut all = centre.to_vec();
        all.push(radius);
        let (d, p) = common_denominator(&all)?;
        let mut b = Builder::<K>::new();
        for i in (0..K).filter(|&i| i != axis) {
            b.square(1, &offset::<K>(i, d, p[i]))?;
        }
        b.square(-checked(&[p[K], p[K]])?, &unit::<K>())?;
        b.finish(frame)
    }

    /// The solid double cone with apex `apex` along `axis`, of radius `r` at distance `h` from the apex:
    /// `h²·Σ_{i≠axis} (x_i − a_i)² ≤ r²·(x_axis − a_axis)²`. A quadric cone has two nappes; intersect with a
    /// half-space ([`crate::rays`] Boolean operations) to keep one.
    ///
    /// # Errors
    /// As [`Quadric::cylinder`].
    pub fn cone(
        axis: usize,
        apex: [Rational; K],
        radius: Rational,
        height: Rational,
        frame: Frame,
    ) -> Result<Self, SolidError> {
        check_axis::<K>(axis)?;
        positive("radius", radius)?;
        positive("height", height)?;
        let mut all = apex.to_vec();
        all.push(radius);
        all.push(height);
        let (d, p) = common_denominator(&all)?;
        let (r, h) = (p[K], p[K + 1]);
        let mut b = Builder::<K>::new();
        let h2 = checked(&[h, h])?;
        for i in (0..K).filter(|&i| i != axis) {
            b.square(h2, &offset::<K>(i, d, p[i]))?;
        }
        b.square(-checked(&[r, r])?, &offset::<K>(axis, d, p[axis]))?;
        b.finish(frame)
    }

    /// The closed half-space `n · x ≤ offset`.
    ///
    /// # Errors
    /// [`SolidError::BadParameter`] for a zero normal or parameters too large.
    pub fn half_space(
        normal: [Rational; K],
        offset: Rational,
        frame: Frame,
    ) -> Result<Self, SolidError> {
        if normal.iter().all(|n| n.num() == 0) {
            return Err(SolidError::BadParameter(
                "a half-space needs a non-zero normal".into(),
            ));
        }
        let mut all = normal.to_vec();
        all.push(offset);
        let (_, p) = common_denominator(&all)?;
        let mut l = p.clone();
        l[K] = -p[K];
        let mut b = Builder::<K>::new();
        b.linear(&l)?;
        b.finish(frame)
    }
}
