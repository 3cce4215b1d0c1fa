//! Structure-aware OpenVDB: the `BoolGrid` file of an arbitrary octree (levels 0…12, at any offset up to
//! level 4 and at multiples of 4096 above, any transform), then edits: any of its header, descriptor,
//! metadata, transform and topology fields (versions, counts, string lengths, grid positions, compression
//! flags, the stored level and offset, the transform's numbers, node origins and value compression bytes)
//! set to any value, bytes flipped or set, 4-byte units removed or repeated, a cut or added tail; read with
//! or without a placement. The untouched file is the tree; an edited one is rejected or is a well-formed
//! tree.
#![no_main]
use arbitrary::Arbitrary;
use ktree::io::{read_vdb, write_vdb, GridMeta};
use ktree_fuzz::BodyEdit;
use libfuzzer_sys::fuzz_target;

#[derive(Debug, Arbitrary)]
enum Edit {
    /// Field `which` of the file (see [`fields`]) set to the low bytes of `value`.
    Field {
        which: u16,
        value: u64,
    },
    Body(BodyEdit),
}

#[derive(Debug, Arbitrary)]
struct Input {
    level: u8,
    shape: Vec<u8>,
    offset: [i32; 3],
    voxel_size: f64,
    origin: [f64; 3],
    edits: Vec<Edit>,
    read_offset: Option<[i64; 3]>,
    read_level: Option<u8>,
}

/// A cursor over a file `write_vdb` wrote, noting where its fields are: (byte offset, width).
struct Fields<'a> {
    bytes: &'a [u8],
    at: usize,
    found: Vec<(usize, usize)>,
}

impl Fields<'_> {
    fn field(&mut self, width: usize) -> u64 {
        self.found.push((self.at, width));
        let mut v = [0u8; 8];
        v[..width].copy_from_slice(&self.bytes[self.at..self.at + width]);
        self.at += width;
        u64::from_le_bytes(v)
    }

    fn skip(&mut self, n: usize) {
        self.at += n;
    }

    fn string(&mut self) {
        let n = self.field(4) as usize;
        self.skip(n);
    }

    fn mask(&mut self, words: usize) -> u32 {
        let b = &self.bytes[self.at..self.at + 8 * words];
        self.found.push((self.at, 8));
        self.skip(8 * words);
        b.iter().map(|x| x.count_ones()).sum()
    }
}

/// The fields of a file that `write_vdb` wrote, in the order of its layout.
fn fields(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut f = Fields {
        bytes,
        at: 8,
        found: Vec::new(),
    };
    for width in [4, 4, 4, 1] {
        f.field(width);
    }
    f.skip(36);
    f.field(4); // file metadata count
    f.field(4); // grid count
    for _ in 0..3 {
        f.string(); // name, type, instance parent
    }
    for _ in 0..3 {
        f.field(8); // grid, block and end positions
    }
    f.field(4); // compression flags
    let entries = f.field(4);
    for _ in 0..entries {
        f.string();
        f.string();
        let n = f.field(4) as usize;
        for _ in 0..n / 4 {
            f.field(4);
        }
        f.skip(n % 4);
    }
    f.string(); // transform
    for _ in 0..18 {
        f.field(8);
    }
    f.field(4); // buffer count
    f.field(1); // background
    let tiles = f.field(4);
    assert_eq!(tiles, 0);
    let uppers = f.field(4);
    let mut leaves = 0;
    for _ in 0..uppers {
        for _ in 0..3 {
            f.field(4);
        }
        let lowers = f.mask(512);
        f.mask(512);
        f.field(1);
        f.skip(32768);
        for _ in 0..lowers {
            let l = f.mask(64);
            f.mask(64);
            f.field(1);
            f.skip(4096);
            for _ in 0..l {
                f.mask(8);
            }
            leaves += l;
        }
    }
    for _ in 0..leaves {
        f.mask(8);
        for _ in 0..3 {
            f.field(4);
        }
        f.mask(8);
    }
    assert_eq!(f.at, bytes.len(), "the fields cover the file");
    f.found
}

fuzz_target!(|input: Input| {
    let level = u32::from(input.level) % 13;
    let tree = ktree_fuzz::arbitrary_tree::<3>(level, &input.shape);
    // Beyond level 4 the universe is one of OpenVDB's top nodes (an offset of a multiple of 4096): writing
    // stays fast, and so does reading the file (about 41 kB) at a placement that leaves its cells
    // unaligned, which may build up to 2^10 nodes a byte of the file.
    let offset = input.offset.map(|o| {
        if level <= 4 {
            i64::from(o)
        } else {
            i64::from(o) >> 12 << 12
        }
    });
    let meta = GridMeta {
        voxel_size: if input.voxel_size.is_finite() && input.voxel_size > 0.0 {
            input.voxel_size
        } else {
            1.0
        },
        origin: input.origin,
    };
    let mut bytes = Vec::new();
    if write_vdb(&mut bytes, &tree, offset, &meta).is_err() {
        assert!(
            offset
                .iter()
                .any(|&o| (1i64 << level) - o > i64::from(i32::MAX)),
            "a valid offset refused"
        );
        return;
    }
    let placed = read_vdb(&bytes, "valid", None, None).expect("a written file reads");
    assert_eq!(placed.tree, tree);
    let fields = fields(&bytes);
    for edit in &input.edits {
        match edit {
            Edit::Field { which, value } => {
                let (at, width) = fields[usize::from(*which) % fields.len()];
                if at + width <= bytes.len() {
                    bytes[at..at + width].copy_from_slice(&value.to_le_bytes()[..width]);
                }
            }
            Edit::Body(e) => ktree_fuzz::edit_body(&mut bytes, e, 4),
        }
    }
    let level = input.read_level.map(u32::from);
    if let Ok(placed) = read_vdb(&bytes, "edited", input.read_offset, level) {
        placed
            .tree
            .check()
            .expect("a tree from a reader is well formed");
    }
});
