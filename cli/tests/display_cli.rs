//! `ktree render` and `ktree lines` end to end: PNG and SVG files appear for octrees, quadtrees and 4-D
//! trees; bad input gives a one-line error and a non-zero exit.

mod common;

use common::ktree;

use ktree::io::write_ktree_file;
use ktree::rays::ball_rays;
use ktree::stacking::paper::stack;

fn is_png(path: &std::path::Path) -> bool {
    std::fs::read(path).is_ok_and(|b| b.starts_with(b"\x89PNG"))
}

#[test]
fn render_and_lines_write_pictures() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    write_ktree_file(
        &p("ball.ktree"),
        &stack(&ball_rays::<3>(4, [16, 16, 16], 14).unwrap()),
    )
    .unwrap();
    write_ktree_file(
        &p("disk.ktree"),
        &stack(&ball_rays::<2>(5, [32, 32], 26).unwrap()),
    )
    .unwrap();
    write_ktree_file(
        &p("ball4.ktree"),
        &stack(&ball_rays::<4>(3, [8, 8, 8, 8], 7).unwrap()),
    )
    .unwrap();
    let s = |path: std::path::PathBuf| path.display().to_string();

    let (ok, out, err) = ktree(&[
        "render",
        &s(p("ball.ktree")),
        "--size",
        "64x48",
        "--out",
        &s(p("a.png")),
        "--depth",
        &s(p("d.png")),
        "--progress",
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("wrote") && is_png(&p("a.png")) && is_png(&p("d.png")));
    let (ok, _, err) = ktree(&[
        "render",
        &s(p("ball.ktree")),
        "--camera",
        "top",
        "--perspective",
        "45",
        "--size",
        "32x32",
        "--out",
        &s(p("b.png")),
    ]);
    assert!(ok && is_png(&p("b.png")), "{err}");
    let (ok, _, err) = ktree(&[
        "render",
        &s(p("ball.ktree")),
        "--eye",
        "40,-30,35",
        "--size",
        "32x32",
        "--out",
        &s(p("e.png")),
    ]);
    assert!(ok && is_png(&p("e.png")), "{err}");
    let (ok, _, err) = ktree(&[
        "render",
        &s(p("disk.ktree")),
        "--size",
        "64x64",
        "--out",
        &s(p("q.png")),
    ]);
    assert!(ok && is_png(&p("q.png")), "{err}");
    let (ok, _, err) = ktree(&[
        "render",
        &s(p("ball4.ktree")),
        "--size",
        "32x32",
        "--frames",
        "3",
        "--out",
        &s(p("strip.png")),
        "--frames-dir",
        &s(p("frames")),
    ]);
    assert!(
        ok && is_png(&p("strip.png")) && is_png(&p("frames/frame_002.png")),
        "{err}"
    );

    // Shading with the normals of a ray file (every run pointing up: a flat-looking but valid picture).
    let flat = ktree::RaySet::<3>::from_rays_with_normals(
        4,
        ball_rays::<3>(4, [16, 16, 16], 14)
            .unwrap()
            .iter()
            .map(|r| (r, [[0.0, 0.0, -1.0], [0.0, 0.0, 1.0]])),
    )
    .unwrap();
    ktree::io::write_rays_file(&p("ball.rays"), &flat).unwrap();
    let (ok, _, err) = ktree(&[
        "render",
        &s(p("ball.ktree")),
        "--rays",
        &s(p("ball.rays")),
        "--size",
        "32x32",
        "--out",
        &s(p("n.png")),
    ]);
    assert!(ok && is_png(&p("n.png")), "{err}");
    assert_ne!(
        std::fs::read(p("n.png")).unwrap(),
        std::fs::read(p("e.png")).unwrap()
    );
    let (ok, out, err) = ktree(&[
        "lines",
        &s(p("ball.ktree")),
        "--out",
        &s(p("l.svg")),
        "--progress",
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("lines"));
    let svg = std::fs::read_to_string(p("l.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("<path"));
    let (ok, _, err) = ktree(&[
        "lines",
        &s(p("ball.ktree")),
        "--view",
        "1,2,3",
        "--method",
        "pairwise",
        "--out",
        &s(p("l.png")),
    ]);
    assert!(ok && is_png(&p("l.png")), "{err}");
}

#[test]
fn bad_input_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let ball = dir.path().join("ball.ktree");
    write_ktree_file(&ball, &stack(&ball_rays::<3>(3, [8, 8, 8], 6).unwrap())).unwrap();
    let disk = dir.path().join("disk.ktree");
    write_ktree_file(&disk, &stack(&ball_rays::<2>(3, [8, 8], 6).unwrap())).unwrap();
    let b = ball.display().to_string();
    for args in [
        vec!["render", b.as_str(), "--size", "0x10"],
        vec!["render", b.as_str(), "--size", "big"],
        vec!["render", b.as_str(), "--size", "16000x16000"],
        vec!["render", b.as_str(), "--camera", "sideways"],
        vec!["render", b.as_str(), "--camera", "0,0,0"],
        vec!["render", b.as_str(), "--perspective", "200"],
        vec!["render", "/nonexistent/x.ktree"],
        vec!["lines", b.as_str(), "--method", "fastest"],
        vec!["lines", b.as_str(), "--view", "1,2"],
        vec!["lines", disk.to_str().unwrap()],
    ] {
        let (ok, _, err) = ktree(&args);
        assert!(!ok, "{args:?} should fail");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("ktree: "), "{err}");
    }
}

/// A version 2 file is rendered from its memory map: the same pictures and summary as the tree read into
/// memory from a version 1 file.
#[test]
fn version_2_files_render_from_their_map_as_in_memory() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let tree = stack(&ball_rays::<3>(7, [60, 64, 70], 50).unwrap());
    ktree::fs::write_atomic_with(&p("v1.ktree"), |w| ktree::io::write_ktree_v1(w, &tree)).unwrap();
    ktree::io::write_ktree_file(&p("v2.ktree"), &tree).unwrap();
    let render = |file: &str, camera: &str| {
        let (ok, out, err) = ktree(&[
            "render",
            p(file).to_str().unwrap(),
            "--camera",
            camera,
            "--size",
            "96x64",
            "--out",
            p("out.png").to_str().unwrap(),
            "--depth",
            p("depth.png").to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        (
            out,
            std::fs::read(p("out.png")).unwrap(),
            std::fs::read(p("depth.png")).unwrap(),
        )
    };
    for camera in ["iso", "top", "1,-2,0.5"] {
        assert!(
            render("v1.ktree", camera) == render("v2.ktree", camera),
            "camera {camera}"
        );
    }
}
