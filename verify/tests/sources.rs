//! Meshes, volumes and ray files produce their rays slab by slab: for every split depth, the runs of each
//! slab equal that slab of the whole ray set made today, the occupied slabs include every slab with runs,
//! and the out-of-core build from the source writes, byte for byte, the file of the tree stacked in memory
//! from the whole set (random small meshes, volumes and ray files, and the meshes and volumes of data/).

use ktree::io::{
    open_rays_file, read_rays_file, write_ktree, write_rays, write_rays_file, AnyRaysFileSource,
    RaysFile, RaysFileSource,
};
use ktree::rays::RaySource;
use ktree::solid::mesh::{MeshSource, MeshTransform, TriangleMesh};
use ktree::solid::volume::{Select, Volume, VolumeSource};
use ktree::stacking::{paper::stack, Builder};
use ktree::AnyRaySet;
use ktree::{Ray, RaySet};
use ktree_verify::cases::{self, ray_sets, Case};
use ktree_verify::meshes::cube;
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
                r.is_empty() || K == 1 || occupied.contains(&b),
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
    write_ktree(&mut expected, &stack(whole)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tree.ktree");
    for depth in depths {
        Builder::new(source)
            .split_depth(depth)
            .to_file(&out, u64::MAX)
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

fn mesh_agrees(
    mesh: &TriangleMesh,
    level: u32,
    placement: &MeshTransform,
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
        let placement = MeshTransform { scale: f64::from(scale) / 2.0, translate: shift.map(f64::from) };
        mesh_agrees(&mesh, level, &placement)?;
    }

    /// Large triangles in universes of several buckets of columns (one per cell of the default depth):
    /// triangles crossing buckets and slabs.
    #[test]
    fn mesh_slabs_across_buckets(
        mesh in soups(),
        level in 7u32..=8,
        shift in prop::array::uniform3(-40i32..40),
    ) {
        let scale = f64::from(1u32 << (level - 4)) / 1.5;
        let placement = MeshTransform { scale, translate: shift.map(f64::from) };
        let whole = mesh.to_rays(level, &placement).unwrap();
        let source = MeshSource::new(&mesh, level, &placement).unwrap();
        slabs_agree(&source, &whole.rays)?;
        file_agrees(&source, &whole.rays, [0, 1, 3, level])?;
    }

    #[test]
    fn closed_boxes_equal_the_whole_mesh(
        lo in prop::array::uniform3(-2i32..30),
        size in prop::array::uniform3(1i32..30),
    ) {
        let lo = lo.map(|c| f64::from(c) / 2.0);
        let hi = std::array::from_fn(|a| lo[a] + f64::from(size[a]) / 2.0);
        let id = MeshTransform { scale: 1.0, translate: [0.0; 3] };
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
        let mesh = ktree::io::read_mesh(&dir.join(name)).unwrap();
        for level in [5, 7] {
            let placement = MeshTransform::fit(&mesh, level).unwrap();
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

/// A source of a ray file and the file read whole give the same runs slab by slab, the same counts and
/// the same tree file.
fn ray_source_agrees<const K: usize>(
    source: &RaysFileSource<K>,
    whole: &RaySet<K>,
) -> Result<(), TestCaseError> {
    prop_assert_eq!(source.runs(), whole.len() as u64);
    prop_assert_eq!(source.voxel_count(), whole.voxel_count());
    slabs_agree(source, whole)?;
    file_agrees(source, whole, 0..=whole.level())
}

/// The ray file of `case` as `write_rays` writes it is opened slab by slab (not read whole) and agrees
/// with the set.
fn ray_file_agrees<const K: usize>(case: &Case<K>) -> Result<(), TestCaseError> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case.rays");
    write_rays_file(&path, &case.rays).unwrap();
    let whole = read_rays_file(&path).unwrap();
    prop_assert!(whole == AnyRaySet::from(case.rays.clone()));
    let RaysFile::Sorted(source) = open_rays_file(&path).unwrap() else {
        return Err(TestCaseError::fail("a sorted file was read whole"));
    };
    match (&source, &whole) {
        (AnyRaysFileSource::K1(s), AnyRaySet::K1(r)) => ray_source_agrees(s, r),
        (AnyRaysFileSource::K2(s), AnyRaySet::K2(r)) => ray_source_agrees(s, r),
        (AnyRaysFileSource::K3(s), AnyRaySet::K3(r)) => ray_source_agrees(s, r),
        (AnyRaysFileSource::K4(s), AnyRaySet::K4(r)) => ray_source_agrees(s, r),
        _ => Err(TestCaseError::fail("the source has another dimension")),
    }
}

/// The lines of a ray file (header included) as `write_rays` writes them.
fn ray_lines<const K: usize>(rays: &RaySet<K>) -> Vec<String> {
    let mut text = Vec::new();
    write_rays(&mut text, rays).unwrap();
    String::from_utf8(text)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

/// Opening a file gives what reading it whole gives: the same set (read whole, or indexed with the same
/// runs), or the same error.
fn opens_as_read(text: &str) -> Result<(), TestCaseError> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("edited.rays");
    std::fs::write(&path, text).unwrap();
    match (open_rays_file(&path), read_rays_file(&path)) {
        (Err(a), Err(b)) => prop_assert_eq!(a, b),
        (Ok(RaysFile::Whole(a)), Ok(b)) => prop_assert!(a == b, "read whole, a different set"),
        (Ok(RaysFile::Sorted(s)), Ok(b)) => match (&s, &b) {
            (AnyRaysFileSource::K1(s), AnyRaySet::K1(r)) => ray_source_agrees(s, r)?,
            (AnyRaysFileSource::K2(s), AnyRaySet::K2(r)) => ray_source_agrees(s, r)?,
            (AnyRaysFileSource::K3(s), AnyRaySet::K3(r)) => ray_source_agrees(s, r)?,
            (AnyRaysFileSource::K4(s), AnyRaySet::K4(r)) => ray_source_agrees(s, r)?,
            _ => return Err(TestCaseError::fail("the source has another dimension")),
        },
        (a, b) => {
            return Err(TestCaseError::fail(format!(
                "opened {:?}, read {:?}",
                a.map(|_| ()),
                b.map(|_| ())
            )))
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(32))]

    #[test]
    fn ray_file_slabs_k1(case in ray_sets::<1>()) { ray_file_agrees(&case)?; }
    #[test]
    fn ray_file_slabs_k2(case in ray_sets::<2>()) { ray_file_agrees(&case)?; }
    #[test]
    fn ray_file_slabs_k3(case in ray_sets::<3>()) { ray_file_agrees(&case)?; }
    #[test]
    fn ray_file_slabs_k4(case in ray_sets::<4>()) { ray_file_agrees(&case)?; }

    /// Lines moved, repeated, or replaced by bad text (a field, a number out of range, a comment): the
    /// file opens as it reads whole — the same rays or the same error naming the file and line.
    #[test]
    fn edited_ray_files_open_as_they_read(
        case in ray_sets::<3>(),
        edits in prop::collection::vec((0usize..64, 0usize..64, 0u8..6), 1..4),
    ) {
        let mut lines = ray_lines(&case.rays);
        for (i, j, what) in edits {
            let n = lines.len();
            let (i, j) = (i % n, j % n);
            match what {
                0 => lines.swap(i, j),
                1 => { let l = lines[i].clone(); lines.insert(j, l); }
                2 => lines[i] = "1 2 x 4".into(),
                3 => lines[i] = format!("{} 99999", lines[i]),
                4 => lines[i] = "0 0 7 3".into(),
                _ => lines.insert(i, "# a comment".into()),
            }
        }
        opens_as_read(&(lines.join("\n") + "\n"))?;
    }
}

#[test]
fn unsorted_overlapping_and_bad_files_open_as_they_read() {
    for text in [
        "",
        "# only a comment\n",
        "3 4\n1 2 3 4\n",
        "3 4\n1 2 3 4\n0 0 0 1\n",
        "3 4\n1 2 3 8\n1 2 5 9\n",
        "3 4\n1 2 3 8\n1 2 8 9\n",
        "3 4\n1 2 3 8\n1 2 x 9\n",
        "3 4\n1 2 3 8\n1 16 3 4\n",
        "3 4\n1 2 3 8 0 0 1 0 0 -1\n",
        "3 4\n1 2 3 8 0 0 1 0 0 -1\n2 0 0 1\n",
        "2 3\n1 5 4\n",
        "1 4\n5 5\n",
        "1 4\n0 3\n5 7\n",
        "5 3\n",
    ] {
        opens_as_read(text).unwrap_or_else(|e| panic!("{text:?}: {e}"));
    }
    // A file changed after it was opened: the slab read names the file and line.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("changing.rays");
    let rays = RaySet::<3>::from_rays(4, [Ray::new([1, 2, 3], 8), Ray::new([9, 0, 0], 3)]).unwrap();
    write_rays_file(&path, &rays).unwrap();
    let Ok(RaysFile::Sorted(AnyRaysFileSource::K3(source))) = open_rays_file(&path) else {
        panic!("a sorted file")
    };
    std::fs::write(&path, "# ktree rays v1\n3 4\n1 2 3 8\n9 0 x 3\n").unwrap();
    let e = source.slab(8..16).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "{}:4: field 3 (\"x\") is not a whole number",
            path.display()
        )
    );
}
