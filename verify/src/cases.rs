//! Random ray sets for the property tests: random ray sets in K = 1 … 4 that print readably
//! when a failure is shrunk.

use std::fmt;

use ktree::{Ray, RaySet};
use proptest::prelude::*;

/// Largest level of the random ray sets for each K (L ≤ 6 for K ≤ 3, L ≤ 4 for K = 4): small enough for
/// the dense references.
pub const fn max_test_level(k: usize) -> u32 {
    if k <= 3 {
        6
    } else {
        4
    }
}

/// A ray set under test, printed in the ray text format so a shrunk failure reads as a file.
#[derive(Clone)]
pub struct Case<const K: usize> {
    /// The rays.
    pub rays: RaySet<K>,
}

impl<const K: usize> fmt::Debug for Case<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "\n# ktree rays v1\n{K} {}", self.rays.level())?;
        for ray in self.rays.iter() {
            for c in &ray.start[..K - 1] {
                write!(f, "{c} ")?;
            }
            writeln!(f, "{} {}", ray.z1(), ray.z2)?;
        }
        Ok(())
    }
}

/// Random runs anywhere: noisy objects that exercise splitting down to voxels.
fn scattered_runs<const K: usize>(level: u32) -> impl Strategy<Value = Vec<Ray<K>>> {
    let side = 1u32 << level;
    let ray = (prop::array::uniform::<_, K>(0..side), 0..side, 1..=side).prop_map(
        move |(mut start, z1, len)| {
            let z2 = (z1 + len).min(side);
            start[K - 1] = z1.min(z2 - 1);
            Ray::new(start, z2)
        },
    );
    prop::collection::vec(ray, 0..40)
}

/// A union of random boxes: solid objects with large aligned parts that combine.
fn box_union_runs<const K: usize>(level: u32) -> impl Strategy<Value = Vec<Ray<K>>> {
    let side = 1u32 << level;
    let bounds = prop::array::uniform::<_, K>((0..side, 1..=side));
    prop::collection::vec(bounds, 1..4).prop_map(move |boxes| {
        let mut rays = Vec::new();
        for b in boxes {
            let lo: [u32; K] = std::array::from_fn(|i| b[i].0);
            let hi: [u32; K] = std::array::from_fn(|i| (b[i].0 + b[i].1).min(side));
            for_each_column(lo, hi, |mut start| {
                start[K - 1] = lo[K - 1];
                rays.push(Ray::new(start, hi[K - 1]));
            });
        }
        rays
    })
}

/// Calls `visit` with every column (first K−1 coordinates) of the box `[lo, hi)`.
pub fn for_each_column<const K: usize>(
    lo: [u32; K],
    hi: [u32; K],
    mut visit: impl FnMut([u32; K]),
) {
    let mut col = lo;
    loop {
        visit(col);
        let mut axis = 0;
        loop {
            if axis + 1 >= K {
                return;
            }
            col[axis] += 1;
            if col[axis] < hi[axis] {
                break;
            }
            col[axis] = lo[axis];
            axis += 1;
        }
    }
}

/// Special objects: empty, the full universe, one voxel, runs on the universe's faces.
fn special_runs<const K: usize>(level: u32) -> impl Strategy<Value = Vec<Ray<K>>> {
    let side = 1u32 << level;
    let voxel = prop::array::uniform::<_, K>(0..side).prop_map(|p| vec![Ray::new(p, p[K - 1] + 1)]);
    let faces = prop::array::uniform::<_, K>(prop::bool::ANY).prop_map(move |hi| {
        // A full-length run in a corner column, plus a one-voxel run at z = U−1 and at z = 0.
        let mut start = [0u32; K];
        for (c, &h) in start.iter_mut().zip(hi.iter()) {
            *c = if h { side - 1 } else { 0 };
        }
        let mut rays = vec![];
        start[K - 1] = 0;
        rays.push(Ray::new(start, side));
        let mut other = start;
        if K > 1 {
            other[0] = side - 1 - other[0];
            other[K - 1] = side - 1;
            rays.push(Ray::new(other, side));
        }
        rays
    });
    prop_oneof![Just(Vec::new()), Just(full_runs::<K>(level)), voxel, faces]
}

fn full_runs<const K: usize>(level: u32) -> Vec<Ray<K>> {
    RaySet::<K>::full(level)
        .expect("small level")
        .iter()
        .collect()
}

/// Random ray sets for dimension K, levels 0 ..= `max_test_level(K)`.
pub fn ray_sets<const K: usize>() -> impl Strategy<Value = Case<K>> {
    (0..=max_test_level(K)).prop_flat_map(|level| {
        prop_oneof![
            3 => scattered_runs::<K>(level),
            4 => box_union_runs::<K>(level),
            1 => special_runs::<K>(level),
        ]
        .prop_map(move |runs| Case {
            rays: RaySet::from_rays(level, runs).expect("generated runs are valid"),
        })
    })
}

/// The project's folder `data/<sub>` (the real meshes and volumes, with their sources in
/// `data/SOURCES.md`).
pub fn data_dir(sub: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data")
        .join(sub)
}
