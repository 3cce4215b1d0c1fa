//! The boundary of each value of an octree with values: one closed, outward-oriented surface per value,
//! each triangle with the value behind it.
//!
//! A value's surface is the boundary mesh of the voxels holding it, made by the sweep of
//! [`boundary_mesh`](super::boundary_mesh), so it is closed, crack-free and 2-manifold as that one is. Its
//! rectangles are merged as far as one value (or nothing) stays behind each: each plane's boundary is
//! split where the value behind it changes, and the pieces merged into rectangles as the binary sweep
//! merges its planes. One sweep of the tree's cross-sections serves every value. A face between two
//! values is in both values' surfaces, oriented outward from each; [`ValueMesh::faces_once`] gives it
//! once.

use std::collections::{BTreeMap, HashMap};

use crate::tree::storage::infallible;
use crate::tree::valued::{ValueLeaves, ValueStorage};
use crate::value::{Dtype, Value};
use crate::KTree;

use super::{sweep, Frame, SurfaceMesh};

/// The surface of one value: closed and outward-oriented around the voxels holding it.
#[derive(Debug, Clone, PartialEq)]
pub struct ValueSurface<V> {
    /// The value inside.
    pub value: V,
    /// The surface, in voxel coordinates until [`ValueMesh::placed`].
    pub mesh: SurfaceMesh,
    /// For each triangle, the value on its outer side (`None`: nothing).
    pub behind: Vec<Option<V>>,
    /// The value's own name, when it has one (a label's name: `liver`), as
    /// [`ValueMesh::with_names`] gives it.
    pub label: Option<String>,
}

impl<V: Value> ValueSurface<V> {
    /// A name for the value's part of a file: its [`label`](Self::label) when it has one, else
    /// `label_3` (integers), `value_0.25` (floats), `rgb_255_0_0` (colours).
    pub fn name(&self) -> String {
        if let Some(label) = &self.label {
            return label.clone();
        }
        self.default_name()
    }

    /// The name of the value's part of a file when it has no name of its own.
    fn default_name(&self) -> String {
        match V::DTYPE {
            Some(Dtype::F32) => format!("value_{}", self.value.text()),
            Some(Dtype::Rgb) => format!("rgb_{}", self.value.text().replace(',', "_")),
            _ => format!("label_{}", self.value.text()),
        }
    }
}

/// The surfaces of every value of a tree, by increasing value ([`Value::key`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ValueMesh<V> {
    /// One surface per value.
    pub surfaces: Vec<ValueSurface<V>>,
}

impl<V: Value> ValueMesh<V> {
    /// The surfaces in world units (see [`SurfaceMesh::placed`]).
    pub fn placed(&self, frame: &Frame) -> Self {
        ValueMesh {
            surfaces: self
                .surfaces
                .iter()
                .map(|s| ValueSurface {
                    mesh: s.mesh.placed(frame),
                    ..s.clone()
                })
                .collect(),
        }
    }

    /// The surfaces named by `name_of` (a label's name, say, from a file's notes): each name made fit
    /// for the groups, materials and meshes of OBJ and glTF files — every character other than a letter,
    /// a digit, `_`, `-` or `.` becomes `_` — and distinct: a name another surface already has is
    /// followed by `_` and the value. A surface `name_of` names nothing keeps its default name.
    ///
    /// ```
    /// use ktree::export::surface::value_boundary_mesh;
    /// let mut dense = [None; 8];
    /// (dense[0], dense[1], dense[2]) = (Some(1u8), Some(2), Some(3));
    /// let mesh = value_boundary_mesh(&ktree::KTree::<3, u8>::from_dense_values(1, &dense).unwrap());
    /// let named = mesh.with_names(|v| (*v < 3).then(|| "left lung".to_string()));
    /// let names: Vec<String> = named.surfaces.iter().map(|s| s.name()).collect();
    /// assert_eq!(names, ["left_lung", "left_lung_2", "label_3"]);
    /// ```
    pub fn with_names(mut self, name_of: impl Fn(&V) -> Option<String>) -> Self {
        let mut taken = std::collections::BTreeSet::new();
        for s in &mut self.surfaces {
            s.label = None;
        }
        // The default names stay as they are; a name of a value's own gives way to them.
        taken.extend(self.surfaces.iter().map(ValueSurface::default_name));
        for s in &mut self.surfaces {
            let Some(name) = name_of(&s.value) else {
                continue;
            };
            let fit: String = name
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.') {
                        c
                    } else {
                        '_'
                    }
                })
                .collect();
            let mut unique = if fit.is_empty() {
                s.default_name()
            } else {
                fit
            };
            if unique != s.default_name() {
                while taken.contains(&unique) {
                    unique = format!("{unique}_{}", s.value.text().replace(',', "_"));
                }
                taken.insert(unique.clone());
            }
            s.label = Some(unique);
        }
        self
    }

    /// Every face once, as `(surface, triangle)` indices: a face against nothing from its value's
    /// surface, a face between two values from the surface of the smaller one (oriented outward from it).
    pub fn faces_once(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.surfaces.iter().enumerate().flat_map(|(k, s)| {
            s.behind
                .iter()
                .enumerate()
                .filter(|(_, b)| b.is_none_or(|b| s.value.key() < b.key()))
                .map(move |(t, _)| (k, t))
        })
    }

    /// The vertices of all the surfaces.
    pub fn vertex_count(&self) -> usize {
        self.surfaces.iter().map(|s| s.mesh.vertices.len()).sum()
    }
}

/// The boundary of each value of `tree`: per value, the closed, outward-oriented surface of the voxels
/// holding it, each triangle with the value behind it (see the module's documentation). In voxel
/// coordinates. (Any valued storage: [`try_value_boundary_mesh`].)
///
/// ```
/// use ktree::export::surface::value_boundary_mesh;
/// use ktree::KTree;
/// // Voxel (0, 0, 0) holds 1, voxel (1, 0, 0) holds 2.
/// let mut dense = [None; 8];
/// (dense[0], dense[1]) = (Some(1u8), Some(2));
/// let mesh = value_boundary_mesh(&KTree::<3, u8>::from_dense_values(1, &dense).unwrap());
/// let one = &mesh.surfaces[0];
/// assert_eq!((one.value, one.mesh.volume(), one.mesh.triangles.len()), (1, 1.0, 12));
/// // The square at x = 1 has 2 behind it; the rest of the cube has nothing.
/// assert_eq!(one.behind.iter().filter(|b| **b == Some(2)).count(), 2);
/// // Each cube's 10 triangles against nothing and the 2 between them, once.
/// assert_eq!(mesh.faces_once().count(), 22);
/// ```
///
/// # Performance
/// One sweep of the tree's cross-sections, each split into the voxels of each value (the work of
/// [`boundary_mesh`](super::boundary_mesh) for every value at once); the value behind each triangle
/// is the one its rectangle was split by. A value is swept only while it is in the sections of a step,
/// over the rows it is in: the work and the memory besides the surfaces follow the values a section
/// meets, not all the values, so a segmentation of many small labels costs about what one of few does.
///
/// # Panics
/// As [`boundary_mesh`](super::boundary_mesh).
pub fn value_boundary_mesh<V: Value>(tree: &KTree<3, V>) -> ValueMesh<V> {
    infallible(try_value_boundary_mesh(tree))
}

/// [`value_boundary_mesh`] over any valued storage.
///
/// ```
/// use ktree::export::surface::{try_value_boundary_mesh, value_boundary_mesh};
/// let tree = ktree::KTree::<3, f32>::from_dense_values(1, &[Some(0.5); 8]).unwrap();
/// let mesh = try_value_boundary_mesh(&tree).unwrap();
/// assert_eq!(mesh, value_boundary_mesh(&tree));
/// assert_eq!(mesh.surfaces[0].name(), "value_0.5");
/// assert_eq!(mesh.surfaces[0].mesh.triangles.len(), 12); // the cube's six squares
/// ```
///
/// # Errors
/// The storage's read error.
///
/// # Panics
/// As [`boundary_mesh`](super::boundary_mesh).
pub fn try_value_boundary_mesh<T: ValueStorage<3>>(
    tree: &T,
) -> Result<ValueMesh<T::Value>, T::Error> {
    let mut values = BTreeMap::new();
    for leaf in ValueLeaves::new(tree) {
        if let (_, Some(v)) = leaf? {
            values.entry(v.key()).or_insert(v);
        }
    }
    let colour: HashMap<_, u32> = values.keys().zip(0..).map(|(k, c)| (*k, c)).collect();
    let meshes = sweep::sweep_colours(tree, |v| colour[&v.key()], values.len())?;
    let values: Vec<T::Value> = values.into_values().collect();
    let surfaces = values
        .iter()
        .zip(meshes)
        .map(|(&value, (mesh, behind))| ValueSurface {
            value,
            mesh,
            behind: behind
                .into_iter()
                .map(|c| (c != sweep::NOTHING).then(|| values[c as usize]))
                .collect(),
            label: None,
        })
        .collect();
    Ok(ValueMesh { surfaces })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::collections::HashMap;

    /// Random labels 1 to 3 (or nothing) in aligned blocks of every size, at `level`.
    fn labels(level: u32) -> impl Strategy<Value = Vec<Option<u8>>> {
        blocks(level, level, 4, 12)
    }

    /// Random labels below `values` (or nothing) in up to `count` aligned blocks of sides below
    /// `2^max_log`, at `level`.
    fn blocks(
        level: u32,
        max_log: u32,
        values: u8,
        count: usize,
    ) -> impl Strategy<Value = Vec<Option<u8>>> {
        let side = 1usize << level;
        let block = (0..max_log, any::<[u16; 3]>(), prop::option::of(1u8..values));
        prop::collection::vec(block, 1..count).prop_map(move |blocks| {
            let mut dense = vec![None; side * side * side];
            for (log, at, value) in blocks {
                let at = at.map(|c| ((c as usize % side) >> log) << log);
                for z in at[2]..at[2] + (1 << log) {
                    for y in at[1]..at[1] + (1 << log) {
                        for x in at[0]..at[0] + (1 << log) {
                            dense[x + side * (y + side * z)] = value;
                        }
                    }
                }
            }
            dense
        })
    }

    /// The value of voxel `p` of `dense` (nothing outside the universe).
    fn at(dense: &[Option<u8>], side: i64, p: [i64; 3]) -> Option<u8> {
        if p.iter().all(|c| (0..side).contains(c)) {
            dense[(p[0] + side * (p[1] + side * p[2])) as usize]
        } else {
            None
        }
    }

    /// The unit faces between a voxel of value `v` and its neighbour holding `w`, by `(v, w)`, counted on
    /// the dense array.
    fn reference(dense: &[Option<u8>], side: i64) -> HashMap<(u8, Option<u8>), f64> {
        let mut out = HashMap::new();
        for z in 0..side {
            for y in 0..side {
                for x in 0..side {
                    let Some(v) = at(dense, side, [x, y, z]) else {
                        continue;
                    };
                    for a in 0..3 {
                        for step in [-1, 1] {
                            let mut q = [x, y, z];
                            q[a] += step;
                            let w = at(dense, side, q);
                            if w != Some(v) {
                                *out.entry((v, w)).or_insert(0.0) += 1.0;
                            }
                        }
                    }
                }
            }
        }
        out
    }

    /// A triangle's normal (twice its area long) and its area.
    fn normal(p: [[f64; 3]; 3]) -> ([f64; 3], f64) {
        let u: [f64; 3] = std::array::from_fn(|a| p[1][a] - p[0][a]);
        let w: [f64; 3] = std::array::from_fn(|a| p[2][a] - p[0][a]);
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        (n, (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() / 2.0)
    }

    fn check(level: u32, dense: &[Option<u8>]) {
        let side = 1i64 << level;
        let tree = KTree::<3, u8>::from_dense_values(level, dense).unwrap();
        let mesh = value_boundary_mesh(&tree);
        let mut areas: HashMap<(u8, Option<u8>), f64> = HashMap::new();
        let mut once: HashMap<(u8, Option<u8>), f64> = HashMap::new();
        for s in &mesh.surfaces {
            assert_eq!(s.behind.len(), s.mesh.triangles.len());
            let voxels = dense.iter().filter(|v| **v == Some(s.value)).count();
            assert_eq!(s.mesh.volume(), voxels as f64, "the volume of {}", s.value);
            // Closed: every directed edge is met once each way.
            let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
            for t in &s.mesh.triangles {
                for i in 0..3 {
                    let (p, q) = (t[i], t[(i + 1) % 3]);
                    *edges.entry((p.min(q), p.max(q))).or_insert(0) += if p < q { 1 } else { -1 };
                }
            }
            assert!(edges.values().all(|&n| n == 0), "{} is closed", s.value);
            for (t, tri) in s.mesh.triangles.iter().enumerate() {
                let p = tri.map(|i| s.mesh.vertices[i as usize]);
                let (n, area) = normal(p);
                *areas.entry((s.value, s.behind[t])).or_insert(0.0) += area;
                // Points inside the triangle: the value on its inner side, `behind` on its outer side.
                for weights in [[0.31, 0.33, 0.36], [0.6, 0.2, 0.2], [0.15, 0.7, 0.15]] {
                    let c: [f64; 3] =
                        std::array::from_fn(|a| (0..3).map(|i| weights[i] * p[i][a]).sum::<f64>());
                    let voxel = |sign: f64| {
                        std::array::from_fn(|a| {
                            (c[a] + sign * 0.25 * n[a] / n[a].abs().max(1.0)).floor() as i64
                        })
                    };
                    assert_eq!(at(dense, side, voxel(-1.0)), Some(s.value));
                    assert_eq!(at(dense, side, voxel(1.0)), s.behind[t]);
                }
            }
        }
        for (k, t) in mesh.faces_once() {
            let s = &mesh.surfaces[k];
            let (_, area) = normal(s.mesh.triangles[t].map(|i| s.mesh.vertices[i as usize]));
            *once.entry((s.value, s.behind[t])).or_insert(0.0) += area;
        }
        let reference = reference(dense, side);
        let close = |a: &HashMap<_, f64>, b: &HashMap<_, f64>| {
            a.len() == b.len()
                && a.iter()
                    .all(|(k, v)| b.get(k).is_some_and(|w| (v - w).abs() < 1e-9))
        };
        assert!(close(&areas, &reference), "{areas:?} against {reference:?}");
        // Once: against nothing, or from the smaller value's side.
        let expected: HashMap<_, f64> = reference
            .into_iter()
            .filter(|((v, w), _)| w.is_none_or(|w| *v < w))
            .collect();
        assert!(close(&once, &expected), "{once:?} against {expected:?}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn each_value_is_closed_and_its_faces_are_those_of_the_voxels(dense in labels(3)) {
            check(3, &dense);
        }

        #[test]
        fn each_value_is_closed_at_level_4(dense in labels(4)) {
            check(4, &dense);
        }

        /// Many small values, most of them appearing, leaving and appearing again along the sweep: each
        /// swept only while it is met, in sweeps handed from one value to the next.
        #[test]
        fn many_small_values_are_each_closed(dense in blocks(4, 2, 200, 120)) {
            check(4, &dense);
        }
    }

    #[test]
    fn a_value_alone_in_space_keeps_its_rectangles() {
        // Two blocks of 2 × 2 × 2 apart: six squares each, merged.
        let side = 8;
        let mut dense = vec![None; side * side * side];
        for z in 0..2 {
            for y in 0..2 {
                for x in 0..2 {
                    dense[x + side * (y + side * z)] = Some(1u8);
                    dense[x + 4 + side * (y + side * (z + 4))] = Some(2);
                }
            }
        }
        check(3, &dense);
        let mesh = value_boundary_mesh(&KTree::<3, u8>::from_dense_values(3, &dense).unwrap());
        assert!(mesh.surfaces.iter().all(|s| s.mesh.triangles.len() == 12));
    }

    #[test]
    fn touching_values_keep_their_rectangles() {
        // Blocks of 2 × 2 × 2 side by side along each axis in turn: six squares each, the one between
        // them with the other value behind.
        for axis in 0..3 {
            let side = 4;
            let mut dense = vec![None; side * side * side];
            for z in 0..2 {
                for y in 0..2 {
                    for x in 0..2 {
                        let mut p = [x, y, z];
                        dense[p[0] + side * (p[1] + side * p[2])] = Some(1u8);
                        p[axis] += 2;
                        dense[p[0] + side * (p[1] + side * p[2])] = Some(2);
                    }
                }
            }
            check(2, &dense);
            let mesh = value_boundary_mesh(&KTree::<3, u8>::from_dense_values(2, &dense).unwrap());
            for s in &mesh.surfaces {
                assert_eq!(s.mesh.triangles.len(), 12, "axis {axis}, value {}", s.value);
                let other = 3 - s.value;
                assert_eq!(s.behind.iter().filter(|b| **b == Some(other)).count(), 2);
            }
        }
        // A slab of 4 × 4 × 1 under two values side by side (split along x, then along y): its top is
        // split in two rectangles, its five other sides whole.
        for split in 0..2 {
            let side = 4;
            let mut dense = vec![None; side * side * side];
            for y in 0..4 {
                for x in 0..4 {
                    dense[x + side * y] = Some(1u8);
                    dense[x + side * (y + side)] = Some(if [x, y][split] < 2 { 2 } else { 3 });
                }
            }
            check(2, &dense);
            let mesh = value_boundary_mesh(&KTree::<3, u8>::from_dense_values(2, &dense).unwrap());
            let one = &mesh.surfaces[0];
            assert_eq!(one.value, 1);
            let behind = |v: u8| one.behind.iter().filter(|b| **b == Some(v)).count();
            assert_eq!((behind(2), behind(3)), (2, 2), "split along {split}");
            // The bottom and two sides: two triangles each; the two sides where the top's rectangles
            // meet on their edge: a fan of five around the centre.
            assert_eq!(
                one.mesh.triangles.len(),
                4 + 3 * 2 + 2 * 5,
                "split along {split}"
            );
        }
    }
}
