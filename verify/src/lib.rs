//! Shared strategies for ktree's property tests (in `tests/`): random ray sets ([`cases`]), random objects
//! as dense boolean arrays ([`objects`]), sparse objects at the largest level of each K ([`sparse`]), all
//! printed readably when proptest shrinks a failure, and the case counts every property runs
//! ([`config()`]). Also the real tools the command-line tests and the experiments check ktree against, and
//! the one rule for a test whose tool is missing ([`tools`]).
#![deny(missing_docs)]

pub mod cases;
mod config;
pub mod labels;
pub mod meshes;
pub mod objects;
pub mod scenes;
pub mod sparse;
pub mod tools;

pub use config::{config, quickcheck_tests};
