//! What the fuzz targets share: the oracles run on whatever a reader accepts, and builders of valid files.

use std::path::Path;

use ktree::io::{read_ktree_any, read_rays, write_ktree, write_rays, AnyRaySet, AnyTree};
use ktree::solid::mesh::{Placement, TriangleMesh};
use ktree::solid::volume::{Select, Volume};

/// The largest level at which accepted inputs are voxelized or stacked (keeps one execution fast).
pub const CHECK_LEVEL: u32 = 5;

/// The `.ktree` bytes of a tree.
pub fn ktree_bytes(tree: &AnyTree) -> Vec<u8> {
    let mut bytes = Vec::new();
    ktree::with_dim!(tree, AnyTree, t => write_ktree(&mut bytes, t)).expect("writing to memory");
    bytes
}

/// The ray text of a ray set.
pub fn rays_text(rays: &AnyRaySet) -> Vec<u8> {
    let mut bytes = Vec::new();
    ktree::with_dim!(rays, AnyRaySet, r => write_rays(&mut bytes, r)).expect("writing to memory");
    bytes
}

/// Overwrites the last 4 bytes with the CRC-32 of the rest, as a writer would (no-op below 4 bytes).
pub fn fix_crc(bytes: &mut [u8]) {
    if bytes.len() >= 4 {
        let at = bytes.len() - 4;
        let crc = crc32fast::hash(&bytes[..at]);
        bytes[at..].copy_from_slice(&crc.to_le_bytes());
    }
}

/// A `.ktree` file that was accepted: it is a checked tree, and it is the one file that tree writes to
/// (the format is canonical), so read → write → read gives the same tree and the same bytes.
pub fn check_accepted_ktree(bytes: &[u8], tree: &AnyTree) {
    crate::check_tree(tree);
    let again = ktree_bytes(tree);
    assert_eq!(
        again, bytes,
        "an accepted .ktree file is not what its tree writes"
    );
    let reread = read_ktree_any(&again, "rewritten").expect("a written tree reads back");
    assert_eq!(&reread, tree);
}

/// The invariants of a tree that a reader returned.
pub fn check_tree(tree: &AnyTree) {
    ktree::with_dim!(tree, AnyTree, t => t.check()).expect("a tree from a reader is well formed");
}

/// A ray file that was accepted: written and read back it is the same set, and its tree (stacked when the
/// universe is small) round-trips through the `.ktree` format.
pub fn check_accepted_rays(rays: &AnyRaySet) {
    let text = rays_text(rays);
    let again = read_rays(&text[..], "rewritten").expect("written rays read back");
    assert_eq!(&again, rays, "rays changed through write → read");
    if rays.level() <= CHECK_LEVEL + 1 || rays.len() <= 64 {
        let tree = rays.stack();
        check_tree(&tree);
        let bytes = ktree_bytes(&tree);
        let reread = read_ktree_any(&bytes, "stacked").expect("a stacked tree reads back");
        assert_eq!(reread, tree, "tree changed through write → read");
    }
}

/// Parses a mesh and, when accepted, voxelizes it fitted into a small universe: errors are fine, panics
/// are not.
pub fn check_mesh(bytes: &[u8], format: &str) {
    let Ok(mesh) = TriangleMesh::from_bytes(bytes, format, Path::new("fuzz")) else {
        return;
    };
    if let Ok(placement) = Placement::fit(&mesh, CHECK_LEVEL) {
        if let Ok(r) = mesh.to_rays(CHECK_LEVEL, &placement) {
            let _ = ktree::stacking::stack(&r.rays);
        }
    }
    let _ = (mesh.signed_volume(), mesh.surface_area(), mesh.open_edges());
}

/// A volume that was accepted: its samples become rays in the smallest universe that holds it (when that
/// is small), by a threshold and by a label.
pub fn check_volume(volume: &Volume) {
    let level = volume.fitting_level();
    if level <= CHECK_LEVEL + 1 {
        for select in [Select::AtLeast(0.5), Select::Label(1.0)] {
            let rays = volume
                .to_rays(level, [0; 3], select)
                .expect("a volume fits its fitting level");
            assert_eq!(rays.voxel_count() as usize, volume.count(select));
        }
    }
}

/// Splits `data` at its first NUL byte (the rest after it), or gives all of it and nothing.
pub fn split_at_nul(data: &[u8]) -> (&[u8], &[u8]) {
    match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], &data[i + 1..]),
        None => (data, &[]),
    }
}
