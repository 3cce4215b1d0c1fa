//! Several meshes in one universe as labels: mesh `i` (in the order given) holds label `i + 1`, the
//! voxels of no mesh are the background. Each mesh is voxelized alone into its runs
//! ([`TriangleMesh::to_rays`], the inside rule of the binary voxelizer), and the runs of every mesh are
//! merged column by column: **where meshes overlap, the later mesh wins** (the largest label), as
//! [`KTree::overlay`](crate::KTree::overlay) of the meshes' trees one after the other would give.

use super::{MeshTransform, TriangleMesh};
use crate::rays::{ValueRun, ValueRuns};
use crate::solid::SolidError;
use crate::space::Universe;
use crate::value::{Dtype, Value};

/// The labels of several meshes as valued runs, with what was noticed on the way.
#[derive(Debug, Clone)]
pub struct LabelRuns<V> {
    /// Label `i + 1` in the voxels whose centres are inside mesh `i` and no later mesh.
    pub runs: ValueRuns<3, V>,
    /// For each mesh, its edges not shared by exactly two triangles (0 for a closed mesh; see
    /// [`TriangleMesh::open_edges`]).
    pub open_edges: Vec<usize>,
    /// For each mesh, the voxels that hold its label (0 for a mesh the later ones hide).
    pub voxels: Vec<u64>,
}

/// The meshes placed by one `placement` in a universe of level `level`, as runs of labels: mesh `i` is
/// label `i + 1`; where meshes overlap, the later mesh wins. Each run of a column comes from the
/// meshes' own runs (one voxelization per mesh, no dense grid), so the runs hold, voxel for voxel, what
/// voxelizing each mesh alone and painting them in order would give;
/// [`KTree::from_value_runs`](crate::KTree::from_value_runs) stacks them into the minimal tree.
///
/// ```
/// use ktree::solid::mesh::{label_runs, MeshTransform, TriangleMesh};
/// use ktree::KTree;
/// // Two cubes [0, 4]³ and [2, 6]³ in voxel units: the second wins where they overlap.
/// let cube = |lo: f64, hi: f64| {
///     let v = (0..8).map(|i| [0, 1, 2].map(|a| if i >> a & 1 == 1 { hi } else { lo })).collect();
///     let t = vec![[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
///                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]];
///     TriangleMesh::new(v, t).unwrap()
/// };
/// let meshes = [cube(0.0, 4.0), cube(2.0, 6.0)];
/// let identity = MeshTransform { scale: 1.0, translate: [0.0; 3] };
/// let labels = label_runs::<u8>(&meshes, 3, &identity).unwrap();
/// assert_eq!(labels.open_edges, [0, 0]);
/// assert_eq!(labels.voxels, [64 - 8, 64]);
/// let tree = KTree::from_value_runs(&labels.runs);
/// assert_eq!((tree.value_at([0, 0, 0]), tree.value_at([3, 3, 3]), tree.value_at([5, 5, 5])), (Some(1), Some(2), Some(2)));
/// assert_eq!(tree.value_at([7, 7, 7]), None);
/// assert_eq!(tree.voxel_count(), 64 + 64 - 8);
/// ```
///
/// # Errors
/// As [`TriangleMesh::to_rays`] for each mesh; [`SolidError::BadParameter`] for no mesh, or more meshes
/// than `V` has labels (255 for `u8`, 65535 for `u16`).
///
/// # Performance
/// One voxelization per mesh, then a sort of all the runs by column and a sweep of each column: about
/// `O(triangles + runs · log runs)`.
pub fn label_runs<V: Value + TryFrom<u32>>(
    meshes: &[TriangleMesh],
    level: u32,
    placement: &MeshTransform,
) -> Result<LabelRuns<V>, SolidError> {
    if meshes.is_empty() {
        return Err(SolidError::BadParameter("no mesh to label".into()));
    }
    let labels = (1..=meshes.len() as u64)
        .map(|l| {
            u32::try_from(l)
                .ok()
                .and_then(|l| V::try_from(l).ok())
                .ok_or_else(|| {
                    SolidError::BadParameter(format!(
                        "{} meshes: label {l} does not fit {}",
                        meshes.len(),
                        V::DTYPE.map_or("the value type", Dtype::name)
                    ))
                })
        })
        .collect::<Result<Vec<V>, _>>()?;
    let universe = Universe::<3>::new(level)?;
    // Every mesh's runs, as (column, z1, z2, mesh).
    let mut all: Vec<(u64, u32, u32, u32)> = Vec::new();
    let mut open_edges = Vec::with_capacity(meshes.len());
    for (i, mesh) in meshes.iter().enumerate() {
        let r = mesh.to_rays(level, placement)?;
        open_edges.push(r.open_edges);
        all.extend(
            r.rays
                .column_keys()
                .iter()
                .zip(r.rays.runs())
                .map(|(&key, &(z1, z2))| (key, z1, z2, i as u32)),
        );
    }
    all.sort_unstable_by_key(|r| (r.0, r.1));
    let mut runs = Vec::with_capacity(all.len());
    let mut sweep = Sweep::default();
    for column in all.chunk_by(|a, b| a.0 == b.0) {
        match column {
            [(key, z1, z2, mesh)] => runs.push(MeshRun {
                column: *key,
                z1: *z1,
                z2: *z2,
                mesh: *mesh,
            }),
            _ => sweep.column(column, &mut runs),
        }
    }
    let mut voxels = vec![0u64; meshes.len()];
    for r in &runs {
        voxels[r.mesh as usize] += u64::from(r.z2 - r.z1);
    }
    let runs = runs
        .into_iter()
        .map(|r| ValueRun {
            column: r.column,
            z1: r.z1,
            z2: r.z2,
            value: labels[r.mesh as usize],
        })
        .collect();
    Ok(LabelRuns {
        runs: ValueRuns::from_sorted_runs(universe, runs),
        open_edges,
        voxels,
    })
}

/// A run of the merged labels: its column's key, `[z1, z2)` and the mesh whose label it holds.
#[derive(Debug, Clone, Copy)]
struct MeshRun {
    column: u64,
    z1: u32,
    z2: u32,
    mesh: u32,
}

/// The buffers of the sweep along one column, kept from column to column.
#[derive(Debug, Default)]
struct Sweep {
    /// Where a run starts or ends: (z, 0 for an end or 1 for a start, mesh).
    events: Vec<(u32, u8, u32)>,
    /// The meshes whose runs hold the current z (each once: a mesh's runs in a column are disjoint).
    inside: Vec<u32>,
}

impl Sweep {
    /// Appends the labelled runs of one column (`column`: its meshes' runs, all of one key) to `out`:
    /// between two consecutive ends of runs, the label of the last mesh inside.
    fn column(&mut self, column: &[(u64, u32, u32, u32)], out: &mut Vec<MeshRun>) {
        let key = column[0].0;
        self.events.clear();
        self.inside.clear();
        for &(_, z1, z2, mesh) in column {
            self.events.push((z1, 1, mesh));
            self.events.push((z2, 0, mesh));
        }
        // Ends before starts at one z, so a mesh that ends where another starts hands over there.
        self.events.sort_unstable();
        // The open run: where it started and its mesh.
        let mut open: Option<(u32, u32)> = None;
        for at in self.events.chunk_by(|a, b| a.0 == b.0) {
            for &(_, start, mesh) in at {
                if start == 1 {
                    self.inside.push(mesh);
                } else if let Some(p) = self.inside.iter().position(|&m| m == mesh) {
                    self.inside.swap_remove(p);
                }
            }
            let z = at[0].0;
            let top = self.inside.iter().copied().max();
            if open.map(|(_, m)| m) == top {
                continue;
            }
            if let Some((z1, mesh)) = open {
                out.push(MeshRun {
                    column: key,
                    z1,
                    z2: z,
                    mesh,
                });
            }
            open = top.map(|m| (z, m));
        }
        debug_assert!(open.is_none(), "every run of a column ends");
    }
}
