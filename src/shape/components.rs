//! Connected components, found on the runs by union–find (never on a dense label array).
//!
//! Connectivity `c` is scipy's `generate_binary_structure(K, c)`: two voxels are neighbours when they
//! differ by at most 1 on every axis and on at most `c` axes. Two runs of neighbouring columns (which differ
//! on `m` column axes) touch when `m ≤ c` and their `z` ranges overlap (`m = c`) or overlap or touch
//! (`m < c`, a diagonal step in `z` allowed). Only the `3^(K−1)` neighbouring columns of each column
//! are looked at.
use super::error::check_connectivity;
use super::input::{copied, runs};
use super::ShapeError;
use crate::rays::RaySet;
use crate::tree::storage::TreeStorage;
use crate::KTree;

/// One connected component: its voxel count and its voxels as a tree of the same universe.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Component<const K: usize> {
    /// The number of voxels.
    pub size: u128,
    /// The component's voxels.
    pub tree: KTree<K>,
}

/// One component's column keys, runs and voxel count, gathered in order.
type Part = (Vec<u64>, Vec<(u32, u32)>, u128);

fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// The component label (a run index, the root) of every run.
fn label_runs<const K: usize>(rays: &RaySet<K>, connectivity: usize) -> Vec<usize> {
    let keys = rays.column_keys();
    let runs = rays.runs();
    let mut parent: Vec<usize> = (0..runs.len()).collect();
    // The column offsets δ ∈ {−1, 0, 1}^(K−1), δ > 0 lexicographically (each pair of columns once).
    let mut deltas: Vec<([i64; K], usize)> = Vec::new();
    let mut d = [-1i64; K];
    d[K - 1] = 0;
    if K > 1 {
        loop {
            let first = d[..K - 1].iter().find(|&&x| x != 0);
            let m = d[..K - 1].iter().filter(|&&x| x != 0).count();
            if first == Some(&1) && m <= connectivity {
                deltas.push((d, m));
            }
            let mut axis = 0;
            while axis + 1 < K {
                d[axis] += 1;
                if d[axis] <= 1 {
                    break;
                }
                d[axis] = -1;
                axis += 1;
            }
            if axis + 1 >= K {
                break;
            }
        }
    }
    let union = |parent: &mut Vec<usize>, a: usize, b: usize| {
        let (ra, rb) = (find(parent, a), find(parent, b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            parent[hi] = lo;
        }
    };
    // Where each offset's neighbour columns start: the neighbours of columns in order are in order too
    // (a fixed offset within the universe keeps the keys' order), so each cursor only moves forward.
    let mut starts = vec![0usize; deltas.len()];
    let columns = rays.keys();
    for (key, range) in rays.column_groups() {
        for (&(delta, m), start) in deltas.iter().zip(starts.iter_mut()) {
            let Some(okey) = columns.moved(key, delta) else {
                continue;
            };
            while *start < keys.len() && keys[*start] < okey {
                *start += 1;
            }
            let lo = *start;
            let mut hi = lo;
            while hi < keys.len() && keys[hi] == okey {
                hi += 1;
            }
            let slack = u32::from(m < connectivity);
            let (mut p, mut q) = (range.start, lo);
            while p < range.end && q < hi {
                let (a, b) = (runs[p], runs[q]);
                if a.0 < b.1 + slack && b.0 < a.1 + slack {
                    union(&mut parent, p, q);
                }
                if a.1 < b.1 {
                    p += 1;
                } else {
                    q += 1;
                }
            }
        }
    }
    (0..runs.len()).map(|i| find(&mut parent, i)).collect()
}

/// The connected components of the full voxels of `tree` (in memory or a file read in place), largest
/// first (ties by the first voxel in column order), each as its own tree: scipy's `label` with
/// `generate_binary_structure(K, connectivity)`.
///
/// ```
/// use ktree::{shape::components, KTree, Ray, RaySet};
/// // Two voxels touching at a corner: apart for connectivity 1, one piece for 2.
/// let rays = RaySet::<2>::from_rays(2, [Ray::new([0, 0], 1), Ray::new([1, 1], 2)]).unwrap();
/// let tree = KTree::from_rays(&rays);
/// assert_eq!(components(&tree, 1).unwrap().len(), 2);
/// assert_eq!(components(&tree, 2).unwrap()[0].size, 2);
/// ```
///
/// # Performance
/// Union–find over the runs ([`rays_of`](crate::tree::rays_of)): `O(runs · 3^(K−1))` and the
/// near-constant factor of the union–find; memory a few words per run.
///
/// # Errors
/// [`ShapeError::Connectivity`] unless `1 ≤ connectivity ≤ K`; [`ShapeError::Storage`] for a read error.
pub fn components<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    connectivity: usize,
) -> Result<Vec<Component<K>>, ShapeError> {
    check_connectivity::<K>(connectivity)?;
    let rays = runs(tree)?;
    let labels = label_runs(&rays, connectivity);
    // Gather each root's runs in order (the runs of a component stay sorted).
    let mut slot = vec![usize::MAX; labels.len()];
    let mut parts: Vec<Part> = Vec::new();
    for (i, &root) in labels.iter().enumerate() {
        if slot[root] == usize::MAX {
            slot[root] = parts.len();
            parts.push(Default::default());
        }
        let part = &mut parts[slot[root]];
        let run = rays.runs()[i];
        part.0.push(rays.column_keys()[i]);
        part.1.push(run);
        part.2 += u128::from(run.1 - run.0);
    }
    if parts.len() == 1 {
        // One piece: the tree itself, copied, not rebuilt.
        return Ok(vec![Component {
            size: parts[0].2,
            tree: copied(tree)?,
        }]);
    }
    // Stable: equal sizes keep the order of their first run.
    parts.sort_by_key(|p| std::cmp::Reverse(p.2));
    Ok(parts
        .into_iter()
        .map(|(columns, runs, size)| Component {
            size,
            tree: KTree::from_rays(&RaySet::from_sorted_parts(
                rays.universe(),
                columns,
                runs,
                None,
            )),
        })
        .collect())
}

/// The voxel counts of the connected components of `tree`, largest first, without building their trees.
///
/// ```
/// use ktree::{shape::component_sizes, KTree, Ray, RaySet};
/// let rays = RaySet::<1>::from_rays(3, [Ray::new([0], 2), Ray::new([4], 7)]).unwrap();
/// assert_eq!(component_sizes(&KTree::from_rays(&rays), 1).unwrap(), vec![3, 2]);
/// ```
///
/// # Errors
/// As [`components`].
pub fn component_sizes<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    connectivity: usize,
) -> Result<Vec<u128>, ShapeError> {
    check_connectivity::<K>(connectivity)?;
    let rays = runs(tree)?;
    let labels = label_runs(&rays, connectivity);
    let mut sizes = vec![0u128; labels.len()];
    for (i, &root) in labels.iter().enumerate() {
        let run = rays.runs()[i];
        sizes[root] += u128::from(run.1 - run.0);
    }
    let mut sizes: Vec<u128> = sizes.into_iter().filter(|&s| s > 0).collect();
    sizes.sort_by_key(|&s| std::cmp::Reverse(s));
    Ok(sizes)
}

/// The largest connected component of `tree` (the first of [`components`]); the empty tree if there is
/// no full voxel.
///
/// # Errors
/// As [`components`].
pub fn largest_component<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    connectivity: usize,
) -> Result<KTree<K>, ShapeError> {
    Ok(match components(tree, connectivity)?.into_iter().next() {
        Some(c) => c.tree,
        None => KTree::empty(tree.level()).expect("the tree's level"),
    })
}

impl<const K: usize> KTree<K> {
    /// The connected components of the full voxels, largest first, each as its own tree
    /// ([`components()`]).
    ///
    /// ```
    /// use ktree::{KTree, Ray, RaySet};
    /// let rays = RaySet::<2>::from_rays(2, [Ray::new([0, 0], 1), Ray::new([1, 1], 2)]).unwrap();
    /// assert_eq!(KTree::from_rays(&rays).components(1).unwrap().len(), 2);
    /// ```
    ///
    /// # Errors
    /// As [`components()`].
    pub fn components(&self, connectivity: usize) -> Result<Vec<Component<K>>, ShapeError> {
        components(self, connectivity)
    }

    /// The voxel counts of the connected components, largest first, without building their trees
    /// ([`component_sizes`]).
    ///
    /// ```
    /// use ktree::{KTree, Ray, RaySet};
    /// let rays = RaySet::<1>::from_rays(3, [Ray::new([0], 2), Ray::new([4], 7)]).unwrap();
    /// assert_eq!(KTree::from_rays(&rays).component_sizes(1).unwrap(), vec![3, 2]);
    /// ```
    ///
    /// # Errors
    /// As [`components()`].
    pub fn component_sizes(&self, connectivity: usize) -> Result<Vec<u128>, ShapeError> {
        component_sizes(self, connectivity)
    }

    /// The largest connected component (the first of [`KTree::components`]); the empty tree if there is
    /// no full voxel.
    ///
    /// ```
    /// use ktree::{KTree, Ray, RaySet};
    /// let rays = RaySet::<1>::from_rays(3, [Ray::new([0], 2), Ray::new([4], 7)]).unwrap();
    /// assert_eq!(KTree::from_rays(&rays).largest_component(1).unwrap().voxel_count(), 3);
    /// ```
    ///
    /// # Errors
    /// As [`components()`].
    pub fn largest_component(&self, connectivity: usize) -> Result<KTree<K>, ShapeError> {
        largest_component(self, connectivity)
    }
}
