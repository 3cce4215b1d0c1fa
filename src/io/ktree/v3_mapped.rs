//! A valued `.ktree` file (version 3) read in place: a [`ValueStorage`] over the file's memory map, so
//! values at points ([`crate::query::values_at`]), walks and every operation over a `ValueStorage` run on
//! a file larger than memory. A node's children and value are found from the file's rank samples (at most
//! 64 word pop-counts each).
//!
//! ```
//! use ktree::io::ktree::v3::{write_valued_ktree_file, MappedValuedTree};
//! use ktree::query::values_at;
//! use ktree::KTree;
//! let tree = KTree::<2, u16>::from_dense_values(1, &[Some(7), None, Some(9), Some(7)]).unwrap();
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("labels.ktree");
//! write_valued_ktree_file(&path, &tree).unwrap();
//! let mapped = MappedValuedTree::<2, u16>::open(&path).unwrap();
//! assert_eq!(values_at(&mapped, &[[0, 0], [1, 0], [0, 1]]).unwrap(), [Some(7), None, Some(9)]);
//! ```

use std::marker::PhantomData;
use std::path::Path;
use std::sync::Arc;

use super::notes::Notes;
use super::v3::{check_valued, Checked, ValuedLevel};
use crate::io::mmap::FileMap;
use crate::io::{KtreeFileError, KtreeFileErrorKind};
use crate::space::{Universe, WorldFrame};
use crate::tree::storage::TreeStorage;
use crate::tree::valued::{mixed_as_partial, ValueStorage};
use crate::tree::words::{children_mask, full_mask, NODES_PER_WORD};
use crate::tree::{LevelCounts, NodeState};
use crate::value::Value;

/// Words between two rank samples.
const WORDS_PER_SAMPLE: usize = 64;

/// A `K`-dimensional tree of `V` values read in place from a version 3 `.ktree` file: checked when
/// opened (checksums, directory, rank samples, values), each read bounds-checked, so a file changed
/// while mapped gives an error naming it and a byte offset, never a read past the map or a panic.
/// Clones share the map.
#[derive(Debug, Clone)]
pub struct MappedValuedTree<const K: usize, V> {
    map: Arc<FileMap>,
    file: Arc<str>,
    universe: Universe<K>,
    levels: Arc<[ValuedLevel]>,
    value_bytes: usize,
    frame: Option<WorldFrame>,
    notes: Arc<Notes>,
    values: PhantomData<V>,
}

impl<const K: usize, V: Value> MappedValuedTree<K, V> {
    /// Opens, checks and maps the version 3 file `path` holding a tree of `K` dimensions and `V`
    /// values.
    ///
    /// # Errors
    /// As [`read_valued_ktree`](super::v3::read_valued_ktree) (except the tree's minimality, which a
    /// walk does not need); a file without values is [`KtreeFileErrorKind::Dtype`].
    pub fn open(path: &Path) -> Result<Self, KtreeFileError> {
        let name = path.display().to_string();
        let io = |e: std::io::Error| {
            KtreeFileError::at_byte(name.clone(), 0, KtreeFileErrorKind::Io(e.into()))
        };
        let file = std::fs::File::open(path).map_err(io)?;
        let len = file.metadata().map_err(io)?.len();
        let len = usize::try_from(len).map_err(|_| {
            KtreeFileError::at_byte(
                name.clone(),
                0,
                KtreeFileErrorKind::Header(
                    "the file is larger than this machine's addresses".into(),
                ),
            )
        })?;
        let map = FileMap::map(&file, 0, len).map_err(io)?;
        let Some(dtype) = V::DTYPE else {
            return Err(KtreeFileError::at_byte(
                name,
                10,
                KtreeFileErrorKind::Dtype {
                    expected: None,
                    found: None,
                },
            ));
        };
        match check_valued::<K, V>(map.bytes(), &name, false)? {
            Checked::Valued {
                universe,
                levels,
                frame,
                notes,
                ..
            } => Ok(Self {
                map: Arc::new(map),
                file: name.into(),
                universe,
                levels: levels.into(),
                value_bytes: dtype.bytes(),
                frame,
                notes: Arc::new(notes),
                values: PhantomData,
            }),
            Checked::Binary(_) => {
                unreachable!("V has a dtype: a binary file fails the dtype check")
            }
        }
    }

    /// The world frame the file keeps, if any.
    pub fn frame(&self) -> Option<WorldFrame> {
        self.frame
    }

    /// The notes the file keeps ([`Notes`]; none for most files).
    pub fn notes(&self) -> &Notes {
        &self.notes
    }

    /// The file read as a tree without values of the same nodes (a mixed node read as a node with
    /// children): every query of a [`TreeStorage`] — distances, nearest voxels, ray casts — runs on the
    /// file in place, each full leaf a leaf where one value holds ([`MappedLeaves`]).
    pub fn leaves(&self) -> MappedLeaves<'_, K, V> {
        MappedLeaves(self)
    }

    /// The error of a read the checked shape does not allow: the file changed after it was opened.
    fn changed(&self, depth: usize, what: &str) -> KtreeFileError {
        let offset = self.levels.get(depth).map_or(0, |l| l.offset) as u64;
        KtreeFileError::at_byte(
            self.file.to_string(),
            offset,
            KtreeFileErrorKind::Tree(format!(
                "level {depth}: {what}: the file was changed after it was opened"
            )),
        )
    }

    fn u64_at(&self, at: usize, depth: usize) -> Result<u64, KtreeFileError> {
        self.map
            .bytes()
            .get(at..at + 8)
            .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
            .ok_or_else(|| self.changed(depth, "a read past the file's end"))
    }

    /// The rank of node `index` among the nodes of level `depth` that `mask` picks, from the samples of
    /// kind `kind` (0: nodes with children, 1: full nodes).
    fn rank(
        &self,
        depth: usize,
        index: usize,
        kind: usize,
        mask: fn(u64) -> u64,
    ) -> Result<u64, KtreeFileError> {
        let level = &self.levels[depth];
        let word = index / NODES_PER_WORD;
        let sample = word / WORDS_PER_SAMPLE;
        let samples_at = level.offset + 8 * (level.words + kind * level.samples);
        let mut rank = self.u64_at(samples_at + 8 * sample, depth)?;
        for w in sample * WORDS_PER_SAMPLE..word {
            rank += u64::from(mask(self.u64_at(level.offset + 8 * w, depth)?).count_ones());
        }
        let below = (1u64 << (2 * (index % NODES_PER_WORD))) - 1;
        let last = self.u64_at(level.offset + 8 * word, depth)? & below;
        Ok(rank + u64::from(mask(last).count_ones()))
    }
}

impl<const K: usize, V: Value> ValueStorage<K> for MappedValuedTree<K, V> {
    type Value = V;
    type Error = KtreeFileError;

    fn universe(&self) -> Universe<K> {
        self.universe
    }

    fn depth_count(&self) -> usize {
        self.levels.len()
    }

    fn root_code(&self) -> Result<u32, KtreeFileError> {
        Ok((self.u64_at(self.levels[0].offset, 0)? & 3) as u32)
    }

    fn codes(&self, depth: usize, first: usize) -> Result<u32, KtreeFileError> {
        let level = self
            .levels
            .get(depth)
            .ok_or_else(|| self.changed(depth, "a level below the last"))?;
        if (first + (1 << K)) as u64 > level.nodes {
            return Err(self.changed(depth, &format!("nodes from {first} are not in the level")));
        }
        // A block of 2^K ≤ 16 siblings starts at a multiple of 2^K: it lies in one word.
        let word = self.u64_at(level.offset + 8 * (first / NODES_PER_WORD), depth)?;
        let codes = word >> (2 * (first % NODES_PER_WORD));
        Ok((codes & ((1u64 << (2 << K)) - 1)) as u32)
    }

    fn children(&self, depth: usize, index: usize) -> Result<usize, KtreeFileError> {
        let rank = self.rank(depth, index, 0, children_mask)?;
        let first = usize::try_from(rank << K).unwrap_or(usize::MAX);
        let below = self.levels.get(depth + 1).map_or(0, |l| l.nodes);
        if rank >= self.levels[depth].children || (first + (1 << K)) as u64 > below {
            return Err(self.changed(
                depth,
                &format!("node {index}'s children are not in the file"),
            ));
        }
        Ok(first)
    }

    fn value(&self, depth: usize, index: usize) -> Result<V, KtreeFileError> {
        let rank = self.rank(depth, index, 1, full_mask)?;
        let level = &self.levels[depth];
        if rank >= level.full {
            return Err(self.changed(depth, &format!("node {index}'s value is not in the file")));
        }
        let at =
            level.offset + 8 * (level.words + 2 * level.samples) + rank as usize * self.value_bytes;
        let bytes = self
            .map
            .bytes()
            .get(at..at + self.value_bytes)
            .ok_or_else(|| self.changed(depth, "a value past the file's end"))?;
        let value = V::read_le(bytes);
        value
            .check()
            .map_err(|e| self.changed(depth, &format!("a value no voxel may hold ({e})")))?;
        Ok(value)
    }
}

/// A [`MappedValuedTree`] read as a tree without values of the same nodes — a mixed node (`11`) reads as a
/// node with children (`10`), as [`LeavesOfValues`](crate::tree::valued::LeavesOfValues) reads a tree in
/// memory — so its voxels with values are the full voxels of a [`TreeStorage`] (not reduced where a mixed
/// node stands), read in place.
///
/// ```
/// use ktree::io::ktree::v3::{write_valued_ktree_file, MappedValuedTree};
/// use ktree::query::Query;
/// use ktree::KTree;
/// let tree = KTree::<2, u16>::from_dense_values(1, &[Some(7), None, Some(9), Some(7)]).unwrap();
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("labels.ktree");
/// write_valued_ktree_file(&path, &tree).unwrap();
/// let mapped = MappedValuedTree::<2, u16>::open(&path).unwrap();
/// assert_eq!(mapped.leaves().contains_many(&[[0, 0], [1, 0]]).unwrap(), [true, false]);
/// ```
#[derive(Debug, Clone, Copy)]
pub struct MappedLeaves<'a, const K: usize, V>(&'a MappedValuedTree<K, V>);

impl<const K: usize, V: Value> MappedLeaves<'_, K, V> {
    fn level(&self, depth: usize, index: usize) -> Result<&ValuedLevel, KtreeFileError> {
        self.0
            .levels
            .get(depth)
            .filter(|l| index as u64 <= l.nodes)
            .ok_or_else(|| {
                self.0
                    .changed(depth, &format!("node {index} is not in the level"))
            })
    }
}

impl<const K: usize, V: Value> TreeStorage<K> for MappedLeaves<'_, K, V> {
    type Error = KtreeFileError;

    fn universe(&self) -> Universe<K> {
        self.0.universe
    }

    fn depth_count(&self) -> usize {
        self.0.levels.len()
    }

    fn level_len(&self, depth: usize) -> usize {
        self.0.levels.get(depth).map_or(0, |l| l.nodes as usize)
    }

    fn counts_per_level(&self) -> Vec<LevelCounts> {
        (self.0.levels.iter().enumerate())
            .map(|(d, l)| LevelCounts {
                level: d as u32,
                full: l.full,
                partial: l.children,
                empty: l.nodes - l.full - l.children,
            })
            .collect()
    }

    fn root_state(&self) -> Result<NodeState, KtreeFileError> {
        Ok(NodeState::from_bits(mixed_as_partial(self.0.root_code()?)))
    }

    fn partial_rank(&self, depth: usize, index: usize) -> Result<usize, KtreeFileError> {
        let nodes = self.level(depth, index)?.nodes;
        if index as u64 == nodes {
            // The rank of the level's end: that of its last node plus the last node's own.
            let Some(last) = index.checked_sub(1) else {
                return Ok(0);
            };
            let code = if depth == 0 {
                self.0.root_code()?
            } else {
                let sibling = last % (1 << K);
                self.0.codes(depth, last - sibling)? >> (2 * sibling) & 3
            };
            let own = u64::from(code >= 2);
            return Ok((self.0.rank(depth, last, 0, children_mask)? + own) as usize);
        }
        Ok(self.0.rank(depth, index, 0, children_mask)? as usize)
    }

    fn first_child(&self, depth: usize, index: usize) -> Result<usize, KtreeFileError> {
        self.0.children(depth, index)
    }

    fn block_codes(&self, depth: usize, first: usize) -> Result<u32, KtreeFileError> {
        Ok(mixed_as_partial(self.0.codes(depth, first)?))
    }
}
