//! VTK files read back: the `.vtu` unstructured grid (a cell per full leaf: count, bounds, volume, and the
//! voxels its cells cover are the tree's) and the `.htg` hyper tree grid (its descriptor and mask decoded
//! breadth first give back the tree's voxels), for random quadtrees and octrees; for random valued trees
//! (`u8`, `u16`, `u32`, `i8`, `f32`, colours) the cell data `value` gives back every voxel's value.

use ktree::export::vtk::{
    write_htg, write_values_htg, write_values_time_slices, write_values_vtu, write_vtu,
};
use ktree::export::Frame;
use ktree::value::{Dtype, Rgb, Value};
use ktree::KTree;
use proptest::prelude::*;

/// The value of attribute `name` in `tag`.
fn attr<'a>(tag: &'a str, name: &str) -> &'a str {
    let key = format!(" {name}=\"");
    let start = tag
        .find(&key)
        .unwrap_or_else(|| panic!("no {name} in {tag}"))
        + key.len();
    &tag[start..start + tag[start..].find('"').unwrap()]
}

/// The `<DataArray …>` tag named `name` and its text (up to `</DataArray>`, empty for an appended one).
fn data_array<'a>(text: &'a str, name: &str) -> (&'a str, &'a str) {
    let key = format!("Name=\"{name}\"");
    let at = text.find(&key).unwrap_or_else(|| panic!("no array {name}"));
    let open = text[..at].rfind("<DataArray").unwrap();
    let close = open + text[open..].find('>').unwrap();
    let tag = &text[open..=close];
    if tag.ends_with("/>") {
        return (tag, "");
    }
    let end = close + text[close..].find("</DataArray>").unwrap();
    (tag, text[close + 1..end].trim())
}

/// An appended array's bytes (header UInt64).
fn appended<'a>(bytes: &'a [u8], text: &str, name: &str) -> &'a [u8] {
    let (tag, _) = data_array(text, name);
    let offset: usize = attr(tag, "offset").parse().unwrap();
    let marker = text.find("<AppendedData encoding=\"raw\">").unwrap();
    let base = marker + text[marker..].find('_').unwrap() + 1;
    let at = base + offset;
    let n = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
    &bytes[at + 8..at + 8 + n]
}

fn f64s(b: &[u8]) -> Vec<f64> {
    b.chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

fn i64s(b: &[u8]) -> Vec<i64> {
    b.chunks_exact(8)
        .map(|c| i64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

const FRAME: Frame = Frame {
    voxel_size: 0.5,
    origin: [1.0, -2.0, 4.0],
};

/// Reads a `.vtu` of a K-tree of `level` back into a dense array, checking its cells on the way.
fn vtu_voxels<const K: usize>(bytes: &[u8], level: u32) -> Vec<bool> {
    vtu_cells::<K>(bytes, level)
        .iter()
        .map(Option::is_some)
        .collect()
}

/// The cell of a `.vtu` of a K-tree of `level` that covers each voxel (a dense array), checking the cells.
fn vtu_cells<const K: usize>(bytes: &[u8], level: u32) -> Vec<Option<usize>> {
    let text = String::from_utf8_lossy(bytes);
    let piece = &text[text.find("<Piece").unwrap()..];
    let cells: usize = attr(piece, "NumberOfCells").parse().unwrap();
    let npoints: usize = attr(piece, "NumberOfPoints").parse().unwrap();
    let points = f64s(appended(bytes, &text, "Points"));
    assert_eq!(points.len(), 3 * npoints);
    let conn = i64s(appended(bytes, &text, "connectivity"));
    let offsets = i64s(appended(bytes, &text, "offsets"));
    let types = appended(bytes, &text, "types");
    let side = f64s(appended(bytes, &text, "side"));
    let lv: Vec<i32> = appended(bytes, &text, "level")
        .chunks_exact(4)
        .map(|c| i32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let corners = 1usize << K;
    assert_eq!(
        (offsets.len(), types.len(), side.len(), lv.len()),
        (cells, cells, cells, cells)
    );
    assert_eq!(conn.len(), cells * corners);
    let u = 1usize << level;
    let mut dense = vec![None; u.pow(K as u32)];
    for c in 0..cells {
        assert_eq!(offsets[c], ((c + 1) * corners) as i64);
        assert_eq!(types[c], if K == 3 { 11 } else { 8 });
        let p = |i: usize| {
            let id = conn[c * corners + i] as usize;
            [points[3 * id], points[3 * id + 1], points[3 * id + 2]]
        };
        let (lo, hi) = (p(0), p(corners - 1));
        // Voxel order: corner o at lo + side · bits of o.
        for o in 0..corners {
            for a in 0..3 {
                let want = if a < K && o >> a & 1 == 1 {
                    hi[a]
                } else {
                    lo[a]
                };
                assert_eq!(p(o)[a], want);
            }
        }
        let s = (hi[0] - lo[0]) / FRAME.voxel_size;
        assert_eq!(side[c], hi[0] - lo[0]);
        assert_eq!(s, (1u64 << (level - lv[c] as u32)) as f64);
        if K == 2 {
            assert_eq!(lo[2], FRAME.origin[2]);
        }
        let v0: Vec<usize> = (0..K)
            .map(|a| ((lo[a] - FRAME.origin[a]) / FRAME.voxel_size) as usize)
            .collect();
        let s = s as usize;
        for i in 0..s.pow(K as u32) {
            let mut index = 0;
            for a in (0..K).rev() {
                index = index * u + v0[a] + (i / s.pow(a as u32)) % s;
            }
            assert!(dense[index].is_none(), "cells overlap");
            dense[index] = Some(c);
        }
    }
    dense
}

/// Reads a `.htg` of a K-tree of `level` back into a dense array.
fn htg_voxels<const K: usize>(bytes: &[u8], level: u32) -> Vec<bool> {
    htg_vertices::<K>(bytes, level)
        .0
        .iter()
        .map(Option::is_some)
        .collect()
}

/// The unmasked leaf vertex of a `.htg` of a K-tree of `level` that covers each voxel (a dense array), and
/// whether each vertex is a leaf.
fn htg_vertices<const K: usize>(bytes: &[u8], level: u32) -> (Vec<Option<usize>>, Vec<bool>) {
    let text = String::from_utf8_lossy(bytes);
    let bits = |name: &str| -> Vec<bool> {
        data_array(&text, name)
            .1
            .split_whitespace()
            .map(|b| b == "1")
            .collect()
    };
    let descriptor = bits("Descriptors");
    let mask = bits("Mask");
    let per_depth: Vec<usize> = data_array(&text, "NumberOfVerticesPerDepth")
        .1
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(mask.len(), per_depth.iter().sum::<usize>());
    let (x, xs) = data_array(&text, "XCoordinates");
    assert_eq!(attr(x, "RangeMin").parse::<f64>().unwrap(), FRAME.origin[0]);
    let extent = FRAME.voxel_size * (1u64 << level) as f64;
    assert_eq!(
        xs,
        format!("{} {}", FRAME.origin[0], FRAME.origin[0] + extent)
    );
    let levels: Vec<i32> = data_array(&text, "level")
        .1
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(levels.len(), mask.len());
    // Breadth first: each refined node's children follow at the next depth, in order.
    let u = 1usize << level;
    let mut dense = vec![None; u.pow(K as u32)];
    let mut leaf = vec![false; mask.len()];
    let mut current: Vec<([usize; 3], usize)> = vec![([0; 3], u)];
    let mut index = 0;
    for (depth, &n) in per_depth.iter().enumerate() {
        assert_eq!(current.len(), n, "depth {depth}");
        let mut next = Vec::new();
        for &(origin, s) in &current {
            assert_eq!(levels[index], depth as i32);
            let refined = descriptor.get(index).copied().unwrap_or(false);
            if refined {
                for c in 0..1usize << K {
                    let mut o = origin;
                    for (a, oa) in o.iter_mut().enumerate().take(K) {
                        *oa += (c >> a & 1) * s / 2;
                    }
                    next.push((o, s / 2));
                }
            } else {
                leaf[index] = true;
                if !mask[index] {
                    for i in 0..s.pow(K as u32) {
                        let mut at = 0;
                        for a in (0..K).rev() {
                            at = at * u + origin[a] + (i / s.pow(a as u32)) % s;
                        }
                        dense[at] = Some(index);
                    }
                }
            }
            index += 1;
        }
        current = next;
    }
    assert!(current.is_empty());
    (dense, leaf)
}

fn dense_of<const K: usize>(tree: &KTree<K>) -> Vec<bool> {
    let u = 1usize << tree.level();
    let mut dense = vec![false; u.pow(K as u32)];
    for cell in tree.full_cells() {
        let s = cell.side() as usize;
        let o = cell.origin();
        for i in 0..s.pow(K as u32) {
            let mut at = 0;
            for a in (0..K).rev() {
                at = at * u + o[a] as usize + (i / s.pow(a as u32)) % s;
            }
            dense[at] = true;
        }
    }
    dense
}

fn check<const K: usize>(tree: &KTree<K>) {
    let mut vtu = Vec::new();
    write_vtu(&mut vtu, tree, &FRAME).unwrap();
    let back = vtu_voxels::<K>(&vtu, tree.level());
    assert_eq!(back, dense_of(tree), "vtu");
    let mut htg = Vec::new();
    write_htg(&mut htg, tree, &FRAME).unwrap();
    assert_eq!(htg_voxels::<K>(&htg, tree.level()), dense_of(tree), "htg");
}

fn random_tree<const K: usize>(level: u32, seed: u64, density: u64) -> KTree<K> {
    let n = 1usize << (K as u32 * level);
    let mut state = seed | 1;
    let dense: Vec<bool> = (0..n)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % 10 < density
        })
        .collect();
    KTree::<K>::from_dense(level, &dense).unwrap()
}

#[test]
fn a_ball_reads_back_with_its_cell_count_bounds_and_volume() {
    let tree = KTree::from_rays(&ktree::rays::ball_rays::<3>(4, [15, 17, 16], 90).unwrap());
    check(&tree);
    let mut vtu = Vec::new();
    write_vtu(&mut vtu, &tree, &FRAME).unwrap();
    let text = String::from_utf8_lossy(&vtu);
    let cells: usize = attr(&text, "NumberOfCells").parse().unwrap();
    assert_eq!(cells, tree.full_cells().count());
    let volume: f64 = f64s(appended(&vtu, &text, "side"))
        .iter()
        .map(|s| s * s * s)
        .sum();
    assert_eq!(volume, tree.voxel_count() as f64 * 0.125);
}

#[test]
fn the_empty_and_the_full_universe() {
    check(&KTree::<3>::from_dense(1, &[false; 8]).unwrap());
    check(&KTree::<3>::full(2).unwrap());
    check(&KTree::<2>::full(0).unwrap());
    let mut out = Vec::new();
    assert!(write_vtu(&mut out, &KTree::<1>::full(2).unwrap(), &FRAME).is_err());
    assert!(write_htg(&mut out, &KTree::<4>::full(1).unwrap(), &FRAME).is_err());
}

/// Random values of a type: a few distinct ones, so that full nodes merge.
trait Sample: Value {
    fn sample(r: u64) -> Self;
}

impl Sample for u8 {
    fn sample(r: u64) -> Self {
        (r % 4) as u8 * 85
    }
}

impl Sample for u16 {
    fn sample(r: u64) -> Self {
        (r % 3) as u16 * 30_000
    }
}

impl Sample for u32 {
    fn sample(r: u64) -> Self {
        (r % 3) as u32 * 2_000_000_000
    }
}

impl Sample for i8 {
    fn sample(r: u64) -> Self {
        [-128, -1, 0, 127][(r % 4) as usize]
    }
}

impl Sample for f32 {
    fn sample(r: u64) -> Self {
        [0.0, -0.0, 0.1, -3.5e-20, 1.0e30, f32::INFINITY][(r % 6) as usize]
    }
}

impl Sample for Rgb {
    fn sample(r: u64) -> Self {
        [[255, 0, 0], [0, 128, 255], [1, 2, 3]][(r % 3) as usize]
    }
}

/// A random dense array of a K-tree of `level`: `density` tenths of the voxels hold a value.
fn random_values<const K: usize, V: Sample>(level: u32, seed: u64, density: u64) -> Vec<Option<V>> {
    let n = 1usize << (K as u32 * level);
    let mut state = seed | 1;
    (0..n)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % 10 < density).then(|| V::sample(state / 10))
        })
        .collect()
}

/// The VTK type and component count `value` must have.
fn vtk_type(dtype: Dtype) -> (&'static str, usize) {
    match dtype {
        Dtype::U8 => ("UInt8", 1),
        Dtype::U16 => ("UInt16", 1),
        Dtype::U32 => ("UInt32", 1),
        Dtype::I8 => ("Int8", 1),
        Dtype::F32 => ("Float32", 1),
        Dtype::Rgb => ("UInt8", 3),
    }
}

/// Checks the `value` tag's type and components.
fn check_value_tag<V: Value>(text: &str) {
    let (tag, _) = data_array(text, "value");
    let (kind, components) = vtk_type(V::DTYPE.unwrap());
    assert_eq!(attr(tag, "type"), kind);
    if components > 1 {
        assert_eq!(attr(tag, "NumberOfComponents"), components.to_string());
    } else {
        assert!(!tag.contains("NumberOfComponents") || attr(tag, "NumberOfComponents") == "1");
    }
    assert!(text.contains("<CellData Scalars=\"value\">"));
}

/// A value of the `.htg`'s ASCII components, as the little-endian bytes the value type reads.
fn htg_value<V: Value>(components: &[&str]) -> V {
    let mut bytes = Vec::new();
    for c in components {
        match V::DTYPE.unwrap() {
            Dtype::U8 | Dtype::Rgb => bytes.push(c.parse::<u8>().unwrap()),
            Dtype::I8 => bytes.extend(c.parse::<i8>().unwrap().to_le_bytes()),
            Dtype::U16 => bytes.extend(c.parse::<u16>().unwrap().to_le_bytes()),
            Dtype::U32 => bytes.extend(c.parse::<u32>().unwrap().to_le_bytes()),
            Dtype::F32 => bytes.extend(c.parse::<f32>().unwrap().to_le_bytes()),
        }
    }
    V::read_le(&bytes)
}

/// Writes a valued tree of `dense` as `.vtu` and `.htg`, reads each voxel's value back from the cell data
/// `value` and compares it (bit for bit) with `dense`; the `.htg`'s vertices without a value (with
/// children, or masked) hold NaN (`float32`) or 0.
fn check_values<const K: usize, V: Value>(level: u32, dense: &[Option<V>]) {
    let tree = KTree::<K, V>::from_dense_values(level, dense).unwrap();
    let same = |a: Option<V>, b: Option<V>| a.map(Value::key) == b.map(Value::key);
    let size = V::DTYPE.unwrap().bytes();
    // .vtu: each voxel's cell, the cell's value.
    let mut vtu = Vec::new();
    write_values_vtu(&mut vtu, &tree, &FRAME).unwrap();
    let text = String::from_utf8_lossy(&vtu);
    check_value_tag::<V>(&text);
    let values: Vec<V> = appended(&vtu, &text, "value")
        .chunks_exact(size)
        .map(V::read_le)
        .collect();
    let cells = vtu_cells::<K>(&vtu, level);
    assert_eq!(
        values.len(),
        attr(&text, "NumberOfCells").parse::<usize>().unwrap()
    );
    for (i, (cell, want)) in cells.iter().zip(dense).enumerate() {
        assert!(same(cell.map(|c| values[c]), *want), "vtu voxel {i}");
    }
    // .htg: each voxel's leaf vertex, the vertex's value.
    let mut htg = Vec::new();
    write_values_htg(&mut htg, &tree, &FRAME).unwrap();
    let text = String::from_utf8_lossy(&htg);
    check_value_tag::<V>(&text);
    let (tag, numbers) = data_array(&text, "value");
    let components = vtk_type(V::DTYPE.unwrap()).1;
    let tokens: Vec<&str> = numbers.split_whitespace().collect();
    let values: Vec<V> = tokens
        .chunks_exact(components)
        .map(htg_value::<V>)
        .collect();
    let (vertices, leaf) = htg_vertices::<K>(&htg, level);
    assert_eq!(values.len(), leaf.len());
    assert_eq!(attr(tag, "NumberOfTuples"), leaf.len().to_string());
    for (i, (vertex, want)) in vertices.iter().zip(dense).enumerate() {
        assert!(same(vertex.map(|v| values[v]), *want), "htg voxel {i}");
    }
    let mut covering = vec![false; leaf.len()];
    for v in vertices.iter().flatten() {
        covering[*v] = true;
    }
    let none = V::read_le(&if V::DTYPE == Some(Dtype::F32) {
        f32::NAN.to_le_bytes().to_vec()
    } else {
        vec![0; size]
    });
    for (v, value) in values.iter().enumerate() {
        if !covering[v] {
            assert!(same(Some(*value), Some(none)), "vertex {v} without a value");
        }
    }
}

/// A 4-D valued tree as a time series: along every axis, the `.vtu` of slice `t` gives each voxel of the
/// dense array at `t` its value, and the `.pvd` lists the slices in order.
#[test]
fn a_4d_tree_with_values_goes_out_slice_by_slice() {
    let level = 2;
    let dense = random_values::<4, u16>(level, 11, 6);
    let tree = KTree::<4, u16>::from_dense_values(level, &dense).unwrap();
    let side = 1u32 << level;
    let dir = tempfile::tempdir().unwrap();
    for axis in 0..4 {
        let pvd = dir.path().join(format!("run{axis}.pvd"));
        let files = write_values_time_slices(&pvd, &tree, axis, &FRAME).unwrap();
        assert_eq!(files.len(), side as usize + 1);
        let collection = std::fs::read_to_string(&pvd).unwrap();
        for t in 0..side {
            let bytes = std::fs::read(&files[t as usize]).unwrap();
            let text = String::from_utf8_lossy(&bytes);
            check_value_tag::<u16>(&text);
            let name = files[t as usize].file_name().unwrap().to_str().unwrap();
            assert!(collection.contains(&format!(
                "timestep=\"{t}\" group=\"\" part=\"0\" file=\"{name}\""
            )));
            let values: Vec<u16> = appended(&bytes, &text, "value")
                .chunks_exact(2)
                .map(u16::read_le)
                .collect();
            let cells = vtu_cells::<3>(&bytes, level);
            for (i, cell) in cells.iter().enumerate() {
                let q = [
                    i as u32 % side,
                    i as u32 / side % side,
                    i as u32 / side / side,
                ];
                let p: [u32; 4] = std::array::from_fn(|a| match a.cmp(&axis) {
                    std::cmp::Ordering::Less => q[a],
                    std::cmp::Ordering::Equal => t,
                    std::cmp::Ordering::Greater => q[a - 1],
                });
                let at = p
                    .iter()
                    .rev()
                    .fold(0usize, |n, &c| n * side as usize + c as usize);
                assert_eq!(
                    cell.map(|c| values[c]),
                    dense[at],
                    "axis {axis}, t {t}, voxel {i}"
                );
            }
        }
    }
}

#[test]
fn values_of_every_type_read_back() {
    fn all<const K: usize>(level: u32, seed: u64) {
        check_values::<K, u8>(level, &random_values::<K, u8>(level, seed, 7));
        check_values::<K, u16>(level, &random_values::<K, u16>(level, seed, 7));
        check_values::<K, u32>(level, &random_values::<K, u32>(level, seed, 7));
        check_values::<K, i8>(level, &random_values::<K, i8>(level, seed, 7));
        check_values::<K, f32>(level, &random_values::<K, f32>(level, seed, 7));
        check_values::<K, Rgb>(level, &random_values::<K, Rgb>(level, seed, 7));
    }
    for seed in 1..4 {
        all::<2>(3, seed);
        all::<3>(2, seed);
    }
    // One value everywhere, none at all, a single voxel.
    check_values::<3, f32>(2, &[Some(0.25); 64]);
    check_values::<2, Rgb>(2, &[None; 16]);
    check_values::<3, u8>(0, &[Some(9)]);
    let mut out = Vec::new();
    let line = KTree::<1, u8>::from_dense_values(1, &[Some(1), None]).unwrap();
    assert!(write_values_vtu(&mut out, &line, &FRAME).is_err());
    assert!(write_values_htg(&mut out, &line, &FRAME).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_valued_octrees_read_back(level in 0u32..=3, seed in any::<u64>(), density in 0u64..=10) {
        check_values::<3, u8>(level, &random_values::<3, u8>(level, seed, density));
        check_values::<3, f32>(level, &random_values::<3, f32>(level, seed, density));
        check_values::<3, Rgb>(level, &random_values::<3, Rgb>(level, seed, density));
    }

    #[test]
    fn random_valued_quadtrees_read_back(level in 0u32..=4, seed in any::<u64>(), density in 0u64..=10) {
        check_values::<2, u8>(level, &random_values::<2, u8>(level, seed, density));
        check_values::<2, f32>(level, &random_values::<2, f32>(level, seed, density));
        check_values::<2, Rgb>(level, &random_values::<2, Rgb>(level, seed, density));
    }

    #[test]
    fn random_octrees_read_back(level in 1u32..=3, seed in any::<u64>(), density in 0u64..=10) {
        check(&random_tree::<3>(level, seed, density));
    }

    #[test]
    fn random_quadtrees_read_back(level in 1u32..=4, seed in any::<u64>(), density in 0u64..=10) {
        check(&random_tree::<2>(level, seed, density));
    }
}
