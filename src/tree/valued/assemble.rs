//! A valued tree collected from its nodes in depth-first order.

use crate::space::{DimCheck, SpaceError, Universe};
use crate::tree::ktree::KTree;
use crate::tree::states::PackedStates;
use crate::value::Value;

use super::ValueState;

/// Collects a valued tree from its nodes in depth-first order (children in code order): each node is
/// appended to its level, each full node's value to its level's column. The caller guarantees a complete
/// traversal of a minimal tree.
#[derive(Debug, Clone)]
pub struct ValueAssembler<const K: usize, V> {
    universe: Universe<K>,
    levels: Vec<PackedStates>,
    values: Vec<Vec<V>>,
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
            values: Vec::new(),
        })
    }

    /// Appends the next node of the traversal, at `depth`.
    pub fn push(&mut self, depth: usize, state: ValueState<V>) {
        while self.levels.len() <= depth {
            self.levels.push(PackedStates::new());
            self.values.push(Vec::new());
        }
        let code = match state {
            ValueState::Empty => 0,
            ValueState::Full(v) => {
                self.values[depth].push(v);
                1
            }
            ValueState::Partial => 2,
            ValueState::Mixed => 3,
        };
        self.levels[depth].push_code(code);
    }

    /// The tree (the caller guarantees the traversal was complete and minimal).
    pub fn finish(self) -> KTree<K, V> {
        let mut levels = self.levels;
        for level in &mut levels {
            level.finish();
        }
        KTree::from_valued_levels(self.universe, levels, self.values)
    }
}
