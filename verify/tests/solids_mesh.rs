//! Triangle meshes to rays: closed meshes with ties (columns through vertices and edges, centres on faces)
//! follow the documented rule exactly; the real meshes in data/ agree with an independent brute-force
//! centre test (the generalised winding number by solid angles) at small levels, and their voxel volume is
//! within the discretisation bound of the signed volume; OBJ, STL (ASCII, binary) and PLY read alike.

use std::path::Path;

use ktree_verify::cases;
use ktree_verify::meshes::{cube, octahedron};

use ktree::solid::mesh::{MeshTransform, TriangleMesh};
use ktree::stacking::paper::stack;
use ktree::{KTree, Universe};
use proptest::prelude::*;

fn rays_dense(mesh: &TriangleMesh, level: u32, p: &MeshTransform) -> Vec<bool> {
    let r = mesh.to_rays(level, p).unwrap();
    let u = Universe::<3>::new(level).unwrap();
    let dense: Vec<bool> = (0..u.voxels() as usize)
        .map(|i| r.rays.contains(u.dense_point(i)))
        .collect();
    let tree = stack(&r.rays);
    tree.assert_well_formed();
    assert_eq!(tree, KTree::<3>::from_dense(level, &dense).unwrap());
    dense
}

/// The documented rule for the octahedron `|dx| + |dy| + |dz| ≤ r` at a centre offset `d` from its centre:
/// inside the solid, or on a face crossed by the column (closed along z); on the silhouette (`dz = 0`,
/// where the column only touches the surface) the column moved by `(ε, ε²)` decides, which is inside
/// exactly when `dx < 0`.
fn octahedron_rule(d: [f64; 3], r: f64) -> bool {
    let sum = d[0].abs() + d[1].abs() + d[2].abs();
    if sum != r {
        return sum < r;
    }
    d[2] != 0.0 || d[0] < 0.0
}

const ID: MeshTransform = MeshTransform {
    scale: 1.0,
    translate: [0.0; 3],
};

#[test]
fn ties_follow_the_documented_rule() {
    // Vertices at voxel centres: columns run through vertices and along edges, centres lie on faces.
    let level = 4;
    let u = Universe::<3>::new(level).unwrap();
    for (c, r) in [
        ([7.5, 7.5, 7.5], 5.0),
        ([6.5, 8.5, 7.5], 4.0),
        ([7.0, 7.0, 7.0], 3.0),
    ] {
        let got = rays_dense(&octahedron(c, r), level, &ID);
        for (i, &g) in got.iter().enumerate() {
            let p = u.dense_point(i);
            let d = [0, 1, 2].map(|a| f64::from(p[a]) + 0.5 - c[a]);
            assert_eq!(
                g,
                octahedron_rule(d, r),
                "octahedron {c:?} {r}: voxel {p:?}"
            );
        }
    }
    // A box with faces through voxel centres: half-open [lo, hi) across x and y (vertical faces are
    // silhouettes: the moved column decides), closed along z.
    let got = rays_dense(&cube([1.5, 2.5, 0.5], [5.5, 3.5, 15.5]), level, &ID);
    assert_eq!(got.iter().filter(|&&b| b).count(), 4 * 16); // 4 × 1 × 16
    assert!(
        got[u.dense_index([1, 2, 0])]
            && got[u.dense_index([4, 2, 15])]
            && !got[u.dense_index([5, 2, 3])]
    );
}

proptest! {
    #![proptest_config(ktree_verify::config(32))]
    /// Octahedra anywhere, on half-voxel grids (ties everywhere) and placed by a transform.
    #[test]
    fn octahedra_are_exact(c in prop::array::uniform3(-4i32..40), r in 1i32..20, s in 1i32..4) {
        let level = 4;
        let u = Universe::<3>::new(level).unwrap();
        let centre = c.map(|x| f64::from(x) / 2.0);
        let p = MeshTransform { scale: f64::from(s), translate: [0.5, -1.0, 0.0] };
        let got = rays_dense(&octahedron(centre, f64::from(r) / 2.0), level, &p);
        for (i, &g) in got.iter().enumerate() {
            let v = u.dense_point(i);
            // Back in mesh coordinates: (v + ½ − t) / s; exact in binary for these values.
            // In voxel coordinates (exact in binary: integer scales, half-integer centres).
            let d = [0, 1, 2].map(|a| f64::from(v[a]) + 0.5 - (p.scale * centre[a] + p.translate[a]));
            prop_assert_eq!(g, octahedron_rule(d, p.scale * f64::from(r) / 2.0), "voxel {:?}", v);
        }
    }
}

/// The generalised winding number of a closed mesh at `q` (sum of signed solid angles / 4π).
fn winding(vertices: &[[f64; 3]], triangles: &[[u32; 3]], q: [f64; 3]) -> f64 {
    let mut total = 0.0;
    for t in triangles {
        let [a, b, c] = t.map(|i| {
            let v = vertices[i as usize];
            [v[0] - q[0], v[1] - q[1], v[2] - q[2]]
        });
        let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]);
        let (la, lb, lc) = (len(a), len(b), len(c));
        let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
        total += 2.0 * det.atan2(den);
    }
    total / (4.0 * std::f64::consts::PI)
}

#[test]
fn real_meshes_match_brute_force_and_volume() {
    let dir = cases::data_dir("meshes");
    for (name, brute_level) in [
        ("bunny_npm.obj", 4),
        ("fandisk.obj", 4),
        ("armadillo.obj", 0),
    ] {
        let mesh = ktree::io::read_mesh(&dir.join(name)).unwrap();
        assert_eq!(mesh.open_edges(), 0, "{name} is closed");
        if brute_level > 0 {
            let p = MeshTransform::fit(&mesh, brute_level).unwrap();
            let got = rays_dense(&mesh, brute_level, &p);
            // The brute force uses the same rounding of vertices to 1/65536 voxel as the ray generator.
            let placed: Vec<[f64; 3]> = mesh
                .vertices()
                .iter()
                .map(|v| p.apply(*v).map(|x| (x * 65536.0).round() / 65536.0))
                .collect();
            let u = Universe::<3>::new(brute_level).unwrap();
            for (i, &g) in got.iter().enumerate() {
                let v = u.dense_point(i);
                let w = winding(&placed, mesh.triangles(), v.map(|c| f64::from(c) + 0.5));
                assert!(
                    (w - w.round()).abs() < 1e-6,
                    "{name}: voxel {v:?} too close to the surface for the brute force"
                );
                assert_eq!(g, w.round() != 0.0, "{name}: voxel {v:?} winding {w}");
            }
        }
        // Volume within the discretisation bound: misclassified centres lie within √3/2 of the surface.
        let level = 7;
        let p = MeshTransform::fit(&mesh, level).unwrap();
        let r = mesh.to_rays(level, &p).unwrap();
        let s = p.scale;
        let volume = mesh.signed_volume() * s.powi(3);
        let bound = 3f64.sqrt() * mesh.surface_area() * s * s;
        let voxels = r.rays.voxel_count() as f64;
        assert!(volume > 0.0);
        assert!(
            (voxels - volume).abs() <= bound,
            "{name}: {voxels} voxels vs volume {volume} (bound {bound})"
        );
        assert!(
            (voxels - volume).abs() <= 0.02 * volume,
            "{name}: {voxels} voxels vs volume {volume}"
        );
    }
}

#[test]
fn formats_read_alike() {
    let mesh = octahedron([7.5, 7.5, 7.5], 6.0);
    let dir = tempfile::tempdir().unwrap();
    let v = mesh.vertices();
    let mut obj = String::from("# octahedron\n");
    let mut stl = String::from("solid oct\n");
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        v.len(),
        mesh.triangles().len()
    );
    let mut bin = vec![0u8; 80];
    bin.extend((mesh.triangles().len() as u32).to_le_bytes());
    for p in v {
        obj += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        ply += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for t in mesh.triangles() {
        obj += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
        ply += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
        stl += "facet normal 0 0 0\nouter loop\n";
        bin.extend([0u8; 12]);
        for &i in t {
            let p = v[i as usize];
            stl += &format!("vertex {} {} {}\n", p[0], p[1], p[2]);
            for x in p {
                bin.extend((x as f32).to_le_bytes());
            }
        }
        stl += "endloop\nendfacet\n";
        bin.extend([0u8; 2]);
    }
    stl += "endsolid oct\n";
    let files = [
        ("m.obj", obj.into_bytes()),
        ("m.ply", ply.into_bytes()),
        ("a.stl", stl.into_bytes()),
        ("b.stl", bin),
    ];
    let want = mesh.to_rays(4, &ID).unwrap().rays;
    for (name, bytes) in files {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let read = ktree::io::read_mesh(&path).unwrap();
        assert_eq!(read.open_edges(), 0, "{name}");
        assert_eq!(read.to_rays(4, &ID).unwrap().rays, want, "{name}");
    }
    // Bad input: errors naming the file, not panics.
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 1 2\nf 1 2 9\n").unwrap();
    let e = ktree::io::read_mesh(&bad).unwrap_err().to_string();
    assert!(e.contains("bad.obj"), "{e}");
    assert!(ktree::io::read_mesh(&dir.path().join("none.stl")).is_err());
    assert!(ktree::io::read_mesh(&dir.path().join("m.xyz")).is_err());
    assert!(MeshTransform::parse("1,2,3").is_err() && MeshTransform::parse("2,0,0,0").is_ok());
    // Levels beyond what the crossing packing holds, and placements far outside, are errors.
    assert!(mesh.to_rays(21, &ID).is_err());
    let far = MeshTransform {
        scale: 1e9,
        translate: [0.0; 3],
    };
    assert!(mesh.to_rays(4, &far).is_err());
}

#[test]
fn open_meshes_are_reported_and_do_not_panic() {
    let full = octahedron([7.5, 7.5, 7.5], 5.0);
    let mut triangles = full.triangles().to_vec();
    triangles.pop();
    let mesh = TriangleMesh::new(full.vertices().to_vec(), triangles).unwrap();
    let r = mesh.to_rays(4, &ID).unwrap();
    assert_eq!(r.open_edges, 3);
    stack(&r.rays).assert_well_formed();
}

/// The files of a mesh whose every triangle has its own three vertices (as STL has them, and as many PLY
/// and OBJ exporters write them for per-face normals or texture coordinates), with the float noise of
/// exporters on them (`−3e−16` written for `0`): OBJ, PLY and binary STL.
fn face_vertex_files(mesh: &TriangleMesh) -> Vec<(&'static str, Vec<u8>)> {
    let noisy =
        |p: [f64; 3], k: usize| p.map(|c| if c == 0.0 { [0.0, -3e-16, 5e-17][k] } else { c });
    let mut obj = String::new();
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        3 * mesh.triangles().len(),
        mesh.triangles().len()
    );
    let mut faces = (String::new(), String::new());
    let mut stl = vec![0u8; 80];
    stl.extend((mesh.triangles().len() as u32).to_le_bytes());
    for (i, t) in mesh.triangles().iter().enumerate() {
        stl.extend([0u8; 12]);
        for (k, &v) in t.iter().enumerate() {
            let p = noisy(mesh.vertices()[v as usize], k);
            obj += &format!("v {:e} {:e} {:e}\n", p[0], p[1], p[2]);
            ply += &format!("{:e} {:e} {:e}\n", p[0], p[1], p[2]);
            stl.extend(p.iter().flat_map(|&c| (c as f32).to_le_bytes()));
        }
        stl.extend([0u8; 2]);
        faces.0 += &format!("f {} {} {}\n", 3 * i + 1, 3 * i + 2, 3 * i + 3);
        faces.1 += &format!("3 {} {} {}\n", 3 * i, 3 * i + 1, 3 * i + 2);
    }
    vec![
        ("obj", (obj + &faces.0).into_bytes()),
        ("ply", (ply + &faces.1).into_bytes()),
        ("stl", stl),
    ]
}

/// A closed mesh stays closed when its vertices are repeated per face with float noise on them (trimesh's
/// `featuretype.STL`, `idler_riser.STL`, `featuretype.ply`, `tube.obj` were said to be open): its open
/// edges are counted on positions, and the voxels are those of the shared-vertex mesh.
#[test]
fn closed_meshes_with_repeated_vertices_are_closed() {
    let id = MeshTransform {
        scale: 1.0,
        translate: [0.0; 3],
    };
    for mesh in [
        octahedron([7.5, 7.5, 7.5], 6.0),
        cube([0.0, 0.0, 0.0], [9.0, 5.0, 3.0]),
    ] {
        assert_eq!(mesh.open_edges(), 0);
        let want = mesh.to_rays(4, &id).unwrap().rays;
        for (format, bytes) in face_vertex_files(&mesh) {
            let read = ktree::io::read_mesh_bytes(&bytes, format, Path::new("m")).unwrap();
            assert_eq!(read.open_edges(), 0, "{format}");
            let r = read.to_rays(4, &id).unwrap();
            assert_eq!((r.open_edges, r.rays), (0, want.clone()), "{format}");
        }
        // One triangle fewer is open again: three edges.
        let (v, t) = (mesh.vertices().to_vec(), mesh.triangles()[1..].to_vec());
        assert_eq!(TriangleMesh::new(v, t).unwrap().open_edges(), 3);
    }
}

/// An ASCII STL of several `solid … endsolid` blocks (trimesh's `multibody.stl`) is read whole: every
/// solid's triangles, voxelized as the union of the solids read one by one.
#[test]
fn every_solid_of_an_ascii_stl_is_read() {
    let id = MeshTransform {
        scale: 1.0,
        translate: [0.0; 3],
    };
    let solids = [
        cube([1.0, 1.0, 1.0], [5.0, 4.0, 3.0]),
        octahedron([10.5, 9.5, 8.5], 4.0),
        cube([2.0, 9.0, 9.0], [4.0, 14.0, 15.0]),
    ];
    let text = |mesh: &TriangleMesh, name: &str| {
        let mut s = format!("solid {name}\n");
        for t in mesh.triangles() {
            s += "  facet normal 0 0 0\n    outer loop\n";
            for &i in t {
                let p = mesh.vertices()[i as usize];
                s += &format!("      vertex {} {} {}\n", p[0], p[1], p[2]);
            }
            s += "    endloop\n  endfacet\n";
        }
        s + &format!("endsolid {name}\n")
    };
    let file: String = solids
        .iter()
        .enumerate()
        .map(|(i, m)| text(m, &format!("body{i}")))
        .collect::<Vec<_>>()
        .join("\n");
    let read = ktree::io::read_mesh_bytes(file.as_bytes(), "stl", Path::new("multi.stl")).unwrap();
    let triangles: usize = solids.iter().map(|m| m.triangles().len()).sum();
    assert_eq!(read.triangles().len(), triangles);
    assert_eq!(read.open_edges(), 0);
    let mut union = ktree::RaySet::<3>::empty(4).unwrap();
    for m in &solids {
        union = union.union(&m.to_rays(4, &id).unwrap().rays).unwrap();
    }
    assert_eq!(read.to_rays(4, &id).unwrap().rays, union);
    // A solid left open is an error naming the line; a binary file whose header starts with "solid " is
    // binary (its length says so).
    let cut = &file[..file.rfind("endsolid").unwrap()];
    let e = ktree::io::read_mesh_bytes(cut.as_bytes(), "stl", Path::new("cut.stl")).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "cut.stl:{}: the ASCII STL ends inside a solid (no 'endsolid')",
            cut.lines().count() + 1
        )
    );
    let mut binary = face_vertex_files(&solids[0]).pop().unwrap().1;
    binary[..12].copy_from_slice(b"solid binary");
    let read = ktree::io::read_mesh_bytes(&binary, "stl", Path::new("b.stl")).unwrap();
    assert_eq!(read.triangles().len(), solids[0].triangles().len());
}

/// Mesh errors are one line naming the file once, with the line or byte where the parser finds the
/// fault (a PLY read by ply-rs said three lines with a debug dump).
#[test]
fn mesh_errors_are_one_line_naming_the_file_once() {
    let header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "ply",
            format!("{header}0 0 0\n1 0 0\n0 1\n3 0 1 2\n"),
            "m.ply:12: vertex 2 has too few values",
        ),
        (
            "ply",
            format!("{header}0 0 0\n1 0 0\n0 1 0\n3 0 1 x\n"),
            "m.ply:13: 'x' is not a number",
        ),
        (
            "ply",
            format!("{header}0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
            "m.ply: triangle 0 refers to vertex [0, 1, 7] but there are 3 vertices",
        ),
        (
            "ply",
            format!("{header}0 0 0\n1 0 0\n0 1 0\n3 0 1 -2\n"),
            "m.ply:13: PLY face 0: '-2' is not a vertex index",
        ),
        (
            "ply",
            header.replace("property float y\n", "property flot y\n"),
            "m.ply:5: unknown property type 'flot'",
        ),
        (
            "ply",
            header.replace("element face 1", "element face"),
            "m.ply:7: unexpected PLY header line 'element face'",
        ),
        (
            "ply",
            format!("{header}0 0 0\n1 0 0\n"),
            "m.ply: the PLY file ends at vertex 2 of 3",
        ),
        (
            "stl",
            "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0\n".into(),
            "m.stl:5: expected 'vertex x y z', found 'vertex 1 0'",
        ),
        (
            "obj",
            "v 0 0 0\nf 1 2 3\n".into(),
            "m.obj: OBJ: face vertex index out of bounds",
        ),
    ];
    for (format, text, want) in cases {
        let e =
            ktree::io::read_mesh_bytes(text.as_bytes(), format, Path::new(&format!("m.{format}")))
                .unwrap_err()
                .to_string();
        assert_eq!(e, want);
    }
}
