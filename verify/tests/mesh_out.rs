//! The boundary of an octree as a triangle mesh: closed (every edge in exactly two triangles, once each
//! way), each vertex's triangles one fan, the volume by the divergence theorem exactly the voxel count,
//! the Euler characteristic twice the solid's (counted from a dense array, face-adjacent voxels
//! connected), and voxelizing the written file at the same level gives back the same tree — on random
//! small trees and on named cases (solids touching along an edge, at a corner, a cube with a hole). Also
//! quadtree outlines (area, loops against the Euler characteristic) and the files' own structure.

use std::collections::HashMap;

use ktree::export::outline::{boundary_loops, signed_area};
use ktree::export::surface::{boundary_mesh, SurfaceMesh};
use ktree::export::{write_mesh, Frame};
use ktree::solid::mesh::MeshTransform;
use ktree::{AnyTree, KTree};
use proptest::prelude::*;

/// A dense array of side `2^level` (axis 0 fastest) with the listed voxels full.
fn dense_of(level: u32, voxels: &[[usize; 3]]) -> Vec<bool> {
    let u = 1usize << level;
    let mut d = vec![false; u * u * u];
    for v in voxels {
        d[v[0] + u * (v[1] + u * v[2])] = true;
    }
    d
}

/// The Euler characteristic of the voxels of `dense` with face-adjacent voxels connected: of the cubical
/// complex whose vertices are the full voxels (voxels − face-adjacent pairs + full 2×2 squares − full
/// 2×2×2 blocks), with the ring of six full voxels around a corner where only two opposite voxels are
/// empty filled by a hexagon (+1).
fn euler_6(level: u32, dense: &[bool]) -> i64 {
    let u = 1i64 << level;
    let at = |x: i64, y: i64, z: i64| {
        (0..u).contains(&x)
            && (0..u).contains(&y)
            && (0..u).contains(&z)
            && dense[(x + u * (y + u * z)) as usize]
    };
    let mut chi = 0;
    for z in 0..u {
        for y in 0..u {
            for x in 0..u {
                // Where two empty voxels touch only at a corner amid six full ones, the surface can
                // only be two sheets: the six are joined through the corner (a hexagon filling their
                // ring in the complex).
                for e in 0usize..4 {
                    let full = (0..8usize).filter(|&o| {
                        at(
                            x + (o & 1) as i64,
                            y + (o >> 1 & 1) as i64,
                            z + (o >> 2 & 1) as i64,
                        )
                    });
                    let empty: Vec<usize> = (0..8usize)
                        .filter(|&o| {
                            !at(
                                x + (o & 1) as i64,
                                y + (o >> 1 & 1) as i64,
                                z + (o >> 2 & 1) as i64,
                            )
                        })
                        .collect();
                    if full.count() == 6 && empty == [e, 7 - e] {
                        chi += 1;
                    }
                }
                // Each block of 2^k voxels spanning the axes in `mask` from (x, y, z).
                for mask in 0..8usize {
                    let all = (0..8usize).filter(|o| o & !mask == 0).all(|o| {
                        at(
                            x + (o & 1) as i64,
                            y + (o >> 1 & 1) as i64,
                            z + (o >> 2 & 1) as i64,
                        )
                    });
                    if all {
                        chi += if mask.count_ones() % 2 == 0 { 1 } else { -1 };
                    }
                }
            }
        }
    }
    chi
}

/// The checks on a mesh in voxel units of a tree of `voxels` voxels; returns its Euler characteristic.
fn check_mesh(mesh: &SurfaceMesh, voxels: u128) -> i64 {
    let chi = check_closed_exact(mesh, voxels);
    assert_eq!(mesh.volume(), voxels as f64);
    chi
}

/// [`check_mesh`] but for the volume in floating point (which rounds for coordinates near 2^21).
fn check_closed_exact(mesh: &SurfaceMesh, voxels: u128) -> i64 {
    // Closed and consistently wound: each directed edge once, and its reverse once.
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &mesh.triangles {
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
            "degenerate {t:?}"
        );
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "edge {a}→{b} in {n} triangles the same way");
        assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}→{b} has no twin");
    }
    // Each vertex's triangles are one fan: the edges opposite it form one cycle.
    let mut opposite: HashMap<u32, HashMap<u32, u32>> = HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let prev = opposite
                .entry(t[k])
                .or_default()
                .insert(t[(k + 1) % 3], t[(k + 2) % 3]);
            assert!(prev.is_none(), "vertex {} is not a fan", t[k]);
        }
    }
    for (v, link) in &opposite {
        let start = *link.keys().next().unwrap();
        let (mut x, mut steps) = (start, 0);
        loop {
            x = link[&x];
            steps += 1;
            if x == start {
                break;
            }
            assert!(steps <= link.len(), "vertex {v}: open link");
        }
        assert_eq!(steps, link.len(), "vertex {v}: more than one fan");
    }
    assert_eq!(
        opposite.len(),
        mesh.vertices.len(),
        "a vertex in no triangle"
    );
    // No triangle of zero area.
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        assert!(n.iter().any(|&x| x != 0.0), "flat triangle {t:?}");
    }
    // Volume, exactly: vertices are multiples of ½, so 48·V is the sum of integer determinants.
    let twice = |i: u32| mesh.vertices[i as usize].map(|x| (2.0 * x) as i128);
    let six_v8: i128 = mesh
        .triangles
        .iter()
        .map(|t| {
            let (a, b, c) = (twice(t[0]), twice(t[1]), twice(t[2]));
            a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0])
        })
        .sum();
    assert_eq!(six_v8, 48 * voxels as i128, "volume");
    let edges = directed.len() as i64 / 2;
    mesh.vertices.len() as i64 - edges + mesh.triangles.len() as i64
}

/// Writes the tree's mesh as `name` placed by `frame`, reads it back with the mesh voxelizer and checks
/// the same tree comes back.
fn round_trip(tree: &KTree<3>, name: &str, frame: &Frame) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    write_mesh(&path, &AnyTree::K3(tree.clone()), frame).unwrap();
    if tree.voxel_count() == 0 {
        return; // no triangle: not a mesh the reader takes
    }
    let mesh = ktree::io::read_mesh(&path).unwrap();
    assert_eq!(mesh.open_edges(), 0, "{name}");
    let s = 1.0 / frame.voxel_size;
    let placement = MeshTransform {
        scale: s,
        translate: frame.origin.map(|o| -o * s),
    };
    let rays = mesh.to_rays(tree.level(), &placement).unwrap();
    assert_eq!(rays.open_edges, 0);
    let back = KTree::from_rays(&rays.rays);
    assert_eq!(back, *tree, "{name}: voxelized back");
}

/// Every check on the tree of `dense`.
fn check_dense(level: u32, dense: &[bool]) -> SurfaceMesh {
    let tree = KTree::<3>::from_dense(level, dense).unwrap();
    let mesh = boundary_mesh(&tree);
    let chi = check_mesh(&mesh, tree.voxel_count());
    assert_eq!(chi, 2 * euler_6(level, dense), "Euler characteristic");
    round_trip(&tree, "t.ply", &Frame::default());
    mesh
}

#[test]
fn one_voxel_and_a_block_are_boxes_of_twelve_triangles() {
    for (level, voxels) in [
        (1, vec![[0, 0, 0]]),
        (2, vec![[1, 2, 3]]),
        (
            1,
            (0..8)
                .map(|o| [o & 1, o >> 1 & 1, o >> 2])
                .collect::<Vec<_>>(),
        ),
    ] {
        let mesh = check_dense(level, &dense_of(level, &voxels));
        assert_eq!((mesh.vertices.len(), mesh.triangles.len()), (8, 12));
    }
}

#[test]
fn cubes_touching_at_an_edge_are_two_spheres() {
    let dense = dense_of(2, &[[0, 0, 0], [1, 1, 0]]);
    let mesh = check_dense(2, &dense);
    assert_eq!(euler_6(2, &dense), 2);
    assert_eq!(mesh.volume(), 2.0);
    // Along the shared edge: both cubes' own vertices, plus a midpoint each.
    let on_edge = mesh
        .vertices
        .iter()
        .filter(|v| v[0] == 1.0 && v[1] == 1.0)
        .count();
    assert_eq!(on_edge, 6);
}

#[test]
fn cubes_touching_at_a_corner_are_two_spheres() {
    let dense = dense_of(2, &[[0, 0, 0], [1, 1, 1]]);
    check_dense(2, &dense);
    assert_eq!(euler_6(2, &dense), 2);
    let mesh = boundary_mesh(&KTree::<3>::from_dense(2, &dense).unwrap());
    assert_eq!(mesh.vertices.len(), 16);
}

#[test]
fn a_cube_with_a_hole_is_a_torus() {
    let mut voxels = Vec::new();
    for z in 0..3 {
        for y in 0..3 {
            for x in 0..3 {
                if (x, y) != (1, 1) {
                    voxels.push([x, y, z]);
                }
            }
        }
    }
    let dense = dense_of(2, &voxels);
    assert_eq!(euler_6(2, &dense), 0);
    check_dense(2, &dense);
}

#[test]
fn a_ring_pinched_along_an_edge_is_a_torus() {
    // Eight voxels in a loop; two of them touch along an edge whose both ends join the same sheet.
    let dense = dense_of(
        2,
        &[
            [0, 0, 1],
            [0, 0, 0],
            [1, 0, 0],
            [1, 1, 0],
            [1, 1, 1],
            [1, 1, 2],
            [1, 0, 2],
            [0, 0, 2],
        ],
    );
    assert_eq!(euler_6(2, &dense), 0);
    check_dense(2, &dense);
}

#[test]
fn two_empty_voxels_at_a_corner_amid_full_ones_split_the_sheet() {
    // A 2 × 2 × 2 block at (1, 1, 1) without its voxels (1, 1, 1) and (2, 2, 2), which touch at a corner.
    let voxels: Vec<[usize; 3]> = (0..8)
        .map(|o| [1 + (o & 1), 1 + (o >> 1 & 1), 1 + (o >> 2)])
        .filter(|v| *v != [1, 1, 1] && *v != [2, 2, 2])
        .collect();
    let dense = dense_of(2, &voxels);
    assert_eq!(euler_6(2, &dense), 1);
    let mesh = check_dense(2, &dense);
    let at_corner = mesh
        .vertices
        .iter()
        .filter(|v| **v == [2.0, 2.0, 2.0])
        .count();
    assert_eq!(at_corner, 2);
}

#[test]
fn big_leaves_beside_small_ones_leave_no_crack() {
    // A 4³ block with one corner voxel taken away and one voxel added beside it: large faces meet small ones.
    let mut voxels = Vec::new();
    for z in 0..4 {
        for y in 0..4 {
            for x in 0..4 {
                if (x, y, z) != (3, 3, 3) {
                    voxels.push([x, y, z]);
                }
            }
        }
    }
    voxels.push([4, 1, 2]);
    voxels.push([1, 4, 1]);
    let level = 3;
    let dense = dense_of(level, &voxels);
    let mesh = check_dense(level, &dense);
    // Merged: far fewer triangles than two per unit face.
    assert!(mesh.triangles.len() < 100, "{}", mesh.triangles.len());
}

#[test]
fn a_ball_round_trips_through_every_format_in_world_units() {
    let tree = KTree::from_rays(&ktree::rays::ball_rays::<3>(4, [16, 16, 16], 100).unwrap());
    let mesh = boundary_mesh(&tree);
    let chi = check_mesh(&mesh, tree.voxel_count());
    assert_eq!(chi, 2);
    let frame = Frame {
        voxel_size: 0.25,
        origin: [1.0, -2.0, 3.5],
    };
    for name in ["ball.ply", "ball.obj", "ball.stl"] {
        round_trip(&tree, name, &frame);
    }
    assert_eq!(
        mesh.placed(&frame).volume(),
        tree.voxel_count() as f64 / 64.0
    );
}

#[test]
fn far_corners_of_the_largest_universe() {
    // At L = 21 lattice coordinates reach 2^21: voxels at both corners, two touching along an edge on the
    // universe's middle planes, and a large cell with a voxel on one face.
    let level = ktree::max_level(3);
    let u = ktree::Universe::<3>::new(level).unwrap();
    let (top, mid) = ((1u32 << level) - 1, 1u32 << (level - 1));
    let voxel = |p: [u32; 3]| u.cell(p, level).unwrap();
    let cells = [
        voxel([0, 0, 0]),
        voxel([top, top, top]),
        voxel([mid - 1, mid - 1, 5]),
        voxel([mid, mid, 5]),
        u.cell([mid, 0, 0], 2).unwrap(),
        voxel([mid + 5, mid >> 1, 7]),
    ];
    let tree = KTree::from_cells(u, &cells).unwrap();
    let mesh = boundary_mesh(&tree);
    // Five solids (the two touching along an edge are apart, as in 6-connectivity): χ = 2 · 5.
    assert_eq!(check_closed_exact(&mesh, tree.voxel_count()), 10);
    let corner = mesh
        .vertices
        .iter()
        .filter(|v| v[0] == f64::from(top) + 1.0);
    assert_eq!(corner.count(), 4);
}

#[test]
fn the_empty_and_the_full_universe() {
    let empty = KTree::<3>::from_dense(2, &[false; 64]).unwrap();
    assert!(boundary_mesh(&empty).triangles.is_empty());
    round_trip(&empty, "empty.ply", &Frame::default());
    let full = KTree::<3>::full(3).unwrap();
    let mesh = boundary_mesh(&full);
    assert_eq!(mesh.triangles.len(), 12);
    check_mesh(&mesh, 512);
    round_trip(&full, "full.glb.ply", &Frame::default());
}

#[test]
fn glb_holds_the_mesh_in_its_chunks() {
    let tree = KTree::<3>::from_dense(2, &dense_of(2, &[[0, 0, 0], [1, 1, 1], [1, 1, 2]])).unwrap();
    let mesh = boundary_mesh(&tree);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.glb");
    let written = write_mesh(&path, &AnyTree::K3(tree), &Frame::default()).unwrap();
    assert_eq!(written.elements, mesh.triangles.len());
    let bytes = std::fs::read(&path).unwrap();
    let word = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(word(4), 2);
    assert_eq!(word(8), bytes.len());
    let json_len = word(12);
    assert_eq!(&bytes[16..20], b"JSON");
    assert_eq!(json_len % 4, 0);
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin = 20 + json_len;
    assert_eq!(&bytes[bin + 4..bin + 8], b"BIN\0");
    assert_eq!(word(bin), bytes.len() - bin - 8);
    assert_eq!(json["accessors"][0]["count"], mesh.vertices.len());
    assert_eq!(json["accessors"][1]["count"], 3 * mesh.triangles.len());
    assert_eq!(word(bin), 12 * (mesh.vertices.len() + mesh.triangles.len()));
    // The first index chunk matches the first triangle.
    let indices = bin + 8 + 12 * mesh.vertices.len();
    assert_eq!(word(indices), mesh.triangles[0][0] as usize);
}

#[test]
fn a_quadtree_is_written_as_outlines_and_an_octree_not_as_svg() {
    let dir = tempfile::tempdir().unwrap();
    let square = AnyTree::K2(KTree::<2>::from_dense(1, &[true, false, false, true]).unwrap());
    for name in ["q.ply", "q.obj", "q.svg"] {
        let w = write_mesh(&dir.path().join(name), &square, &Frame::default()).unwrap();
        assert_eq!((w.vertices, w.elements), (8, 8), "{name}");
    }
    let svg = std::fs::read_to_string(dir.path().join("q.svg")).unwrap();
    assert_eq!(svg.matches('M').count(), 2);
    let ply = std::fs::read(dir.path().join("q.ply")).unwrap();
    assert!(ply.windows(14).any(|w| w == b"element edge 8"));
    let cube = AnyTree::K3(KTree::<3>::full(1).unwrap());
    let err = write_mesh(&dir.path().join("c.svg"), &cube, &Frame::default()).unwrap_err();
    assert!(err.to_string().contains("c.svg"), "{err}");
    assert!(write_mesh(&dir.path().join("q.stl"), &square, &Frame::default()).is_err());
    let line = AnyTree::K1(KTree::<1>::full(2).unwrap());
    assert!(write_mesh(&dir.path().join("l.ply"), &line, &Frame::default()).is_err());
}

/// The Euler characteristic of a quadtree's pixels, edge-adjacent pixels connected.
fn euler_4(level: u32, dense: &[bool]) -> i64 {
    let u = 1i64 << level;
    let at =
        |x: i64, y: i64| (0..u).contains(&x) && (0..u).contains(&y) && dense[(x + u * y) as usize];
    let mut chi = 0;
    for y in 0..u {
        for x in 0..u {
            chi += i64::from(at(x, y))
                - i64::from(at(x, y) && at(x + 1, y))
                - i64::from(at(x, y) && at(x, y + 1))
                + i64::from(at(x, y) && at(x + 1, y) && at(x, y + 1) && at(x + 1, y + 1));
        }
    }
    chi
}

fn check_outline(level: u32, dense: &[bool]) {
    let tree = KTree::<2>::from_dense(level, dense).unwrap();
    let loops = boundary_loops(&tree);
    let area: f64 = loops.iter().map(|l| signed_area(l)).sum();
    assert_eq!(area, tree.voxel_count() as f64);
    let outer = loops.iter().filter(|l| signed_area(l) > 0.0).count() as i64;
    assert_eq!(outer - (loops.len() as i64 - outer), euler_4(level, dense));
    for l in &loops {
        // Axis-aligned, corners only: consecutive edges turn.
        let n = l.len();
        assert!(n >= 4);
        for i in 0..n {
            let (p, q, r) = (l[i], l[(i + 1) % n], l[(i + 2) % n]);
            let d1 = [q[0] - p[0], q[1] - p[1]];
            let d2 = [r[0] - q[0], r[1] - q[1]];
            assert!(d1[0] == 0.0 || d1[1] == 0.0);
            assert_eq!(d1[0] * d2[0] + d1[1] * d2[1], 0.0, "not a corner");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn random_octrees_give_closed_exact_meshes(
        level in 2u32..=3,
        seed in any::<u64>(),
        density in 1u32..=9,
    ) {
        let n = 1usize << (3 * level);
        let mut state = seed | 1;
        let dense: Vec<bool> = (0..n)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state % 10) < u64::from(density)
            })
            .collect();
        check_dense(level, &dense);
    }

    #[test]
    fn unions_and_differences_of_boxes_give_closed_exact_meshes(
        level in 3u32..=5,
        boxes in prop::collection::vec(
            (any::<bool>(), prop::array::uniform3(0usize..32), prop::array::uniform3(1usize..24)),
            1..8,
        ),
    ) {
        // Boxes of every size, added and cut out in turn: leaves of many sizes side by side, with
        // T-junctions, holes and edge and corner contacts.
        let u = 1usize << level;
        let mut dense = vec![false; u * u * u];
        for (add, corner, size) in boxes {
            let lo = corner.map(|c| c % u);
            let hi: [usize; 3] = std::array::from_fn(|a| (lo[a] + size[a]).min(u));
            for z in lo[2]..hi[2] {
                for y in lo[1]..hi[1] {
                    for x in lo[0]..hi[0] {
                        dense[x + u * (y + u * z)] = add;
                    }
                }
            }
        }
        check_dense(level, &dense);
    }

    #[test]
    fn random_quadtrees_give_closed_outlines(
        level in 1u32..=4,
        cells in proptest::collection::vec(any::<bool>(), 256),
    ) {
        let n = 1usize << (2 * level);
        check_outline(level, &cells[..n]);
    }
}

#[test]
fn smooth_meshes_are_closed_near_the_voxels_volume_and_not_the_exact_mesh() {
    use ktree::export::surface::smooth_mesh;
    for level in [4u32, 5, 6] {
        let u = 1i64 << level;
        let tree = KTree::from_rays(&ktree::rays::ball_rays::<3>(level, [u, u, u], u).unwrap());
        let voxels = tree.voxel_count() as f64;
        let exact = boundary_mesh(&tree);
        let smooth = smooth_mesh(&tree, 10).unwrap();
        // Closed and consistently wound: each directed edge once, and its reverse once.
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for t in &smooth.triangles {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &directed {
            assert_eq!(n, 1);
            assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}→{b} has no twin");
        }
        // Within 1 % of the voxel count (the ball's own volume, nearly); not the staircase.
        let volume = smooth.volume();
        assert!(
            (volume - voxels).abs() < 0.01 * voxels,
            "L = {level}: {volume} for {voxels}"
        );
        assert!(smooth
            .vertices
            .iter()
            .any(|v| v.iter().any(|x| (2.0 * x).fract() != 0.0)));
        assert_ne!(smooth.triangles.len(), exact.triangles.len());
        // Every vertex within half a voxel of the exact surface's lattice.
        let (lo, hi) = exact.bounds().unwrap();
        let (slo, shi) = smooth.bounds().unwrap();
        for a in 0..3 {
            assert!(slo[a] >= lo[a] - 0.5 && shi[a] <= hi[a] + 0.5);
        }
    }
    // Solids touching along an edge stay two closed sheets.
    let tree = KTree::<3>::from_dense(2, &dense_of(2, &[[0, 0, 0], [1, 1, 0]])).unwrap();
    let smooth = smooth_mesh(&tree, 5).unwrap();
    assert!(smooth.volume() > 0.0);
    assert_eq!(smooth.triangles.len() % 2, 0);
}
