//! Files in and out: atomic writes, the ray text format and the `.ktree` tree format.

mod atomic;

pub use atomic::{write_atomic, write_atomic_with};
