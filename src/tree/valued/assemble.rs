//! A valued tree collected from its nodes in depth-first order.

use crate::space::{DimCheck, SpaceError, Universe};
use crate::tree::ktree::KTree;
use crate::value::Value;

use super::{ValueState, ValuedLevel};

/// Collects a valued tree from its nodes in depth-first order (children in code order): each node is
/// appended to its level, each full node's value to its level's column. The caller guarantees a complete
/// traversal of a minimal tree.
#[derive(Debug, Clone)]
pub struct ValueAssembler<const K: usize, V> {
    universe: Universe<K>,
    levels: Vec<ValuedLevel<V>>,
}

impl<const K: usize, V: Value> ValueAssembler<K, V> {
    /// An assembler for a universe of level `level`.
    ///
    /// # Errors
    /// [`SpaceError::LevelTooLarge`] for a level beyond [`crate::max_level`].
    pub fn new(level: u32) -> Result<Self, SpaceError> {
        let () = DimCheck::<K>::OK;
        Ok(Self {
            universe: Universe::new(level)?,
            levels: Vec::new(),
        })
    }

    /// Appends the next node of the traversal, at `depth`.
    pub fn push(&mut self, depth: usize, state: ValueState<V>) {
        if self.levels.len() <= depth {
            self.levels.resize_with(depth + 1, ValuedLevel::new);
        }
        self.levels[depth].push(state);
    }

    /// The tree (the caller guarantees the traversal was complete and minimal).
    pub fn finish(self) -> KTree<K, V> {
        let (levels, values) = self
            .levels
            .into_iter()
            .map(ValuedLevel::into_packed)
            .unzip();
        KTree::from_valued_levels(self.universe, levels, values)
    }
}
