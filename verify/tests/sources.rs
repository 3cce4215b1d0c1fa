//! Meshes, volumes and ray files produce their rays slab by slab: for every split depth, the runs of each
//! slab equal that slab of the whole ray set made today, the occupied slabs include every slab with runs,
//! and the out-of-core build from the source writes, byte for byte, the file of the tree stacked in memory
//! from the whole set (random small meshes, volumes and ray files, and the meshes and volumes of data/).

use ktree::io::write_ktree_v2;
use ktree::solid::mesh::{MeshSource, Placement, TriangleMesh};
use ktree::solid::volume::{Select, Volume, VolumeSource};
use ktree::stacking::{stack, stack_to_file, OutOfCore, RaySource};
use ktree::RaySet;
use ktree_verify::cases;
use proptest::prelude::*;

/// Every slab of every width has the runs of the whole set, and the occupied slabs hold them all.
fn slabs_agree<const K: usize, S>(source: &S, whole: &RaySet<K>) -> Result<(), TestCaseError>
where
    S: RaySource<K>,
    S::Error: std::fmt::Debug,
{
    let level = whole.level();
    prop_assert_eq!(source.universe(), whole.universe());
    for m in 0..=level {
        let side = 1u32 << (level - m);
        let occupied = source.occupied_slabs(m);
        prop_assert!(occupied.windows(2).all(|w| w[0] < w[1]), "depth {}", m);
        for b in 0..1u32 << m {
            let x = b * side..(b + 1) * side;
            let slab = source.slab(x.clone()).unwrap();
            let r = whole.slab_range(x);
            prop_assert!(
                slab.keys[..] == whole.column_keys()[r.clone()]
                    && slab.runs[..] == whole.runs()[r.clone()],
                "depth {}, slab {}: the source's runs differ from the whole set's",
                m,
                b
            );
            prop_assert!(
                r.is_empty() || occupied.contains(&b),
                "depth {}, slab {} not listed",
                m,
                b
            );
        }
    }
    Ok(())
}

/// The out-of-core build from the source writes the bytes of the whole set's tree built in memory.
fn file_agrees<const K: usize, S>(
    source: &S,
    whole: &RaySet<K>,
    depths: impl IntoIterator<Item = u32>,
) -> Result<(), TestCaseError>
where
    S: RaySource<K>,
    S::Error: std::fmt::Display,
{
    let mut expected = Vec::new();
    write_ktree_v2(&mut expected, &stack(whole)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tree.ktree");
    for depth in depths {
        stack_to_file(source, &out, &OutOfCore::new(depth, u64::MAX), &|_| {})
            .map_err(|e| TestCaseError::fail(format!("depth {depth}: {e}")))?;
        prop_assert!(
            std::fs::read(&out).unwrap() == expected,
            "depth {}: the file differs from the in-memory build's",
            depth
        );
    }
    Ok(())
}

/// A triangle soup (open or closed, crossing the universe's faces) with vertices on a half-voxel grid, so
/// that columns run through vertices and along edges.
fn soups() -> impl Strategy<Value = TriangleMesh> {
    (
        prop::collection::vec(prop::array::uniform3(-4i32..40), 3..12),
        prop::collection::vec(prop::array::uniform3(0u32..12), 1..16),
    )
        .prop_map(|(v, t)| {
            let n = v.len() as u32;
            let vertices = v.iter().map(|p| p.map(|c| f64::from(c) / 2.0)).collect();
            let triangles = t.iter().map(|t| t.map(|i| i % n)).collect();
            TriangleMesh::new(vertices, triangles).unwrap()
        })
}

/// The box [lo, hi]³, outward oriented (closed).
fn cube(lo: [f64; 3], hi: [f64; 3]) -> TriangleMesh {
    let vertices: Vec<[f64; 3]> = (0..8)
        .map(|i| [0, 1, 2].map(|a| if i >> a & 1 == 1 { hi[a] } else { lo[a] }))
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let triangles = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    TriangleMesh::new(vertices, triangles).unwrap()
}

fn mesh_agrees(
    mesh: &TriangleMesh,
    level: u32,
    placement: &Placement,
) -> Result<(), TestCaseError> {
    let whole = mesh.to_rays(level, placement).unwrap();
    let source = MeshSource::new(mesh, level, placement).unwrap();
    prop_assert_eq!(source.vertical_triangles(), whole.vertical_triangles);
    slabs_agree(&source, &whole.rays)?;
    file_agrees(&source, &whole.rays, 0..=level)
}

proptest! {
    #![proptest_config(ktree_verify::config(64))]

    #[test]
    fn mesh_slabs_equal_the_whole_mesh(
        mesh in soups(),
        level in 1u32..=5,
        scale in 1i32..4,
        shift in prop::array::uniform3(-6i32..6),
    ) {
        let placement = Placement { scale: f64::from(scale) / 2.0, translate: shift.map(f64::from) };
        mesh_agrees(&mesh, level, &placement)?;
    }

    #[test]
    fn closed_boxes_equal_the_whole_mesh(
        lo in prop::array::uniform3(-2i32..30),
        size in prop::array::uniform3(1i32..30),
    ) {
        let lo = lo.map(|c| f64::from(c) / 2.0);
        let hi = std::array::from_fn(|a| lo[a] + f64::from(size[a]) / 2.0);
        let id = Placement { scale: 1.0, translate: [0.0; 3] };
        mesh_agrees(&cube(lo, hi), 4, &id)?;
    }

    #[test]
    fn volume_slabs_equal_the_whole_volume(
        shape in prop::array::uniform3(1usize..9),
        seed in prop::collection::vec(0u8..4, 512),
        offset in prop::array::uniform3(0u32..8),
        label in any::<bool>(),
    ) {
        let n = shape.iter().product::<usize>();
        let v = Volume::new(shape, seed[..n].iter().map(|&x| f64::from(x)).collect(), [1.0; 3]).unwrap();
        let select = if label { Select::Label(2.0) } else { Select::AtLeast(2.0) };
        let whole = v.to_rays(4, offset, select).unwrap();
        let source = VolumeSource::new(v, 4, offset, select).unwrap();
        slabs_agree(&source, &whole)?;
        file_agrees(&source, &whole, 0..=4)?;
    }
}

#[test]
fn bundled_meshes_equal_their_whole_rays() {
    let dir = cases::data_dir("meshes");
    for name in ["bunny_npm.obj", "fandisk.obj", "armadillo.obj"] {
        let mesh = TriangleMesh::read(&dir.join(name)).unwrap();
        for level in [5, 7] {
            let placement = Placement::fit(&mesh, level).unwrap();
            let whole = mesh.to_rays(level, &placement).unwrap();
            let source = MeshSource::new(&mesh, level, &placement).unwrap();
            slabs_agree(&source, &whole.rays).unwrap();
            file_agrees(&source, &whole.rays, [0, 2, level]).unwrap();
        }
    }
}

#[test]
fn bundled_volumes_equal_their_whole_rays() {
    let dir = cases::data_dir("volumes");
    for (name, select, offset) in [
        ("skull_grey.json", Select::AtLeast(29_000.0), [0, 0, 0]),
        ("itk_t1_brain.json", Select::AtLeast(1.0), [3, 50, 60]),
    ] {
        let volume = Volume::read(&dir.join(name)).unwrap();
        let level = 8;
        let whole = volume.to_rays(level, offset, select).unwrap();
        let source = VolumeSource::new(volume, level, offset, select).unwrap();
        slabs_agree(&source, &whole).unwrap();
        file_agrees(&source, &whole, [0, 3, 5, level]).unwrap();
    }
}
