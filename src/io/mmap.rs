//! Read-only memory maps of files: one of the crate's two modules with `unsafe` code (the other steps rays
//! in the lanes of vectors, `map::ray_lanes`).
//!
//! A `.ktree` (version 2) is read by mapping it, so that queries touch only the pages they need and a tree
//! larger than memory can be inspected. Everything else in the crate sees a map as a plain `&[u8]`.

use std::fs::File;
use std::io;

/// A read-only view of a byte range of a file, unmapped when dropped.
#[derive(Debug)]
pub(crate) struct FileMap {
    map: memmap2::Mmap,
}

impl FileMap {
    /// Maps `len` bytes of `file` from `offset` read-only.
    ///
    /// # Errors
    /// Any error of `mmap(2)` (for instance, a range beyond the file's end on some systems).
    pub(crate) fn map(file: &File, offset: u64, len: usize) -> io::Result<Self> {
        let mut options = memmap2::MmapOptions::new();
        options.offset(offset).len(len);
        // SAFETY: `Mmap` is read-only (`PROT_READ`, `MAP_SHARED`), so this process never writes through it
        // and no `&mut` alias to the bytes exists. The remaining hazard of any file map is another process
        // changing the file while it is mapped:
        // * bytes rewritten in place become visible through the `&[u8]`. The crate only ever copies values
        //   out of the map (`u64::from_le_bytes` on bounds-checked slices) and treats every value as
        //   untrusted data — sizes and offsets come from the directory validated when the file was opened,
        //   node codes are matched exhaustively, a node the shape says exists but is not there is an error
        //   (`KtreeView`'s queries) — so a concurrent writer yields wrong answers or an error, never an
        //   out-of-bounds access, a panic or an invalid value of a Rust type;
        // * a file truncated underneath makes the kernel raise `SIGBUS` on the first access to a page past
        //   the new end, which terminates the process (it does not corrupt memory).
        // `.ktree` files are written to a temporary file and renamed over the target
        // (`crate::fs::write_atomic_with`), so ktree itself never changes a file that a reader has mapped: a
        // rename leaves the old inode, and the old bytes, in place for existing maps.
        let map = unsafe { options.map(file)? };
        Ok(Self { map })
    }

    /// The mapped bytes.
    pub(crate) fn bytes(&self) -> &[u8] {
        &self.map
    }
}
