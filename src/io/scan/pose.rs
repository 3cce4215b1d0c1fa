//! A 6-DoF pose computed as OctoMap's `octomath::Pose6D` computes it, in `f32`, operation for operation,
//! so that scans placed by ktree and by OctoMap are the same floats.

/// A rigid motion: a rotation (a unit quaternion) followed by a translation, with OctoMap's arithmetic.
///
/// [`Pose::from_xyz_rpy`] builds the quaternion from Euler angles as `octomath::Quaternion(roll, pitch,
/// yaw)` does (the rotation matrix `Rz(yaw)·Ry(pitch)·Rx(roll)` in `f64`, its quaternion rounded to
/// `f32`), and [`Pose::transform`] rotates by `q·(0, v)·q⁻¹` and translates as `Pose6D::transform` does,
/// in `f32` in the same order: the results are OctoMap's to the bit.
///
/// ```
/// use ktree::io::Pose;
/// // A quarter turn about z, then 1 m along x.
/// let pose = Pose::from_xyz_rpy(1.0, 0.0, 0.0, 0.0, 0.0, std::f64::consts::FRAC_PI_2);
/// let p = pose.transform([1.0, 0.0, 0.0]);
/// assert!((p[0] - 1.0).abs() < 1e-6 && (p[1] - 1.0).abs() < 1e-6 && p[2].abs() < 1e-6);
/// assert_eq!(ktree::io::Pose::IDENTITY.transform([3.0, 4.0, 5.0]), [3.0, 4.0, 5.0]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// The translation, applied after the rotation.
    pub translation: [f32; 3],
    /// The rotation as a quaternion `[w, x, y, z]` (OctoMap's `u, x, y, z`), unit length when made from
    /// angles; a pose read from a file keeps the file's quaternion as it is.
    pub rotation: [f32; 4],
}

impl Default for Pose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// A quaternion `[w, x, y, z]` in OctoMap's `f32` arithmetic.
type Quaternion = [f32; 4];

/// The product `a·b` as `octomath::Quaternion::operator*` computes it.
fn multiply(a: Quaternion, b: Quaternion) -> Quaternion {
    let [au, ax, ay, az] = a;
    let [bu, bx, by, bz] = b;
    [
        au * bu - ax * bx - ay * by - az * bz,
        ay * bz - by * az + au * bx + bu * ax,
        az * bx - bz * ax + au * by + bu * ay,
        ax * by - bx * ay + au * bz + bu * az,
    ]
}

/// The conjugate (OctoMap's `Quaternion::inv`, an inverse for unit quaternions).
fn conjugate([u, x, y, z]: Quaternion) -> Quaternion {
    [u, -x, -y, -z]
}

/// `q` divided by its norm (the norm summed in `f64` from `f32` squares), as `Quaternion::normalized`.
fn normalized(q: Quaternion) -> Quaternion {
    let sum: f64 = q.iter().fold(0.0, |n, &c| n + f64::from(c * c));
    let norm = sum.sqrt() as f32;
    if f64::from(norm) > 0.0 {
        q.map(|c| c / norm)
    } else {
        q
    }
}

/// The square root of `max(0, v)` halved, rounded to `f32`: one component's magnitude.
fn half_root(v: f64) -> f32 {
    // std::max(0., v): v only when 0 < v (a NaN gives 0).
    let v = if 0.0 < v { v } else { 0.0 };
    (v.sqrt() / 2.0) as f32
}

/// `magnitude` with the sign of `difference` (non-negative: positive).
fn signed(magnitude: f32, difference: f64) -> f32 {
    if difference >= 0.0 {
        magnitude.abs()
    } else {
        -magnitude.abs()
    }
}

impl Pose {
    /// No rotation, no translation.
    pub const IDENTITY: Pose = Pose {
        translation: [0.0; 3],
        rotation: [1.0, 0.0, 0.0, 0.0],
    };

    /// The pose at `(x, y, z)` turned by `roll` about x, then `pitch` about y, then `yaw` about z (radians),
    /// as `octomath::Pose6D(x, y, z, roll, pitch, yaw)`.
    pub fn from_xyz_rpy(x: f32, y: f32, z: f32, roll: f64, pitch: f64, yaw: f64) -> Pose {
        let (sr, cr) = (roll.sin(), roll.cos());
        let (sp, cp) = (pitch.sin(), pitch.cos());
        let (sy, cy) = (yaw.sin(), yaw.cos());
        let m00 = cy * cp;
        let m01 = cy * sp * sr - sy * cr;
        let m02 = cy * sp * cr + sy * sr;
        let m10 = sy * cp;
        let m11 = sy * sp * sr + cy * cr;
        let m12 = sy * sp * cr - cy * sr;
        let m20 = -sp;
        let m21 = cp * sr;
        let m22 = cp * cr;
        let u = half_root(1.0 + m00 + m11 + m22);
        let qx = half_root(1.0 + m00 - m11 - m22);
        let qy = half_root(1.0 - m00 + m11 - m22);
        let qz = half_root(1.0 - m00 - m11 + m22);
        Pose {
            translation: [x, y, z],
            rotation: [
                u,
                signed(qx, m21 - m12),
                signed(qy, m02 - m20),
                signed(qz, m10 - m01),
            ],
        }
    }

    /// `v` rotated by the pose's rotation (`q·(0, v)·q⁻¹`, as `Quaternion::rotate`).
    pub fn rotate(&self, v: [f32; 3]) -> [f32; 3] {
        let q = self.rotation;
        let r = multiply(multiply(q, [0.0, v[0], v[1], v[2]]), conjugate(q));
        [r[1], r[2], r[3]]
    }

    /// `p` rotated, then translated (as `Pose6D::transform`).
    pub fn transform(&self, p: [f32; 3]) -> [f32; 3] {
        let r = self.rotate(p);
        let t = self.translation;
        [r[0] + t[0], r[1] + t[1], r[2] + t[2]]
    }

    /// The inverse motion, as `Pose6D::inv`: the conjugate rotation normalized, and the translation
    /// rotated back and negated.
    pub fn inverse(&self) -> Pose {
        let rotation = normalized(conjugate(self.rotation));
        let back = Pose {
            translation: [0.0; 3],
            rotation,
        };
        let t = self.translation;
        Pose {
            translation: back.rotate([-t[0], -t[1], -t[2]]),
            rotation,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pose_and_its_inverse_cancel() {
        let pose = Pose::from_xyz_rpy(1.5, -2.0, 0.25, 0.3, -0.7, 2.9);
        let n: f32 = pose.rotation.iter().map(|c| c * c).sum();
        assert!((n - 1.0).abs() < 1e-6);
        let p = [0.4f32, 7.0, -3.0];
        let back = pose.inverse().transform(pose.transform(p));
        for a in 0..3 {
            assert!((back[a] - p[a]).abs() < 1e-5, "{back:?}");
        }
    }

    #[test]
    fn angles_turn_about_the_axes_named() {
        let half_pi = std::f64::consts::FRAC_PI_2;
        let close = |a: [f32; 3], b: [f32; 3]| (0..3).all(|i| (a[i] - b[i]).abs() < 1e-6);
        let roll = Pose::from_xyz_rpy(0.0, 0.0, 0.0, half_pi, 0.0, 0.0);
        assert!(close(roll.transform([0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]));
        let pitch = Pose::from_xyz_rpy(0.0, 0.0, 0.0, 0.0, half_pi, 0.0);
        assert!(close(pitch.transform([0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]));
        let yaw = Pose::from_xyz_rpy(0.0, 0.0, 0.0, 0.0, 0.0, half_pi);
        assert!(close(yaw.transform([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]));
        // A half turn has w = 0 and a negative-free axis.
        let turn = Pose::from_xyz_rpy(0.0, 0.0, 0.0, 0.0, 0.0, std::f64::consts::PI);
        assert!(close(turn.transform([1.0, 2.0, 0.0]), [-1.0, -2.0, 0.0]));
    }
}
