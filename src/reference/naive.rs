//! Reference builder: naive voxel-by-voxel insertion into a child-pointer tree, merging `2^K` full siblings
//! into their parent on the way back up. The dumbest correct way to build a k-tree; tests compare every
//! fast builder with it. Cost: `O(voxels · L)`.
//!
//! A node's `2^K` children are a by-value array; `[T; 1 << K]` is not expressible on stable Rust with a
//! const generic `K`, so the array length is a typenum type chosen per `K` by [`Fanout`], and the array is
//! a `generic_array::GenericArray`.

use generic_array::{sequence::GenericSequence, ArrayLength, GenericArray};

use crate::rays::RaySet;
use crate::space::{SpaceError, Universe};
use crate::tree::{KTree, NodeState, TreeAssembler};

/// Marker type for the dimension `K`, to pick the typenum length of a child array.
#[derive(Debug)]
pub struct Dim<const K: usize>;

/// Maps a dimension to the typenum length `2^K`.
pub trait Fanout {
    /// `2^K` as a typenum unsigned integer.
    type Len: ArrayLength;
}

impl Fanout for Dim<1> {
    type Len = typenum::U2;
}
impl Fanout for Dim<2> {
    type Len = typenum::U4;
}
impl Fanout for Dim<3> {
    type Len = typenum::U8;
}
impl Fanout for Dim<4> {
    type Len = typenum::U16;
}

/// A node of the pointer tree.
enum Node<const K: usize>
where
    Dim<K>: Fanout,
{
    Empty,
    Full,
    Partial(Box<GenericArray<Node<K>, <Dim<K> as Fanout>::Len>>),
}

/// A child-pointer k-tree built one voxel at a time.
///
/// ```
/// use ktree::reference::NaiveTree;
/// let mut t = NaiveTree::<2>::new(1).unwrap();
/// for p in [[0, 0], [1, 0], [0, 1], [1, 1]] { t.insert(p); }
/// assert_eq!(t.to_tree(), ktree::KTree::<2>::full(1).unwrap()); // four full voxels merged
/// ```
pub struct NaiveTree<const K: usize>
where
    Dim<K>: Fanout,
{
    universe: Universe<K>,
    root: Node<K>,
}

impl<const K: usize> NaiveTree<K>
where
    Dim<K>: Fanout,
{
    /// An empty tree.
    ///
    /// # Errors
    /// [`SpaceError::LevelTooLarge`] for a level beyond [`crate::max_level`].
    pub fn new(level: u32) -> Result<Self, SpaceError> {
        Ok(Self {
            universe: Universe::new(level)?,
            root: Node::Empty,
        })
    }

    /// The tree of a ray set, inserting every voxel of every run.
    ///
    /// # Errors
    /// As [`NaiveTree::new`].
    pub fn from_rays(rays: &RaySet<K>) -> Result<Self, SpaceError> {
        let mut t = Self::new(rays.level())?;
        for ray in rays.iter() {
            let mut p = ray.start;
            for z in ray.z1()..ray.z2 {
                p[K - 1] = z;
                t.insert(p);
            }
        }
        Ok(t)
    }

    /// Marks the voxel `point` full (points outside the universe are ignored).
    pub fn insert(&mut self, point: [u32; K]) {
        if self.universe.check_point(point).is_ok() {
            insert(&mut self.root, point, self.universe.level());
        }
    }

    /// The equivalent compact tree, by a depth-first walk.
    pub fn to_tree(&self) -> KTree<K> {
        let mut out = TreeAssembler::<K>::new(self.universe.level()).expect("level checked");
        walk(&self.root, 0, &mut out);
        out.finish()
    }
}

/// Inserts `point` below `node`, whose cell has side `2^bits`; merges full children on the way up.
fn insert<const K: usize>(node: &mut Node<K>, point: [u32; K], bits: u32)
where
    Dim<K>: Fanout,
{
    if bits == 0 {
        *node = Node::Full;
        return;
    }
    if let Node::Full = node {
        return;
    }
    if let Node::Empty = node {
        *node = Node::Partial(Box::new(GenericArray::generate(|_| Node::Empty)));
    }
    let Node::Partial(children) = node else {
        unreachable!("made partial above")
    };
    let mut code = 0usize;
    for (axis, &c) in point.iter().enumerate() {
        code |= ((c >> (bits - 1) & 1) as usize) << axis;
    }
    insert(&mut children[code], point, bits - 1);
    if children.iter().all(|c| matches!(c, Node::Full)) {
        *node = Node::Full;
    }
}

fn walk<const K: usize>(node: &Node<K>, depth: usize, out: &mut TreeAssembler<K>)
where
    Dim<K>: Fanout,
{
    match node {
        Node::Empty => out.push(depth, NodeState::Empty),
        Node::Full => out.push(depth, NodeState::Full),
        Node::Partial(children) => {
            out.push(depth, NodeState::Partial);
            for c in children.iter() {
                walk(c, depth + 1, out);
            }
        }
    }
}
