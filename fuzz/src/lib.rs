//! What the fuzz targets share: the oracles run on whatever a reader accepts, and builders of valid files.

use std::path::Path;

use arbitrary::Arbitrary;
use ktree::io::{read_ktree_any, read_rays, write_ktree, write_ktree_v1, write_rays, KtreeFileError, KtreeView};
use ktree::{AnyRaySet, AnyTree};
use ktree::solid::cloud::{bounds as cloud_bounds, CloudVoxelizer};
use ktree::solid::mesh::MeshTransform;
use ktree::solid::volume::{Select, Volume};
use ktree::{max_level, KTree, Universe};

/// The largest level at which accepted inputs are voxelized or stacked (keeps one execution fast).
pub const CHECK_LEVEL: u32 = 5;

/// The `.ktree` version 1 bytes of a tree.
pub fn ktree_bytes(tree: &AnyTree) -> Vec<u8> {
    let mut bytes = Vec::new();
    ktree::with_dim!(tree, AnyTree, t => write_ktree_v1(&mut bytes, t)).expect("writing to memory");
    bytes
}

/// The `.ktree` version 2 bytes of a tree.
pub fn ktree_v2_bytes(tree: &AnyTree) -> Vec<u8> {
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

/// A `.ktree` version 2 file that was accepted: it is a checked tree, it is the one file that tree writes
/// (version 2 is canonical too: padding, rank samples, counts and checksums are all checked), and the
/// memory-mapped view of the same bytes gives the same tree.
pub fn check_accepted_ktree_v2(bytes: &[u8], tree: &AnyTree) {
    crate::check_tree(tree);
    let again = ktree_v2_bytes(tree);
    assert_eq!(
        again, bytes,
        "an accepted .ktree v2 file is not what its tree writes"
    );
    let reread = read_ktree_any(&again, "rewritten").expect("a written tree reads back");
    assert_eq!(&reread, tree);
    let view = KtreeView::from_bytes(again, "rewritten").expect("a written tree opens as a view");
    assert_eq!(view.counts_per_level(), tree.counts_per_level());
    let from_view = ktree::with_dim!(tree, AnyTree, t => view_tree(&view).is_ok_and(|v| &v == t));
    assert!(from_view, "the view of an accepted file gives another tree");
}

/// The tree of a view, of the view's dimension `K`.
pub fn view_tree<const K: usize>(view: &KtreeView) -> Result<KTree<K>, KtreeFileError> {
    view.to_tree::<K>()
}

/// Opens `bytes` as a memory-mapped `.ktree` view: written to a file of this process in the temporary
/// folder, mapped, and the file removed again (the map stays valid).
pub fn open_mapped(bytes: &[u8]) -> Result<KtreeView, KtreeFileError> {
    let path = std::env::temp_dir().join(format!("ktree-fuzz-{}.ktree", std::process::id()));
    std::fs::write(&path, bytes).expect("writing a temporary file");
    let view = KtreeView::open(&path);
    std::fs::remove_file(&path).expect("removing a temporary file");
    view
}

/// The largest number of nodes [`arbitrary_tree`] decides (keeps one execution fast).
pub const MAX_SHAPE_NODES: usize = 4096;

/// A tree of a level-`level` universe (`level ≤ max_level(K)`) described by `shape`: a depth-first walk
/// from the root in which each byte decides a node — 0 mod 3 empty, 1 full, 2 divided into its `2^K`
/// children (a divided voxel is full) — and nodes beyond the bytes, or beyond [`MAX_SHAPE_NODES`], are
/// empty. Siblings all alike are merged, so every reduced tree of the universe has a description.
pub fn arbitrary_tree<const K: usize>(level: u32, shape: &[u8]) -> KTree<K> {
    let universe = Universe::<K>::new(level).expect("a level of the universe");
    let mut cells = Vec::new();
    let mut bytes = shape.iter().take(MAX_SHAPE_NODES);
    let mut stack = vec![universe.root()];
    while let Some(cell) = stack.pop() {
        match bytes.next().map(|b| b % 3) {
            Some(1) => cells.push(cell),
            Some(2) if cell.log_side() > 0 => {
                stack.extend((0..1 << K).rev().map(|code| cell.child(code)))
            }
            Some(2) => cells.push(cell),
            _ => {}
        }
    }
    KTree::from_cells(universe, &cells).expect("disjoint cells of the universe")
}

/// [`arbitrary_tree`] of dimension `K = 1 + k mod 4`, at `level` reduced modulo `max_level(K) + 1`.
pub fn arbitrary_any_tree(k: u8, level: u8, shape: &[u8]) -> AnyTree {
    let k = 1 + usize::from(k % 4);
    let level = u32::from(level) % (max_level(k) + 1);
    match k {
        1 => AnyTree::from(arbitrary_tree::<1>(level, shape)),
        2 => AnyTree::from(arbitrary_tree::<2>(level, shape)),
        3 => AnyTree::from(arbitrary_tree::<3>(level, shape)),
        _ => AnyTree::from(arbitrary_tree::<4>(level, shape)),
    }
}

/// The invariants of a tree that a reader returned.
pub fn check_tree(tree: &AnyTree) {
    ktree::with_dim!(tree, AnyTree, t => t.check()).expect("a tree from a reader is well formed");
}

/// A ray file that was accepted: written and read back it is the same set, and its tree (stacked when the
/// universe is small, or the rays and their voxels few) round-trips through the `.ktree` format.
pub fn check_accepted_rays(rays: &AnyRaySet) {
    let text = rays_text(rays);
    let again = read_rays(&text[..], "rewritten").expect("written rays read back");
    assert_eq!(&again, rays, "rays changed through write → read");
    // A few rays in a large universe may still cover millions of voxels in a thin column, whose tree has
    // about one node a voxel: stacked only when the voxels are few too.
    let voxels: u128 = ktree::with_dim!(rays, AnyRaySet, r => r.voxel_count());
    if rays.level() <= CHECK_LEVEL + 1 || (rays.len() <= 64 && voxels <= 1 << 16) {
        let tree = rays.build();
        check_tree(&tree);
        let bytes = ktree_bytes(&tree);
        let reread = read_ktree_any(&bytes, "stacked").expect("a stacked tree reads back");
        assert_eq!(reread, tree, "tree changed through write → read");
    }
}

/// Parses a mesh and, when accepted, voxelizes it fitted into a small universe: errors are fine, panics
/// are not.
pub fn check_mesh(bytes: &[u8], format: &str) {
    let Ok(mesh) = ktree::io::read_mesh_bytes(bytes, format, Path::new("fuzz")) else {
        return;
    };
    if let Ok(placement) = MeshTransform::fit(&mesh, CHECK_LEVEL) {
        if let Ok(r) = mesh.to_rays(CHECK_LEVEL, &placement) {
            let _ = ktree::stacking::paper::stack(&r.rays);
        }
    }
    let _ = (mesh.signed_volume(), mesh.surface_area(), mesh.open_edges());
}

/// Parses a point cloud and, when accepted, voxelizes it: at a voxel size that puts it in a universe of
/// level ≤ [`CHECK_LEVEL`], and cropped to a level-3 universe
/// at the origin 0; errors are fine, panics are not.
pub fn check_cloud(bytes: &[u8], format: &str) {
    let Ok(cloud) = ktree::io::read_cloud_bytes(bytes, format, Path::new("fuzz")) else {
        return;
    };
    let points = cloud.points();
    if let Some((lo, hi)) = cloud_bounds(points) {
        let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
        let size = if extent.is_finite() && extent > 0.0 {
            extent / 15.0
        } else {
            1.0
        };
        if let Ok(v) = CloudVoxelizer::new(size).and_then(|v| v.voxelize(points)) {
            assert!(v.rays.level() <= CHECK_LEVEL);
            assert!(v.rays.voxel_count() <= points.len() as u128);
            KTree::from_rays(&v.rays).assert_well_formed();
        }
    }
    let cropped = CloudVoxelizer::new(0.5)
        .expect("a positive voxel size")
        .origin([0.0; 3])
        .level(3)
        .crop(true)
        .min_points(2)
        .voxelize(points)
        .expect("cropping accepts every finite point");
    assert!(cropped.rays.voxel_count() * 2 + u128::from(cropped.cropped) <= points.len() as u128);
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

/// A number written into a text header: integers and floats of any size, or any text in its place.
#[derive(Debug, Arbitrary)]
pub enum Number {
    /// A signed integer.
    Int(i64),
    /// An unsigned integer.
    Big(u64),
    /// A float (`NaN`, `inf` and subnormals included).
    Float(f64),
    /// Any text.
    Text(String),
}

impl std::fmt::Display for Number {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Number::Int(v) => write!(f, "{v}"),
            Number::Big(v) => write!(f, "{v}"),
            Number::Float(v) => write!(f, "{v}"),
            Number::Text(v) => write!(f, "{v}"),
        }
    }
}

/// An edit of the lines of a text header (`keyword` picks one of the format's keywords).
#[derive(Debug, Arbitrary)]
pub enum HeaderEdit {
    /// Line `at` becomes a keyword followed by numbers.
    Replace {
        /// The line.
        at: u8,
        /// The keyword's index.
        keyword: u8,
        /// What follows it.
        numbers: Vec<Number>,
    },
    /// A keyword line inserted before line `at`.
    Insert {
        /// The line.
        at: u8,
        /// The keyword's index.
        keyword: u8,
        /// What follows it.
        numbers: Vec<Number>,
    },
    /// Line `at` becomes any text.
    Text {
        /// The line.
        at: u8,
        /// Its new text.
        text: String,
    },
    /// A line removed.
    Drop(u8),
    /// A line repeated.
    Duplicate(u8),
    /// Two lines exchanged.
    Swap(u8, u8),
}

/// An edit of binary data counted in units of `unit` bytes (a run-length pair, a node, a word).
#[derive(Debug, Arbitrary)]
pub enum BodyEdit {
    /// Bits of a byte flipped.
    Xor {
        /// The byte.
        at: u16,
        /// The bits.
        mask: u8,
    },
    /// A byte set.
    Set {
        /// The byte.
        at: u16,
        /// Its value.
        value: u8,
    },
    /// Units removed.
    Drop {
        /// The first unit.
        at: u16,
        /// How many.
        len: u8,
    },
    /// Units repeated right after themselves.
    Duplicate {
        /// The first unit.
        at: u16,
        /// How many.
        len: u8,
    },
    /// Bytes cut from the end.
    Truncate(u16),
    /// Bytes appended.
    Append(Vec<u8>),
}

/// A file made of text header lines (the last one `data`) and a binary body: binvox and OctoMap `.bt`.
#[derive(Debug, Clone, PartialEq)]
pub struct TextHeaderFile {
    /// The header lines, without their newlines.
    pub lines: Vec<String>,
    /// Everything after the header.
    pub body: Vec<u8>,
}

impl TextHeaderFile {
    /// Splits a written file after its first line that is exactly `data`.
    pub fn split(bytes: &[u8]) -> Self {
        let mut lines = Vec::new();
        let mut at = 0;
        while let Some(len) = bytes[at..].iter().position(|&b| b == b'\n') {
            let line = String::from_utf8(bytes[at..at + len].to_vec()).expect("a text header");
            at += len + 1;
            let last = line == "data";
            lines.push(line);
            if last {
                break;
            }
        }
        Self {
            lines,
            body: bytes[at..].to_vec(),
        }
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut bytes = Vec::new();
        for line in &self.lines {
            bytes.extend_from_slice(line.as_bytes());
            bytes.push(b'\n');
        }
        bytes.extend_from_slice(&self.body);
        bytes
    }

    /// Applies a header edit; `keywords` are the format's line keywords.
    pub fn edit_header(&mut self, edit: &HeaderEdit, keywords: &[&str]) {
        let n = self.lines.len();
        let line = |keyword: u8, numbers: &[Number]| {
            let mut line = keywords[usize::from(keyword) % keywords.len()].to_string();
            for number in numbers {
                line.push(' ');
                line.push_str(&number.to_string());
            }
            line
        };
        match edit {
            HeaderEdit::Replace {
                at,
                keyword,
                numbers,
            } if n > 0 => self.lines[usize::from(*at) % n] = line(*keyword, numbers),
            HeaderEdit::Insert {
                at,
                keyword,
                numbers,
            } => self
                .lines
                .insert(usize::from(*at) % (n + 1), line(*keyword, numbers)),
            HeaderEdit::Text { at, text } if n > 0 => {
                self.lines[usize::from(*at) % n] = text.clone()
            }
            HeaderEdit::Drop(at) if n > 0 => {
                self.lines.remove(usize::from(*at) % n);
            }
            HeaderEdit::Duplicate(at) if n > 0 => {
                let at = usize::from(*at) % n;
                self.lines.insert(at, self.lines[at].clone());
            }
            HeaderEdit::Swap(a, b) if n > 0 => {
                self.lines.swap(usize::from(*a) % n, usize::from(*b) % n)
            }
            _ => {}
        }
    }
}

/// Applies an edit to binary data made of `unit`-byte units.
pub fn edit_body(body: &mut Vec<u8>, edit: &BodyEdit, unit: usize) {
    let units = body.len() / unit;
    match edit {
        BodyEdit::Xor { at, mask } if !body.is_empty() => {
            let at = usize::from(*at) % body.len();
            body[at] ^= mask;
        }
        BodyEdit::Set { at, value } if !body.is_empty() => {
            let at = usize::from(*at) % body.len();
            body[at] = *value;
        }
        BodyEdit::Drop { at, len } if units > 0 => {
            let first = usize::from(*at) % units;
            let end = (first + usize::from(*len)).min(units);
            body.drain(first * unit..end * unit);
        }
        BodyEdit::Duplicate { at, len } if units > 0 => {
            let first = usize::from(*at) % units;
            let end = (first + usize::from(*len)).min(units);
            let copy = body[first * unit..end * unit].to_vec();
            body.splice(end * unit..end * unit, copy);
        }
        BodyEdit::Truncate(n) => body.truncate(body.len().saturating_sub(usize::from(*n))),
        BodyEdit::Append(tail) => body.extend_from_slice(tail),
        _ => {}
    }
}

/// Scans that were accepted: each placed in the world has its node's points, and an identity pose moves
/// nothing.
pub fn check_scan_nodes(nodes: &[ktree::io::ScanNode]) {
    for node in nodes {
        let scan = node.to_scan();
        assert_eq!(scan.points.len(), node.points.len());
        let unmoved = ktree::io::ScanNode {
            pose: ktree::io::Pose::IDENTITY,
            ..node.clone()
        };
        assert_eq!(unmoved.to_scan().points, node.points);
    }
}
