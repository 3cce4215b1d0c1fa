//! Geometric transforms of a tree of any `K`: exact integer operations where the parameters allow (integer
//! translations, quarter turns, rational scales), one affine (or projective) overlay pass otherwise.

use ktree::ops::{self, Affine, AxisMap, Projective};
use ktree::KTree;

use crate::failure::Failure;

/// A uniform scale factor: an exact ratio `p/q`, or any positive number.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Factor {
    /// `p/q`, computed exactly by rational overlays.
    Ratio(u32, u32),
    /// Any other factor, by an affine pass.
    Real(f64),
}

/// Translated by `t` (K numbers): exactly when all are whole numbers (voxels leaving the universe are
/// dropped), by an affine pass otherwise.
pub(crate) fn translate<const K: usize>(tree: &KTree<K>, t: &[f64]) -> Result<KTree<K>, Failure> {
    let t: [f64; K] = t.try_into().map_err(|_| {
        Failure::Value(format!(
            "a translation of a K = {K} tree needs {K} numbers, got {}",
            t.len()
        ))
    })?;
    if t.iter().any(|v| !v.is_finite()) {
        return Err(Failure::Value(format!("translation {t:?} is not finite")));
    }
    if t.iter().all(|v| v.fract() == 0.0 && v.abs() < 9.0e15) {
        return Ok(ops::translate(tree, t.map(|v| v as i64)));
    }
    Ok(ops::transform(tree, &Affine::translation(t))?)
}

/// Rotated by `degrees` in the plane of axes `from` → `to`, about the universe's centre: by reordering
/// children for multiples of 90°, by an affine pass otherwise.
pub(crate) fn rotate<const K: usize>(
    tree: &KTree<K>,
    degrees: f64,
    from: usize,
    to: usize,
) -> Result<KTree<K>, Failure> {
    if !degrees.is_finite() {
        return Err(Failure::Value(format!("angle {degrees} is not finite")));
    }
    if degrees % 90.0 == 0.0 {
        let quarter = AxisMap::<K>::quarter_turn(from, to)?;
        let turns = ((degrees / 90.0) % 4.0) as i64;
        let mut out = tree.clone();
        for _ in 0..turns.rem_euclid(4) {
            out = ops::rotate_axes(&out, &quarter);
        }
        return Ok(out);
    }
    let centre = Affine::<K>::universe_centre(tree.level());
    let m = Affine::rotation_about(from, to, degrees, centre)?;
    Ok(ops::transform(tree, &m)?)
}

/// Scaled by `factor` about the universe's origin corner.
pub(crate) fn scale<const K: usize>(tree: &KTree<K>, factor: Factor) -> Result<KTree<K>, Failure> {
    match factor {
        Factor::Ratio(p, q) => Ok(ops::scale(tree, p, q)?),
        Factor::Real(s) if s.is_finite() && s > 0.0 => {
            Ok(ops::transform(tree, &Affine::scaling_about(s, [0.0; K]))?)
        }
        Factor::Real(s) => Err(Failure::Value(format!(
            "the scale factor must be a positive number, got {s}"
        ))),
    }
}

/// Mapped by a homogeneous `(K + 1) × (K + 1)` matrix (row-major, acting on column vectors `[x; 1]`):
/// affine when the last row is `0 … 0 1`, projective otherwise.
pub(crate) fn matrix<const K: usize>(tree: &KTree<K>, m: &[f64]) -> Result<KTree<K>, Failure> {
    match Affine::<K>::from_homogeneous(m) {
        Ok(a) => Ok(ops::transform(tree, &a)?),
        Err(_) => {
            let p = Projective::<K>::from_homogeneous(m)?;
            Ok(ops::transform_projective(tree, &p)?)
        }
    }
}
