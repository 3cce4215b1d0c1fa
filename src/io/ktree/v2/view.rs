//! [`KtreeView`]: a checked version 2 file read in place through a memory map.

use std::fs::File;
use std::path::Path;
use std::sync::Arc;

use super::super::notes::Notes;
use super::super::{KtreeFileError, KtreeFileErrorKind};
use super::check::check_bytes;
use super::layout::*;
use super::mapped::MappedTree;
use crate::io::mmap::FileMap;
use crate::space::{Cell, Universe, WorldFrame};
use crate::tree::{KTree, LevelCounts, NodeState, PackedStates};

/// Where a view's bytes are (shared by the view's clones).
#[derive(Debug, Clone)]
enum Backing {
    /// A file, mapped whole.
    Map(Arc<FileMap>),
    /// Bytes in memory.
    Bytes(Arc<[u8]>),
}

/// A read-only view of a `.ktree` version 2 file through a memory map: statistics, point queries and leaf
/// iteration without loading the levels into memory.
///
/// Opening checks the whole file (the checks listed with the layout in the README) by scanning it through
/// windows of 1 MiB that are unmapped after use, holding besides only one level's rank samples (1/256 of
/// the level); queries then read only the pages they touch.
///
/// ```
/// use ktree::{io, KTree};
/// let tree = KTree::<2>::from_dense(1, &[true, false, false, true]).unwrap();
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("t.ktree");
/// io::write_ktree_file(&path, &tree).unwrap();
/// let view = io::KtreeView::open(&path).unwrap();
/// assert_eq!(view.counts(), tree.counts());
/// assert!(view.contains([0u32, 0]).unwrap() && !view.contains([1u32, 0]).unwrap());
/// ```
#[derive(Debug, Clone)]
pub struct KtreeView {
    name: String,
    backing: Backing,
    pub(super) layout: Layout,
}

impl KtreeView {
    /// Opens and checks a version 2 file.
    ///
    /// # Errors
    /// [`KtreeFileError`] naming the file and byte offset of the first problem
    /// ([`KtreeFileErrorKind::Version`] for a version 1 file: read those with
    /// [`read_ktree_file`](crate::io::read_ktree_file)).
    pub fn open(path: &Path) -> Result<Self, KtreeFileError> {
        let name = path.display().to_string();
        let io_error = |offset: u64, e: std::io::Error| {
            KtreeFileError::at_byte(name.clone(), offset, KtreeFileErrorKind::Io(e.into()))
        };
        let file = File::open(path).map_err(|e| io_error(0, e))?;
        let len = file.metadata().map_err(|e| io_error(0, e))?.len();
        let len_usize = usize::try_from(len).map_err(|_| {
            io_error(
                0,
                std::io::Error::other("the file is larger than the address space"),
            )
        })?;
        let layout = Layout::parse(&name, len, |offset, n| {
            read_at(&file, offset, n).map_err(|e| io_error(offset, e))
        })?;
        layout.check_sections(&name, |offset, n, f| {
            let window = FileMap::map(&file, offset, n).map_err(|e| io_error(offset, e))?;
            f(window.bytes())
        })?;
        let map = FileMap::map(&file, 0, len_usize).map_err(|e| io_error(0, e))?;
        Ok(Self {
            name,
            backing: Backing::Map(Arc::new(map)),
            layout,
        })
    }

    /// A view of a version 2 file's bytes held in memory (`name` is used in errors).
    ///
    /// # Errors
    /// As [`KtreeView::open`].
    pub fn from_bytes(bytes: Vec<u8>, name: &str) -> Result<Self, KtreeFileError> {
        let layout = layout_of_bytes(&bytes, name)?;
        check_bytes(&layout, &bytes, name)?;
        Ok(Self {
            name: name.to_string(),
            backing: Backing::Bytes(bytes.into()),
            layout,
        })
    }

    fn bytes(&self) -> &[u8] {
        match &self.backing {
            Backing::Map(map) => map.bytes(),
            Backing::Bytes(b) => b,
        }
    }

    /// Whether the view reads through a memory map (rather than bytes in memory).
    pub fn is_mapped(&self) -> bool {
        matches!(self.backing, Backing::Map(_))
    }

    /// The dimension `K`.
    pub fn k(&self) -> usize {
        self.layout.k
    }

    /// The universe level `L`.
    pub fn level(&self) -> u32 {
        self.layout.level
    }

    /// Where the voxels are in the world, if the file says ([`write_ktree_framed`](crate::io::write_ktree_framed)).
    pub fn frame(&self) -> Option<WorldFrame> {
        self.layout.frame
    }

    /// The file's notes (none if it keeps none).
    pub fn notes(&self) -> &Notes {
        &self.layout.notes
    }

    /// The number of stored levels.
    pub fn depth_count(&self) -> usize {
        self.layout.sections.len()
    }

    /// Node counts per level, from the root down (read from the checked directory).
    pub fn counts_per_level(&self) -> Vec<LevelCounts> {
        self.layout.counts_per_level()
    }

    /// Total node counts (`level` holds the universe level), as [`KTree::counts`].
    pub fn counts(&self) -> LevelCounts {
        LevelCounts::total(self.level(), &self.counts_per_level())
    }

    /// The number of voxels inside the object, from the directory's full-node counts (no walk), as
    /// [`KTree::voxel_count`].
    pub fn voxel_count(&self) -> u128 {
        crate::tree::voxels_of_levels(self.k(), self.level(), &self.counts_per_level())
    }

    /// The total number of nodes.
    pub fn node_count(&self) -> u64 {
        self.layout.sections.iter().map(|s| s.nodes).sum()
    }

    /// Bytes needed at Meagher's 2 bits a node.
    pub fn bytes_at_two_bits(&self) -> u64 {
        self.node_count().div_ceil(4)
    }

    fn word(&self, section: &Section, j: u64) -> u64 {
        u64_at(self.bytes(), (section.offset + 8 * j) as usize)
    }

    /// The state of node `index` at `depth`, or `None` if there is no such node.
    pub fn state(&self, depth: usize, index: u64) -> Option<NodeState> {
        let s = self.layout.sections.get(depth)?;
        if index >= s.nodes {
            return None;
        }
        let code = self.word(s, index / NODES_PER_WORD) >> (2 * (index % NODES_PER_WORD)) & 3;
        NodeState::from_code(code as u8)
    }

    /// Word `j` of the node states of level `depth`, or the error of a file changed since opening when
    /// the level has no such word (every read stays inside the sections checked at opening).
    pub(crate) fn level_word(&self, depth: usize, j: u64) -> Result<u64, KtreeFileError> {
        match self.layout.sections.get(depth) {
            Some(s) if j < s.words() => Ok(self.word(s, j)),
            _ => Err(self.changed(depth, j.saturating_mul(NODES_PER_WORD))),
        }
    }

    /// The number of nodes of level `depth` (0 below the last level).
    pub(crate) fn level_nodes(&self, depth: usize) -> u64 {
        self.layout.sections.get(depth).map_or(0, |s| s.nodes)
    }

    /// The name given when the view was opened (the file's path).
    pub(crate) fn name(&self) -> &str {
        &self.name
    }

    /// The error for a node that is not what the checks at opening found: the file was changed since.
    pub(crate) fn changed(&self, depth: usize, index: u64) -> KtreeFileError {
        // The offset named is that of the last word read inside the level, so it lies within the file.
        let section = &self.layout.sections[depth.min(self.layout.sections.len() - 1)];
        let inside = index.min(section.nodes.saturating_sub(1));
        KtreeFileError::at_byte(self.name.clone(), section.offset + 8 * (inside / NODES_PER_WORD), KtreeFileErrorKind::Tree(format!(
                "node {index} of level {depth} is missing or has the code 11: the file was changed after it was opened"
            )))
    }

    /// The state of a node the tree's shape says exists, or the error of a file changed since opening.
    pub(crate) fn checked_state(
        &self,
        depth: usize,
        index: u64,
    ) -> Result<NodeState, KtreeFileError> {
        self.state(depth, index)
            .ok_or_else(|| self.changed(depth, index))
    }

    /// The number of partial nodes before node `index` of level `depth` (`index` < the level's size).
    ///
    /// # Errors
    /// The error of a file changed since opening if the level has no node `index`.
    pub(crate) fn partial_rank(&self, depth: usize, index: u64) -> Result<u64, KtreeFileError> {
        let s = match self.layout.sections.get(depth) {
            Some(s) if index < s.nodes => s,
            _ => return Err(self.changed(depth, index)),
        };
        let word = index / NODES_PER_WORD;
        let block = word / WORDS_PER_SAMPLE;
        let mut rank = u64_at(self.bytes(), (s.samples_offset() + 8 * block) as usize);
        for j in block * WORDS_PER_SAMPLE..word {
            rank = rank.saturating_add(u64::from(partial_mask(self.word(s, j)).count_ones()));
        }
        let slot = index % NODES_PER_WORD;
        Ok(rank.saturating_add(u64::from(
            (partial_mask(self.word(s, word)) & slots_mask(slot)).count_ones(),
        )))
    }

    /// The universe, if the file's `K` is `K`.
    pub(crate) fn universe<const K: usize>(&self) -> Result<Universe<K>, KtreeFileError> {
        self.dimension::<K>()
    }

    fn dimension<const K: usize>(&self) -> Result<Universe<K>, KtreeFileError> {
        if K != self.k() {
            return Err(KtreeFileError::at_byte(
                self.name.clone(),
                8,
                KtreeFileErrorKind::Dimension {
                    expected: K,
                    found: self.k(),
                },
            ));
        }
        Ok(Universe::new(self.level()).expect("level checked when opened"))
    }

    /// Whether the voxel `point` is inside the object (`O(L)` node reads, each rank at most 64 word
    /// pop-counts). Points outside the universe are outside the object.
    ///
    /// # Errors
    /// [`KtreeFileErrorKind::Dimension`] if the file's `K` is not `K`; the failed read's error if the file
    /// was changed after it was opened.
    pub fn contains<const K: usize>(&self, point: [u32; K]) -> Result<bool, KtreeFileError> {
        crate::query::contains(&MappedTree::<K>::new(self)?, point)
    }

    /// Visits every leaf (empty and full) in Morton (depth-first) order, as [`KTree::for_each_leaf`],
    /// through the one walk over any storage ([`TryLeaves`](crate::tree::cursor::TryLeaves) over the map).
    ///
    /// # Errors
    /// [`KtreeFileErrorKind::Dimension`] if the file's `K` is not `K`; the first failed read's error if the
    /// file was changed after it was opened (the leaves visited until then are as read).
    pub fn for_each_leaf<const K: usize>(
        &self,
        mut visit: impl FnMut(Cell<K>, NodeState),
    ) -> Result<(), KtreeFileError> {
        let tree = MappedTree::<K>::new(self)?;
        for leaf in crate::tree::cursor::TryLeaves::new(&tree) {
            let (cell, state) = leaf?;
            visit(cell, state);
        }
        Ok(())
    }

    /// Visits the full leaves in Morton order: the object's linear tree.
    ///
    /// # Errors
    /// [`KtreeFileErrorKind::Dimension`] if the file's `K` is not `K`.
    pub fn for_each_full_cell<const K: usize>(
        &self,
        mut visit: impl FnMut(Cell<K>),
    ) -> Result<(), KtreeFileError> {
        self.for_each_leaf::<K>(|cell, state| {
            if state == NodeState::Full {
                visit(cell)
            }
        })
    }

    /// Loads the tree, of the dimension the file names, into memory.
    ///
    /// # Errors
    /// A read error if the file was changed after it was opened.
    pub fn to_any_tree(&self) -> Result<crate::AnyTree, KtreeFileError> {
        Ok(match self.k() {
            1 => self.to_tree::<1>()?.into(),
            2 => self.to_tree::<2>()?.into(),
            3 => self.to_tree::<3>()?.into(),
            _ => self.to_tree::<4>()?.into(),
        })
    }

    /// Loads the tree into memory.
    ///
    /// # Errors
    /// [`KtreeFileErrorKind::Dimension`] if the file's `K` is not `K`.
    pub fn to_tree<const K: usize>(&self) -> Result<KTree<K>, KtreeFileError> {
        let universe = self.dimension::<K>()?;
        let levels = self
            .layout
            .sections
            .iter()
            .enumerate()
            .map(|(depth, s)| {
                let words = (0..s.words()).map(|j| self.word(s, j)).collect();
                PackedStates::from_words(words, s.nodes as usize)
                    .map_err(|_| self.changed(depth, 0))
            })
            .collect::<Result<_, _>>()?;
        let tree = KTree::from_levels(universe, levels);
        tree.check().map_err(|e| {
            KtreeFileError::at_byte(
                self.name.clone(),
                HEADER_BYTES as u64,
                KtreeFileErrorKind::Tree(e.to_string()),
            )
        })?;
        Ok(tree)
    }
}

/// Reads `n` bytes of `file` at `offset`.
pub(crate) fn read_at(file: &File, offset: u64, n: usize) -> std::io::Result<Vec<u8>> {
    use std::io::{Read, Seek, SeekFrom};
    let mut f = file;
    f.seek(SeekFrom::Start(offset))?;
    let mut buf = vec![0u8; n];
    f.read_exact(&mut buf)?;
    Ok(buf)
}
