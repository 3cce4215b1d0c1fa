//! Shading of the rendered images: the light of a camera, Lambert shading with ambient light, the colours
//! of the six axis-aligned faces, and surface normals read from the rays an object was built from.

use super::camera::{v3, Camera};
use crate::rays::RaySet;

/// The light direction (towards the light) for a camera: above and to the left of the eye.
pub(super) fn light_for(camera: &Camera) -> [f64; 3] {
    let f = camera.frame();
    let back = [-f.f[0], -f.f[1], -f.f[2]];
    let l = v3::add_scaled(v3::add_scaled(back, 0.6, f.u), -0.25, f.r);
    v3::normalize(l).expect("non-zero light")
}

/// Lambert shading with ambient light.
#[inline]
pub(super) fn shade(normal: [f64; 3], light: [f64; 3], base: [u8; 3]) -> [u8; 3] {
    let k = 0.2 + 0.8 * v3::dot(normal, light).max(0.0);
    base.map(|c| (f64::from(c) * k).round().clamp(0.0, 255.0) as u8)
}

/// The shaded colour of each of the six axis-aligned faces, computed once an image: a face is lit the same
/// wherever it is seen, and a pixel's colour is then a lookup.
pub(super) struct FaceColours([[u8; 3]; 6]);

impl FaceColours {
    pub(super) fn new(light: [f64; 3], base: [u8; 3]) -> Self {
        Self(std::array::from_fn(|i| {
            let mut normal = [0.0; 3];
            normal[i / 2] = if i % 2 == 1 { -1.0 } else { 1.0 };
            shade(normal, light, base)
        }))
    }

    /// The colour of the face on `axis` that a ray along `dir` enters (the face looks against the ray).
    #[inline]
    pub(super) fn entered(&self, axis: usize, dir: [f64; 3]) -> [u8; 3] {
        self.0[2 * axis + usize::from(dir[axis] > 0.0)]
    }
}

/// Looks up the surface normal of the voxel `v` seen through a face on `axis` from the rays' normals:
/// the run's end normal for a face across the run, else the end normals interpolated along the run.
pub(super) fn ray_normal(
    rays: &RaySet<3>,
    v: [u32; 3],
    axis: usize,
    dir: [f64; 3],
) -> Option<[f64; 3]> {
    let key = rays.column_key(v);
    let keys = rays.column_keys();
    let start = keys.partition_point(|&k| k < key);
    let end = keys.partition_point(|&k| k <= key);
    let runs = &rays.runs()[start..end];
    let j = runs.partition_point(|&(_, z2)| z2 <= v[2]);
    let &(z1, z2) = runs.get(j)?;
    if z1 > v[2] {
        return None;
    }
    let [n1, n2] = rays.normals(start + j)?;
    let (n1, n2) = (n1.map(f64::from), n2.map(f64::from));
    let n = if axis == 2 {
        if dir[2] > 0.0 {
            n1
        } else {
            n2
        }
    } else {
        let t = (f64::from(v[2]) + 0.5 - f64::from(z1)) / f64::from(z2 - z1);
        [
            n1[0] + t * (n2[0] - n1[0]),
            n1[1] + t * (n2[1] - n1[1]),
            n1[2] + t * (n2[2] - n1[2]),
        ]
    };
    let n = v3::normalize(n)?;
    (v3::norm(n) > 0.5).then_some(n)
}
