//! OpenVDB files (`.vdb`): octrees written as one `BoolGrid` (`Tree_bool_5_4_3`), the grid type OpenVDB's
//! Python module reads as a voxel set — active voxels are the object — and trees with values as one typed
//! grid (`Int32Grid`, `FloatGrid`, `Vec3SGrid`, see [`typed`]); read from a level set (a `FloatGrid` or
//! `DoubleGrid` of class `level set`: its interior, see [`super`]) or any other grid (its active voxels: a
//! `BoolGrid`, `MaskGrid`, `Int32Grid`, `Int64Grid`, `FloatGrid`, `DoubleGrid`, `Vec3SGrid`, `Vec3DGrid`), or,
//! with their values, from a typed grid ([`typed`]).
//!
//! The layout (file format version 224, OpenVDB 10): a header (magic `0x56444220` as `i64`, versions, a
//! UUID), file metadata, the grid count, and per grid its descriptor (name, type, positions), its compression
//! flags, metadata, transform, topology and leaf buffers. The tree is OpenVDB's root → 32³ internal nodes of
//! 128³ voxels → 16³ internal nodes of 8³ → 8³ leaves; masks are `u64` words, bit `n` of word `n / 64`,
//! with `n = x·D² + y·D + z` inside a node of side `D` (x slowest). All values little-endian.
//!
//! Written files are uncompressed (compression flags 0), which every OpenVDB reads. Reading takes what
//! OpenVDB writes (`vdb_values`): values raw or with active-mask compression, in zlib or Blosc
//! chunks (Blosc 1 frames with the LZ4 codec and byte shuffle, OpenVDB's default, decoded by
//! `blosc`); other Blosc codecs are reported as unsupported), and half floats. The first grid of a
//! type read is taken (reading values, a `BoolGrid`, `MaskGrid` or level set is passed over, and named with
//! its class when no other grid is read). OpenVDB index `(x, y, z)` is ktree
//! voxel `(x, y, z)` minus the offset written with, and the transform's voxel size and translation (the
//! world centre of index 0) become the [`GridMeta`](super::GridMeta).
//!
//! One concept a module: [`write`] the node structure and grid writer (and the `BoolGrid`), [`typed`] trees
//! with values out and in, [`read`] the reader (header, grid choice, the walk over active values),
//! [`level_set`] level sets out and their interior in, [`values`] the value buffers as OpenVDB stores them,
//! [`blosc`] its Blosc frames; this module the format's constants and node geometry, which all of them share.

mod blosc;
mod level_set;
mod read;
#[cfg(test)]
mod tests;
mod typed;
mod values;
mod write;

pub use level_set::write_vdb_level_set;
pub use read::{read_vdb, read_vdb_within};
pub use typed::{
    read_vdb_values, read_vdb_values_within, vdb_holds_values, write_any_valued_vdb,
    write_vdb_values, PlacedValues,
};
pub use write::write_vdb;

const MAGIC: i64 = 0x5644_4220;
const FILE_VERSION: u32 = 224;
const BOOL_TREE: &str = "Tree_bool_5_4_3";
const MASK_TREE: &str = "Tree_mask_5_4_3";
const FLOAT_TREE: &str = "Tree_float_5_4_3";
const DOUBLE_TREE: &str = "Tree_double_5_4_3";
const INT32_TREE: &str = "Tree_int32_5_4_3";
const INT64_TREE: &str = "Tree_int64_5_4_3";
const VEC3S_TREE: &str = "Tree_vec3s_5_4_3";
const VEC3D_TREE: &str = "Tree_vec3d_5_4_3";
/// Appended to a grid's type name when its values are saved as half floats.
const HALF_FLOAT_SUFFIX: &str = "_HalfFloat";
/// Grid metadata written by ktree: the universe level and the offset, read back as defaults.
const LEVEL_KEY: &str = "ktree_level";
const OFFSET_KEY: &str = "ktree_offset";
/// Words of a leaf mask (8³ bits), of a lower node mask (16³), of an upper node mask (32³).
const LEAF_WORDS: usize = 8;
const LOWER_WORDS: usize = 64;
const UPPER_WORDS: usize = 512;

/// The slot of the child holding `p` in a node of `2^log_dim` children a side, each `2^child_log` voxels.
fn slot(p: [i64; 3], log_dim: u32, child_log: u32) -> u32 {
    let m = (1i64 << (log_dim + child_log)) - 1;
    let c = |a: usize| ((p[a] & m) >> child_log) as u32;
    (c(0) << (2 * log_dim)) | (c(1) << log_dim) | c(2)
}

/// The origin of the node of side `2^log_side` holding `p`.
fn origin_of(p: [i64; 3], log_side: u32) -> [i64; 3] {
    p.map(|c| c & !((1i64 << log_side) - 1))
}

/// The corner of child `n` (in OpenVDB's order, x slowest) of the node at `origin` with `2^log_dim` children
/// a side, each `2^child_log` voxels.
fn corner_of(origin: [i64; 3], n: usize, log_dim: u32, child_log: u32) -> [i64; 3] {
    let m = (1usize << log_dim) - 1;
    let c = [n >> (2 * log_dim), n >> log_dim & m, n & m];
    std::array::from_fn(|a| origin[a] + ((c[a] as i64) << child_log))
}
