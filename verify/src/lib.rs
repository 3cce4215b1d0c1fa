//! Shared strategies for ktree's property tests (in `tests/`): random ray sets ([`cases`]) and random
//! objects as dense boolean arrays ([`objects`]), both printed readably when proptest shrinks a failure.

pub mod cases;
pub mod objects;
