//! binvox files (Patrick Min's voxelizer, read by OctoMap's `binvox2bt`): a text header, then the voxels
//! run-length encoded.
//!
//! ```text
//! #binvox 1
//! dim D D D
//! translate tx ty tz       <- world position of the grid's corner (optional, default 0)
//! scale s                  <- world length of the whole grid (optional, default D)
//! data
//! (value, count) bytes     <- value 0 or 1, count 1…255, covering D³ voxels in total
//! ```
//!
//! Voxel `(x, y, z)` is number `x·D² + z·D + y` of the stream (y runs fastest), and binvox voxel `(x, y, z)`
//! is ktree voxel `(x, y, z)` plus the read offset (0 by default). `translate` and `scale` become the grid's
//! [`GridMeta`] (voxel size `s / D`, origin `t`). Only cubic grids exist in binvox; a `D` that is not a power of
//! two reads into the smallest universe that holds it unless a level is given.

use std::io::Write;

use super::grid::{
    max_grid_nodes, place_boxes, GridBoxes, GridFileError, GridFileErrorKind, GridMeta,
    GridPlacement, IndexBox, PlacedTree, MAX_GRID_RUNS,
};
use crate::tree::KTree;

/// The largest `D` read or written (binvox is dense: a level-12 grid already has 2^36 voxels).
pub const BINVOX_MAX_DIM: u64 = 1 << 12;

/// Reads a binvox file's bytes into an octree placed by `offset` and `level` (see [`GridPlacement::choose`]).
///
/// ```
/// use ktree::io::{read_binvox, write_binvox, GridMeta};
/// let tree = ktree::KTree::<3>::from_dense(1, &[true, false, false, false, false, false, false, true]).unwrap();
/// let mut bytes = Vec::new();
/// write_binvox(&mut bytes, &tree, &GridMeta::default()).unwrap();
/// assert!(bytes.starts_with(b"#binvox 1\ndim 2 2 2\n"));
/// assert_eq!(read_binvox(&bytes, "mem", None, None).unwrap().tree, tree);
/// ```
///
/// # Errors
/// [`GridFileError`] naming the byte offset of the first problem: a bad header, a value other than 0 or 1,
/// a count of 0, data shorter or longer than `D³` voxels, or voxels outside the universe asked for.
pub fn read_binvox(
    bytes: &[u8],
    file: &str,
    offset: Option<[i64; 3]>,
    level: Option<u32>,
) -> Result<PlacedTree, GridFileError> {
    let fail = |at: usize, kind| GridFileError::new(file, at, kind);
    let (dim, meta, data_at) = read_header(bytes, file)?;
    let d = dim as u64;
    let total = u128::from(d).pow(3);
    // Every pair covers at most 255 voxels: check the length before allocating the slab.
    let min_bytes = 2 * total.div_ceil(255);
    let data = &bytes[data_at..];
    if (data.len() as u128) < min_bytes {
        return Err(fail(
            bytes.len(),
            GridFileErrorKind::Truncated(format!(
                "{d}³ voxels need at least {min_bytes} data bytes, found {}",
                data.len()
            )),
        ));
    }
    let side = dim as usize;
    // One x slab at a time, indexed y·D + z so that z runs are contiguous.
    let mut slab = vec![false; side * side];
    let mut dirty = false;
    let mut boxes = GridBoxes::default();
    boxes.note_known(IndexBox {
        origin: [0; 3],
        size: [d; 3],
    });
    let mut runs = 0u64;
    let mut flush = |slab: &mut [bool], x: u64, boxes: &mut GridBoxes| -> Result<(), usize> {
        for y in 0..side {
            let row = &mut slab[y * side..(y + 1) * side];
            let mut z = 0;
            while z < side {
                if !row[z] {
                    z += 1;
                    continue;
                }
                let z0 = z;
                while z < side && row[z] {
                    row[z] = false;
                    z += 1;
                }
                runs += 1;
                if runs > MAX_GRID_RUNS {
                    return Err(0);
                }
                boxes.inside.push(IndexBox {
                    origin: [x as i64, y as i64, z0 as i64],
                    size: [1, 1, (z - z0) as u64],
                });
            }
        }
        Ok(())
    };
    let too_many = |at: usize| {
        fail(
            at,
            GridFileErrorKind::Unsupported(format!("more than {MAX_GRID_RUNS} runs")),
        )
    };
    let plane = u128::from(d * d);
    let mut pos: u128 = 0;
    let mut at = 0usize;
    while pos < total {
        if at + 2 > data.len() {
            return Err(fail(
                data_at + at,
                GridFileErrorKind::Truncated(format!("{pos} of {total} voxels given")),
            ));
        }
        let (value, count) = (data[at], data[at + 1]);
        if value > 1 {
            return Err(fail(
                data_at + at,
                GridFileErrorKind::Data(format!("value {value} is not 0 or 1")),
            ));
        }
        if count == 0 {
            return Err(fail(
                data_at + at + 1,
                GridFileErrorKind::Data("a run count of 0".into()),
            ));
        }
        let end = pos + u128::from(count);
        if end > total {
            return Err(fail(
                data_at + at + 1,
                GridFileErrorKind::Data(format!("the runs cover more than {total} voxels")),
            ));
        }
        while pos < end {
            let x = (pos / plane) as u64;
            let in_slab = (pos % plane) as u64;
            let stop = end.min(u128::from(x + 1) * plane);
            if value == 1 {
                for i in in_slab..in_slab + (stop - pos) as u64 {
                    let (z, y) = (i / d, i % d);
                    slab[y as usize * side + z as usize] = true;
                }
                dirty = true;
            }
            pos = stop;
            if pos.is_multiple_of(plane) && dirty {
                flush(&mut slab, x, &mut boxes).map_err(|_| too_many(data_at + at))?;
                dirty = false;
            }
        }
        at += 2;
    }
    if at != data.len() {
        return Err(fail(
            data_at + at,
            GridFileErrorKind::Data(format!(
                "{} bytes after the last of the {total} voxels",
                data.len() - at
            )),
        ));
    }
    let placement = GridPlacement::choose(boxes.known, boxes.alignment(), offset, level)
        .map_err(|m| fail(0, GridFileErrorKind::GridPlacement(m)))?;
    let tree = place_boxes(&boxes, &placement, max_grid_nodes(bytes.len()))
        .map_err(|m| fail(0, GridFileErrorKind::GridPlacement(m)))?;
    Ok(PlacedTree {
        tree,
        placement,
        meta,
    })
}

/// Parses the header; returns `D`, the metadata and the offset of the first data byte.
fn read_header(bytes: &[u8], file: &str) -> Result<(u32, GridMeta, usize), GridFileError> {
    let fail = |at: usize, m: String| GridFileError::new(file, at, GridFileErrorKind::Header(m));
    let mut at = 0usize;
    let mut line_no = 0;
    let mut dim = None;
    let mut translate = [0.0; 3];
    let mut scale = None;
    loop {
        let rest = &bytes[at..];
        let Some(len) = rest.iter().take(256).position(|&b| b == b'\n') else {
            return Err(fail(
                at,
                "expected a header line ending in a newline (before `data`)".into(),
            ));
        };
        let line = std::str::from_utf8(&rest[..len])
            .map_err(|_| fail(at, "the header line is not text".into()))?
            .trim();
        let words: Vec<&str> = line.split_whitespace().collect();
        let line_at = at;
        at += len + 1;
        line_no += 1;
        if line_no == 1 {
            if words != ["#binvox", "1"] {
                return Err(fail(
                    line_at,
                    format!("expected `#binvox 1`, found {line:?}"),
                ));
            }
            continue;
        }
        let numbers = |n: usize| -> Result<Vec<f64>, GridFileError> {
            let v: Vec<f64> = words[1..]
                .iter()
                .map(|w| w.parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| fail(line_at, format!("{line:?}: expected {n} numbers")))?;
            if v.len() != n || !v.iter().all(|x| x.is_finite()) {
                return Err(fail(
                    line_at,
                    format!("{line:?}: expected {n} finite numbers"),
                ));
            }
            Ok(v)
        };
        match words.first().copied() {
            Some("dim") => {
                let v = numbers(3)?;
                if v[0] != v[1] || v[1] != v[2] || v[0].fract() != 0.0 || v[0] < 1.0 {
                    return Err(fail(
                        line_at,
                        format!("{line:?}: expected a cubic grid `dim D D D`, D ≥ 1"),
                    ));
                }
                if v[0] > BINVOX_MAX_DIM as f64 {
                    return Err(fail(
                        line_at,
                        format!("D = {} exceeds {BINVOX_MAX_DIM}", v[0]),
                    ));
                }
                dim = Some(v[0] as u32);
            }
            Some("translate") => {
                let v = numbers(3)?;
                translate = [v[0], v[1], v[2]];
            }
            Some("scale") => {
                let v = numbers(1)?;
                if v[0] <= 0.0 {
                    return Err(fail(line_at, "scale must be positive".into()));
                }
                scale = Some(v[0]);
            }
            Some("data") if words.len() == 1 => break,
            _ => return Err(fail(line_at, format!("unknown header line {line:?}"))),
        }
    }
    let dim = dim.ok_or_else(|| fail(0, "no `dim` line before `data`".into()))?;
    let meta = GridMeta {
        voxel_size: scale.unwrap_or(f64::from(dim)) / f64::from(dim),
        origin: translate,
    };
    Ok((dim, meta, at))
}

/// Writes an octree as a binvox grid of side `D = 2^L` (ktree voxel = binvox voxel); `meta` gives
/// `translate` (its origin) and `scale` (`D ·` its voxel size).
///
/// The cost is one pass over the `D³` voxels (binvox is a dense format).
///
/// # Errors
/// Any I/O error; [`std::io::ErrorKind::InvalidInput`] for a universe beyond [`BINVOX_MAX_DIM`].
pub fn write_binvox(mut w: impl Write, tree: &KTree<3>, meta: &GridMeta) -> std::io::Result<()> {
    let d = 1u64 << tree.level();
    if d > BINVOX_MAX_DIM {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "a level-{} universe is larger than binvox's limit",
                tree.level()
            ),
        ));
    }
    let [tx, ty, tz] = meta.origin.map(header_number);
    let scale = header_number(meta.voxel_size * d as f64);
    write!(
        w,
        "#binvox 1\ndim {d} {d} {d}\ntranslate {tx} {ty} {tz}\nscale {scale}\ndata\n"
    )?;
    let rays = tree.to_rays();
    let side = d as usize;
    let mut slab = vec![false; side * side]; // indexed z·D + y: the stream's order within a slab
    let mut enc = RunEncoder {
        w: std::io::BufWriter::new(w),
        value: 0,
        count: 0,
    };
    let keys = rays.column_keys();
    let runs = rays.runs();
    let mut i = 0;
    for x in 0..d {
        slab.iter_mut().for_each(|v| *v = false);
        while i < keys.len() && rays.column_of_key(keys[i])[0] as u64 == x {
            let y = rays.column_of_key(keys[i])[1] as usize;
            let (z1, z2) = runs[i];
            for z in z1 as usize..z2 as usize {
                slab[z * side + y] = true;
            }
            i += 1;
        }
        for &v in &slab {
            enc.push(u8::from(v))?;
        }
    }
    enc.finish()
}

/// A number of the header in a form that reads back exactly and keeps the line short (header lines are
/// at most 256 bytes): its plain digits, or with an exponent where those would be long (`1e300`).
fn header_number(x: f64) -> String {
    let plain = x.to_string();
    if plain.len() <= 24 {
        plain
    } else {
        format!("{x:e}")
    }
}

struct RunEncoder<W: Write> {
    w: W,
    value: u8,
    count: u8,
}

impl<W: Write> RunEncoder<W> {
    fn push(&mut self, v: u8) -> std::io::Result<()> {
        if self.count > 0 && (v != self.value || self.count == 255) {
            self.w.write_all(&[self.value, self.count])?;
            self.count = 0;
        }
        self.value = v;
        self.count += 1;
        Ok(())
    }

    fn finish(mut self) -> std::io::Result<()> {
        if self.count > 0 {
            self.w.write_all(&[self.value, self.count])?;
        }
        self.w.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rays::ball_rays;
    use crate::stacking::paper::stack;

    fn sample() -> (KTree<3>, Vec<u8>) {
        let tree = stack(&ball_rays::<3>(4, [7, 8, 9], 6).unwrap());
        let mut bytes = Vec::new();
        write_binvox(&mut bytes, &tree, &GridMeta::default()).unwrap();
        (tree, bytes)
    }

    #[test]
    fn round_trip_and_the_voxel_order_of_the_format() {
        let (tree, bytes) = sample();
        assert_eq!(read_binvox(&bytes, "s", None, None).unwrap().tree, tree);
        // One voxel at binvox (x, y, z) = (1, 0, 0) in a 2³ grid: stream index x·4 = 4.
        let mut one = b"#binvox 1\ndim 2 2 2\ndata\n".to_vec();
        one.extend_from_slice(&[0, 4, 1, 1, 0, 3]);
        let t = read_binvox(&one, "one", None, None).unwrap().tree;
        assert!(t.contains([1, 0, 0]) && t.voxel_count() == 1);
        // y runs fastest: index 1 is (0, 1, 0); index 2 is (0, 0, 1).
        let mut two = b"#binvox 1\ndim 2 2 2\ndata\n".to_vec();
        two.extend_from_slice(&[0, 1, 1, 1, 0, 6]);
        assert!(read_binvox(&two, "two", None, None)
            .unwrap()
            .tree
            .contains([0, 1, 0]));
        let mut three = b"#binvox 1\ndim 2 2 2\ndata\n".to_vec();
        three.extend_from_slice(&[0, 2, 1, 1, 0, 5]);
        assert!(read_binvox(&three, "three", None, None)
            .unwrap()
            .tree
            .contains([0, 0, 1]));
    }

    #[test]
    fn a_grid_that_is_not_a_power_of_two_takes_the_next_level_or_the_one_asked_for() {
        let mut g = b"#binvox 1\ndim 3 3 3\ntranslate 1 2 3\nscale 6\ndata\n".to_vec();
        g.extend_from_slice(&[1, 27]);
        let p = read_binvox(&g, "g", None, None).unwrap();
        assert_eq!((p.tree.level(), p.tree.voxel_count()), (2, 27));
        assert_eq!(
            p.meta,
            GridMeta {
                voxel_size: 2.0,
                origin: [1.0, 2.0, 3.0]
            }
        );
        let p = read_binvox(&g, "g", Some([1, 0, 0]), Some(3)).unwrap();
        assert!(p.tree.contains([3, 2, 2]) && !p.tree.contains([0, 0, 0]));
        assert!(read_binvox(&g, "g", None, Some(1)).is_err());
    }

    #[test]
    fn bad_files_name_the_byte() {
        let (_, bytes) = sample();
        let data_at = bytes.windows(5).position(|w| w == b"data\n").unwrap() + 5;
        let e = read_binvox(&bytes[..bytes.len() - 1], "s", None, None).unwrap_err();
        assert!(matches!(e.kind, GridFileErrorKind::Truncated(_)), "{e}");
        let mut bad = bytes.clone();
        bad[data_at] = 7;
        let e = read_binvox(&bad, "s", None, None).unwrap_err();
        assert_eq!(e.offset(), Some(data_at as u64), "{e}");
        let mut bad = bytes.clone();
        bad[data_at + 1] = 0;
        assert_eq!(
            read_binvox(&bad, "s", None, None).unwrap_err().offset(),
            Some(data_at as u64 + 1)
        );
        let mut padded = bytes.clone();
        padded.extend_from_slice(&[0, 1]);
        assert!(read_binvox(&padded, "s", None, None).is_err());
        // A 100-byte file claiming a huge grid is refused before anything is allocated.
        let mut huge = b"#binvox 1\ndim 4096 4096 4096\ndata\n".to_vec();
        huge.resize(100, 1);
        let e = read_binvox(&huge, "huge", None, None).unwrap_err();
        assert!(matches!(e.kind, GridFileErrorKind::Truncated(_)), "{e}");
        for text in [
            "#binvox 2\n",
            "#binvox 1\ndim 2 3 2\ndata\n",
            "#binvox 1\ndata\n",
            "#binvox 1\nfoo\n",
        ] {
            assert!(
                read_binvox(text.as_bytes(), "h", None, None).is_err(),
                "{text}"
            );
        }
    }
}
