//! `ktree view` end to end, in a real browser: the page opens in headless Chromium with no error and no
//! request, draws the tree, and its first frame's silhouette agrees with `ktree render` of the same tree and
//! camera on at least 95 % of the pixels of their union; its first camera frames the whole object in a
//! 1024 × 768 window. Where Chromium is missing the browser checks print a `SKIPPED:` line and pass, or
//! fail under `KTREE_REQUIRE_TOOLS=1` (as `.ci/run` sets it).

mod common;

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{ktree, tools};

use ktree::io::write_ktree_file;
use ktree::rays::ball_rays;
use ktree::KTree;

/// The Chromium binary on the `PATH`; `None` after [`tools::missing`] where there is none.
#[track_caller]
fn chromium() -> Option<PathBuf> {
    tools::require(
        &["chromium", "chromium-browser", "google-chrome"],
        "install Chromium (Debian's chromium)",
    )
}

/// Runs headless Chromium on `url` with `extra` flags (its own new profile, offline, software WebGL);
/// returns its standard output. Ends it after two minutes.
fn run_chromium(browser: &Path, url: &str, extra: &[&str]) -> String {
    let profile = tempfile::tempdir().unwrap();
    let mut child = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(extra)
        .arg(url)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("start chromium");
    // Read while it runs: a page's DOM is larger than a pipe holds.
    let mut stdout = child.stdout.take().expect("piped");
    let reader = std::thread::spawn(move || {
        let mut out = Vec::new();
        stdout.read_to_end(&mut out).map(|_| out)
    });
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("chromium did not finish on {url}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    String::from_utf8_lossy(&reader.join().unwrap().unwrap()).into_owned()
}

/// The page's own record of its first frame (`key=value` lines of `#ktree-status`) and its errors, read
/// from the DOM after load.
fn page_status(browser: &Path, page: &Path, hash: &str) -> (Vec<(String, String)>, String) {
    let url = format!("file://{}{hash}", page.display());
    let dom = run_chromium(browser, &url, &["--window-size=320,240", "--dump-dom"]);
    let between = |open: &str, close: &str| {
        let at = dom
            .find(open)
            .unwrap_or_else(|| panic!("no {open} in {dom:.2000}"))
            + open.len();
        dom[at..].split(close).next().unwrap().to_string()
    };
    let status = between("<pre id=\"ktree-status\">", "</pre>")
        .lines()
        .filter_map(|l| l.split_once('='))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    let errors = between("id=\"ktree-errors\"", "</ol>");
    (status, errors)
}

fn get<'a>(status: &'a [(String, String)], key: &str) -> &'a str {
    status
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
        .unwrap_or_else(|| panic!("no {key} in {status:?}"))
}

/// Object pixels (anything but the white background) of a PNG.
fn silhouette(path: &Path) -> (u32, u32, Vec<bool>) {
    let image = image::open(path).unwrap().to_rgb8();
    let mask = image.pixels().map(|p| p.0 != [255, 255, 255]).collect();
    (image.width(), image.height(), mask)
}

/// Intersection over union of two masks.
fn iou(a: &[bool], b: &[bool]) -> f64 {
    let both = a.iter().zip(b).filter(|(x, y)| **x && **y).count();
    let either = a.iter().zip(b).filter(|(x, y)| **x || **y).count();
    both as f64 / either.max(1) as f64
}

/// A ball and a box beside it, off-centre: no symmetry hides a mirrored or turned view.
fn lopsided() -> KTree<3> {
    let n = 32u32;
    let mut dense = vec![false; (n * n * n) as usize];
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let (fx, fy, fz) = (
                    f64::from(x) - 11.5,
                    f64::from(y) - 13.5,
                    f64::from(z) - 15.5,
                );
                let ball = fx * fx + fy * fy + fz * fz <= 81.0;
                let slab = (16..30).contains(&x) && (4..12).contains(&y) && (2..27).contains(&z);
                dense[(x + n * (y + n * z)) as usize] = ball || slab;
            }
        }
    }
    KTree::<3>::from_dense(5, &dense).unwrap()
}

fn s(path: &Path) -> String {
    path.display().to_string()
}

#[test]
fn the_page_matches_ktree_render_in_a_browser() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let ball = KTree::from_rays(&ball_rays::<3>(6, [64, 64, 64], 50).unwrap());
    write_ktree_file(&p("ball.ktree"), &ball).unwrap();
    write_ktree_file(&p("lopsided.ktree"), &lopsided()).unwrap();
    // The page is written (and the budget respected) whether or not a browser is there.
    for (tree, camera) in [("ball", "iso"), ("lopsided", "front"), ("lopsided", "iso")] {
        let page = p(&format!("{tree}-{camera}.html"));
        let (ok, out, err) = ktree(&[
            "view",
            &s(&p(&format!("{tree}.ktree"))),
            "--camera",
            camera,
            "--out",
            &s(&page),
        ]);
        assert!(ok, "{err}");
        assert!(out.contains("boxes"), "{out}");
        let (ok, _, err) = ktree(&[
            "render",
            &s(&p(&format!("{tree}.ktree"))),
            "--camera",
            camera,
            "--size",
            "320x240",
            "--out",
            &s(&p(&format!("{tree}-{camera}.png"))),
        ]);
        assert!(ok, "{err}");
    }
    let Some(browser) = chromium() else {
        return;
    };
    for (tree, camera) in [("ball", "iso"), ("lopsided", "front"), ("lopsided", "iso")] {
        let page = p(&format!("{tree}-{camera}.html"));
        let (status, errors) = page_status(&browser, &page, "#bare");
        assert_eq!(get(&status, "errors"), "0", "{tree} {camera}: {errors}");
        assert!(
            get(&status, "painted").parse::<u64>().unwrap() > 1000,
            "{status:?}"
        );
        let shot = p(&format!("{tree}-{camera}-page.png"));
        run_chromium(
            &browser,
            &format!("file://{}#bare", page.display()),
            &[
                "--window-size=320,240",
                &format!("--screenshot={}", shot.display()),
            ],
        );
        let (w, h, page_mask) = silhouette(&shot);
        let (rw, rh, render_mask) = silhouette(&p(&format!("{tree}-{camera}.png")));
        assert_eq!((w, h), (rw, rh));
        let agree = iou(&page_mask, &render_mask);
        println!(
            "{tree} {camera}: silhouettes agree on {:.2} % of their union",
            100.0 * agree
        );
        assert!(agree >= 0.95, "{tree} {camera}: IoU {agree}");
    }
    // The camera named in the URL's hash overrides the page's: the lopsided object's front page seen
    // from iso is the iso picture.
    let shot = p("hash.png");
    run_chromium(
        &browser,
        &format!(
            "file://{}#camera=iso&bare",
            p("lopsided-front.html").display()
        ),
        &[
            "--window-size=320,240",
            &format!("--screenshot={}", shot.display()),
        ],
    );
    let (.., hash_mask) = silhouette(&shot);
    let (.., iso_mask) = silhouette(&p("lopsided-iso.png"));
    let (.., front_mask) = silhouette(&p("lopsided-front.png"));
    assert!(iou(&hash_mask, &iso_mask) >= 0.95);
    assert!(
        iou(&hash_mask, &front_mask) < 0.9,
        "the front and iso views must differ"
    );
}

/// The page's header (the JSON the page reads its boxes and first camera from).
fn header_of(page: &Path) -> serde_json::Value {
    let html = std::fs::read_to_string(page).unwrap();
    let text = html
        .split("id=\"ktree-header\">")
        .nth(1)
        .unwrap()
        .split("</script>")
        .next()
        .unwrap();
    serde_json::from_str(text).unwrap()
}

/// The half width and half height, on the screen axes of the page's first camera and around its target,
/// of the projection of every corner of every full voxel of `tree`.
fn projected_extent(tree: &KTree<3>, frame: &serde_json::Value) -> [f64; 2] {
    let vector = |key: &str| -> [f64; 3] {
        let v = frame[key].as_array().unwrap();
        std::array::from_fn(|a| v[a].as_f64().unwrap())
    };
    let (target, right, up) = (vector("target"), vector("right"), vector("up"));
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let mut extent = [0.0f64; 2];
    for (cell, state) in tree.leaves() {
        if state != ktree::NodeState::Full {
            continue;
        }
        let side = cell.side() as f64;
        for c in 0..8 {
            let v: [f64; 3] = std::array::from_fn(|a| {
                f64::from(cell.origin()[a]) + if c >> a & 1 == 1 { side } else { 0.0 } - target[a]
            });
            extent[0] = extent[0].max(dot(v, right).abs());
            extent[1] = extent[1].max(dot(v, up).abs());
        }
    }
    extent
}

/// `ktree view`'s first camera frames the whole object: the armadillo at L = 9 (which ran off both sides
/// of a 1024 × 768 window), a bar far wider than tall and one far taller than wide. The camera the page is
/// given holds the projection of every full voxel; in a browser, no pixel on the border of a 1024 × 768
/// window is painted, and the page's own framing of its first view is the one it was given.
#[test]
fn the_first_camera_frames_the_whole_object() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    let armadillo = common::data_dir().join("meshes/armadillo.obj");
    let (ok, _, err) = ktree(&[
        "voxelize",
        &s(&armadillo),
        "--level",
        "9",
        "--fit",
        "--out",
        &s(&p("armadillo.ktree")),
    ]);
    assert!(ok, "{err}");
    let bar = |size: [u32; 3]| {
        let n = 64u32;
        let dense: Vec<bool> = (0..n * n * n)
            .map(|i| {
                let at = [i % n, i / n % n, i / (n * n)];
                (0..3).all(|a| (32 - size[a] / 2..32 + size[a] / 2).contains(&at[a]))
            })
            .collect();
        KTree::<3>::from_dense(6, &dense).unwrap()
    };
    write_ktree_file(&p("wide.ktree"), &bar([60, 4, 4])).unwrap();
    write_ktree_file(&p("tall.ktree"), &bar([4, 4, 60])).unwrap();
    let names = ["armadillo", "wide", "tall"];
    for name in names {
        let (ok, _, err) = ktree(&[
            "view",
            &s(&p(&format!("{name}.ktree"))),
            "--out",
            &s(&p(&format!("{name}.html"))),
        ]);
        assert!(ok, "{err}");
        let header = header_of(&p(&format!("{name}.html")));
        let frame = &header["frame"];
        let tree = KTree::<3>::load(p(&format!("{name}.ktree"))).unwrap();
        let object = projected_extent(&tree, frame);
        let extent: Vec<f64> = frame["extent"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        for a in 0..2 {
            assert!(
                object[a] <= extent[a] + 1e-9,
                "{name}: the object's projection {object:?} is outside the camera's extent {extent:?}"
            );
        }
        assert!(frame["margin"].as_f64().unwrap() > 1.0, "{name}: {frame}");
    }
    let Some(browser) = chromium() else {
        return;
    };
    for name in names {
        let page = p(&format!("{name}.html"));
        let (status, errors) = page_status(&browser, &page, "#bare");
        assert_eq!(get(&status, "errors"), "0", "{name}: {errors}");
        assert_eq!(get(&status, "first_camera"), "header", "{name}");
        let check: f64 = get(&status, "frame_check").parse().unwrap();
        assert!(
            check < 1e-9,
            "{name}: the page frames its first view otherwise than its header ({check})"
        );
        let shot = p(&format!("{name}.png"));
        run_chromium(
            &browser,
            &format!("file://{}#bare", page.display()),
            &[
                "--window-size=1024,768",
                &format!("--screenshot={}", shot.display()),
            ],
        );
        let (w, h, mask) = silhouette(&shot);
        assert_eq!((w, h), (1024, 768));
        let painted = |x: u32, y: u32| mask[(y * w + x) as usize];
        let border = (0..w).any(|x| painted(x, 0) || painted(x, h - 1))
            || (0..h).any(|y| painted(0, y) || painted(w - 1, y));
        assert!(
            !border,
            "{name}: the object touches the border of the window"
        );
        assert!(
            mask.iter().filter(|&&m| m).count() > 10_000,
            "{name}: too little drawn"
        );
    }
}

#[test]
fn every_dimension_opens_without_errors_and_nothing_is_requested() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    write_ktree_file(
        &p("disk.ktree"),
        &KTree::from_rays(&ball_rays::<2>(6, [64, 64], 50).unwrap()),
    )
    .unwrap();
    write_ktree_file(
        &p("moving.ktree"),
        &KTree::from_rays(&ball_rays::<4>(4, [16, 16, 16, 16], 12).unwrap()),
    )
    .unwrap();
    write_ktree_file(
        &p("ball.ktree"),
        &KTree::from_rays(&ball_rays::<3>(7, [128, 128, 128], 100).unwrap()),
    )
    .unwrap();
    // Other formats are read through the common layer: the ball as a ray file.
    let (ok, _, err) = ktree(&["convert", &s(&p("ball.ktree")), &s(&p("ball.rays"))]);
    assert!(ok, "{err}");
    let pages = [
        ("disk.ktree", vec![]),
        ("moving.ktree", vec!["--time-axis", "2"]),
        ("ball.rays", vec!["--budget", "300"]),
    ];
    for (name, extra) in &pages {
        let page = p(&format!("{name}.html"));
        let mut args = vec!["view", &s(&p(name))]
            .into_iter()
            .map(String::from)
            .collect::<Vec<_>>();
        args.extend(extra.iter().map(|x| x.to_string()));
        args.extend(["--out".to_string(), s(&page)]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (ok, out, err) = ktree(&args);
        assert!(ok, "{name}: {err}");
        let html = std::fs::read_to_string(&page).unwrap();
        // Nothing in the page points outside it, and the page forbids every request.
        assert!(
            !html.contains("http://") && !html.contains("https://"),
            "{name}"
        );
        assert!(html.contains("content=\"default-src 'none';"), "{name}");
        // The boxes in the page (the header's counts) are within the budget.
        let header: serde_json::Value = serde_json::from_str(
            html.split("id=\"ktree-header\">")
                .nth(1)
                .unwrap()
                .split("</script>")
                .next()
                .unwrap(),
        )
        .unwrap();
        let boxes = header["full"].as_u64().unwrap() + header["coarse"].as_u64().unwrap();
        let groups: u64 = header["groups"]
            .as_array()
            .unwrap()
            .iter()
            .map(|g| g["count"].as_u64().unwrap())
            .sum();
        assert_eq!(boxes, groups);
        let budget = header["budget"].as_u64().unwrap();
        assert!(
            boxes <= budget && boxes > 0,
            "{name}: {boxes} boxes, budget {budget}"
        );
        if *name == "ball.rays" {
            assert_eq!(budget, 300);
            assert!(
                header["coarse"].as_u64().unwrap() > 0,
                "a level-7 ball does not fit in 300 boxes"
            );
            assert!(out.contains("coarse"), "{out}");
        }
    }
    let Some(browser) = chromium() else {
        return;
    };
    for (name, _) in &pages {
        let (status, errors) = page_status(&browser, &p(&format!("{name}.html")), "");
        assert_eq!(get(&status, "errors"), "0", "{name}: {errors}");
        assert!(
            get(&status, "painted").parse::<u64>().unwrap() > 100,
            "{name}: {status:?}"
        );
        // The controls, driven by DOM events (a drag with each button, the wheel, a clip slider, the
        // camera and colour menus, the time slider of a 4-D tree): each moves the view as it should and
        // changes the frame drawn.
        let (status, errors) = page_status(&browser, &p(&format!("{name}.html")), "#selftest");
        assert_eq!(get(&status, "errors"), "0", "{name}: {errors}");
        let mut controls = vec!["rotate", "pan", "zoom", "clip", "camera", "colour"];
        if *name == "moving.ktree" {
            controls.push("time");
        }
        for control in controls {
            assert_eq!(
                get(&status, &format!("selftest_{control}")),
                "1",
                "{name}: {control} ({status:?})"
            );
        }
    }
    // The time slider shows one slice of a 4-D tree: a ball moving along the time axis is elsewhere at
    // another time.
    let mut dense = vec![false; 1 << 16];
    for (i, voxel) in dense.iter_mut().enumerate() {
        let [x, y, z, t] = [0, 4, 8, 12].map(|s| ((i >> s) & 15) as f64 + 0.5);
        *voxel = (x - 4.0 - 0.5 * t).powi(2) + (y - 8.0).powi(2) + (z - 8.0).powi(2) <= 9.0;
    }
    write_ktree_file(&p("run.ktree"), &KTree::<4>::from_dense(4, &dense).unwrap()).unwrap();
    let (ok, _, err) = ktree(&[
        "view",
        &s(&p("run.ktree")),
        "--camera",
        "top",
        "--out",
        &s(&p("run.html")),
    ]);
    assert!(ok, "{err}");
    let mut masks = Vec::new();
    for time in [1, 14] {
        let (status, errors) = page_status(&browser, &p("run.html"), &format!("#time={time}"));
        assert_eq!(get(&status, "errors"), "0", "{errors}");
        let shot = p(&format!("run-{time}.png"));
        run_chromium(
            &browser,
            &format!("file://{}#bare&time={time}", p("run.html").display()),
            &[
                "--window-size=320,240",
                &format!("--screenshot={}", shot.display()),
            ],
        );
        let (.., mask) = silhouette(&shot);
        assert!(
            mask.iter().filter(|&&m| m).count() > 100,
            "time {time}: nothing drawn"
        );
        masks.push(mask);
    }
    assert!(
        iou(&masks[0], &masks[1]) < 0.5,
        "the slices at times 1 and 14 must differ"
    );
    // The check itself catches a request: a page that tries one records the blocked request as an error.
    let html = std::fs::read_to_string(p("disk.ktree.html")).unwrap();
    let leaky = html.replace(
        "</body>",
        "<script>fetch(\"https://example.com/x\");</script></body>",
    );
    std::fs::write(p("leaky.html"), leaky).unwrap();
    let (status, errors) = page_status(&browser, &p("leaky.html"), "");
    assert_ne!(
        get(&status, "errors"),
        "0",
        "a blocked request must be recorded"
    );
    assert!(errors.contains("example.com"), "{errors}");
}

#[test]
fn bad_input_is_a_one_line_error_and_the_default_page_is_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    std::fs::write(p("junk.ktree"), b"not a tree at all").unwrap();
    write_ktree_file(&p("line.ktree"), &KTree::<1>::full(3).unwrap()).unwrap();
    write_ktree_file(&p("moving.ktree"), &KTree::<4>::full(2).unwrap()).unwrap();
    write_ktree_file(&p("cube.ktree"), &KTree::<3>::full(2).unwrap()).unwrap();
    let page = s(&p("page.html"));
    let cases: Vec<Vec<&str>> = vec![
        vec!["missing.ktree", "--out", &page],
        vec!["junk.ktree", "--out", &page],
        vec!["line.ktree", "--out", &page],
        vec!["moving.ktree", "--time-axis", "4", "--out", &page],
        vec!["cube.ktree", "--budget", "0", "--out", &page],
        vec!["cube.ktree", "--camera", "sideways", "--out", &page],
        // A file where the page's folder would be.
        vec!["cube.ktree", "--out", "/dev/null/page.html"],
    ];
    for case in cases {
        let file = s(&p(case[0]));
        let mut args = vec!["view", &file];
        args.extend(&case[1..]);
        let (ok, _, err) = ktree(&args);
        assert!(!ok, "{args:?} should fail");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
    }
    assert!(!p("page.html").exists());
    // Without --out: a new page in the temporary folder, its path printed; --open without a browser to
    // open it with says so and succeeds.
    let out = Command::new(env!("CARGO_BIN_EXE_ktree"))
        .args(["view", &s(&p("cube.ktree")), "--open"])
        .env("PATH", dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("no browser"), "{text}");
    let written = text
        .split_whitespace()
        .find(|w| w.ends_with(".html"))
        .map(PathBuf::from)
        .unwrap();
    assert!(
        written.starts_with(std::env::temp_dir()),
        "{}",
        written.display()
    );
    assert!(std::fs::read_to_string(&written)
        .unwrap()
        .contains("ktree-header"));
    std::fs::remove_file(written).unwrap();
}

/// Whether `px` is a shade of `base`: every channel `base`'s times one factor (to rounding).
fn is_shade(px: [u8; 3], base: [u8; 3]) -> bool {
    let f = f64::from(px[0].max(px[1]).max(px[2])) / f64::from(base[0].max(base[1]).max(base[2]));
    (0..3).all(|c| (f64::from(px[c]) - f64::from(base[c]) * f).abs() <= 3.0)
}

/// The values of the legend's entries in the page's DOM (`data-value` of `#legend .entry`).
fn legend_of(browser: &Path, page: &Path, hash: &str) -> Vec<String> {
    let url = format!("file://{}{hash}", page.display());
    let dom = run_chromium(browser, &url, &["--window-size=320,240", "--dump-dom"]);
    dom.split("class=\"entry\" data-value=\"")
        .skip(1)
        .map(|rest| rest.split('"').next().unwrap().to_string())
        .collect()
}

/// Pages of trees with values: coloured by value (the page's status says `colour=value`, the first
/// colouring), their legend lists the tree's labels (the 32 that fill the most voxels, and how many more
/// there are), a float tree's legend is the ramp from its smallest to its largest value; the colour menu
/// still switches (selftest); in a screenshot of a quadtree with values every drawn pixel is a shade of one
/// label's palette colour and each label's squares show its colour as the page shades a face seen from
/// above. Pages of trees without values keep their colourings.
#[test]
fn pages_of_trees_with_values_are_coloured_by_value_with_a_legend() {
    use ktree::display::palette::label_colour;
    use ktree::io::ktree::v3::write_valued_ktree_file;
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    // A quadtree: 16 × 16 voxels in 4 × 4 blocks of labels 3, 10, 17, 24 (by block column) and 50 (the
    // top row of blocks), the top right block empty.
    let labels2: Vec<Option<u8>> = (0..256u32)
        .map(|i| {
            let (bx, by) = (i % 16 / 4, i / 16 / 4);
            match (bx, by) {
                (3, 3) => None,
                (_, 3) => Some(50),
                _ => Some(3 + 7 * bx as u8),
            }
        })
        .collect();
    let quad = KTree::<2, u8>::from_dense_values(4, &labels2).unwrap();
    write_valued_ktree_file(&p("labels2d.ktree"), &quad).unwrap();
    // An octree of 40 labels in slabs one voxel thick across x: labels 1 … 32 where y < 24 (768 voxels
    // each), 33 … 40 where y ≥ 24 and x < 8 (256 each): the legend keeps the 32 that fill the most voxels.
    let labels3: Vec<Option<u16>> = (0..32u32.pow(3))
        .map(|i| {
            let (x, y) = (i % 32, i / 32 % 32);
            let label = x as u16 + 1 + if y >= 24 { 32 } else { 0 };
            (label <= 40).then_some(label)
        })
        .collect();
    let many = KTree::<3, u16>::from_dense_values(5, &labels3).unwrap();
    write_valued_ktree_file(&p("many.ktree"), &many).unwrap();
    let floats: Vec<Option<f32>> = (0..64u32)
        .map(|i| (i % 3 != 0).then_some(0.5 + (i % 5) as f32 / 2.0))
        .collect();
    write_valued_ktree_file(
        &p("floats.ktree"),
        &KTree::<3, f32>::from_dense_values(2, &floats).unwrap(),
    )
    .unwrap();
    write_ktree_file(&p("shape.ktree"), &many.shape()).unwrap();
    // A 4-D ball of label 1 in the first half of time and 2 in the second; a tree of colours.
    let moving: Vec<Option<u8>> = (0..1usize << 16)
        .map(|i| {
            let [x, y, z, t] = [0, 4, 8, 12].map(|s| ((i >> s) & 15) as f64 + 0.5);
            let inside = (x - 8.0).powi(2) + (y - 8.0).powi(2) + (z - 8.0).powi(2) <= 30.0;
            inside.then_some(if t < 8.0 { 1 } else { 2 })
        })
        .collect();
    write_valued_ktree_file(
        &p("moving.ktree"),
        &KTree::<4, u8>::from_dense_values(4, &moving).unwrap(),
    )
    .unwrap();
    let colours: Vec<Option<ktree::tree::Rgb>> = (0..64u8)
        .map(|i| (i % 2 == 0).then_some([4 * i, 255 - 4 * i, 90]))
        .collect();
    write_valued_ktree_file(
        &p("colours.ktree"),
        &KTree::<3, ktree::tree::Rgb>::from_dense_values(2, &colours).unwrap(),
    )
    .unwrap();
    for name in ["labels2d", "many", "floats", "shape", "moving", "colours"] {
        let (ok, out, err) = ktree(&[
            "view",
            &s(&p(&format!("{name}.ktree"))),
            "--out",
            &s(&p(&format!("{name}.html"))),
        ]);
        assert!(ok, "{name}: {err}");
        assert!(out.contains("boxes"), "{out}");
    }
    // The header carries the legend whether or not a browser is there.
    let legend = &header_of(&p("labels2d.html"))["values"]["legend"];
    assert_eq!(legend["kind"], "labels");
    let entries: Vec<u64> = legend["entries"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e[0].as_u64().unwrap())
        .collect();
    assert_eq!(entries, [3, 10, 17, 24, 50]);
    assert_eq!(
        header_of(&p("shape.html"))["values"],
        serde_json::Value::Null
    );
    let Some(browser) = chromium() else {
        return;
    };
    // The labels of the quadtree: its distinct values, from the dense array.
    let mut distinct: Vec<String> = labels2.iter().flatten().map(u8::to_string).collect();
    distinct.sort_by_key(|v| v.parse::<u32>().unwrap());
    distinct.dedup();
    let (status, errors) = page_status(&browser, &p("labels2d.html"), "");
    assert_eq!(get(&status, "errors"), "0", "{errors}");
    assert_eq!(get(&status, "colour"), "value");
    assert_eq!(get(&status, "legend"), distinct.join(","));
    assert_eq!(get(&status, "legend_more"), "0");
    assert_eq!(legend_of(&browser, &p("labels2d.html"), ""), distinct);
    // Forty labels: the 32 that fill the most voxels, counted from the dense array, and 8 more.
    let mut voxels = std::collections::BTreeMap::<u16, u32>::new();
    for v in labels3.iter().flatten() {
        *voxels.entry(*v).or_default() += 1;
    }
    let mut by_count: Vec<(u16, u32)> = voxels.into_iter().collect();
    by_count.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let mut top: Vec<u16> = by_count.iter().take(32).map(|e| e.0).collect();
    top.sort_unstable();
    let top: Vec<String> = top.iter().map(u16::to_string).collect();
    let (status, errors) = page_status(&browser, &p("many.html"), "");
    assert_eq!(get(&status, "errors"), "0", "{errors}");
    assert_eq!(get(&status, "colour"), "value");
    assert_eq!(get(&status, "legend"), top.join(","));
    assert_eq!(
        get(&status, "legend_more"),
        (by_count.len() - 32).to_string()
    );
    let (status, errors) = page_status(&browser, &p("floats.html"), "");
    assert_eq!(get(&status, "errors"), "0", "{errors}");
    assert_eq!(get(&status, "legend"), "ramp 0.5 2.5");
    let (status, errors) = page_status(&browser, &p("colours.html"), "");
    assert_eq!(get(&status, "errors"), "0", "{errors}");
    assert_eq!(get(&status, "legend"), "stored");
    // A 4-D tree: the slice at time 12 shows label 2 only, in its colour.
    let (status, errors) = page_status(&browser, &p("moving.html"), "#time=12");
    assert_eq!(get(&status, "errors"), "0", "{errors}");
    assert_eq!(get(&status, "colour"), "value");
    assert_eq!(get(&status, "legend"), "1,2");
    assert!(get(&status, "painted").parse::<u64>().unwrap() > 100);
    let shot = p("moving.png");
    run_chromium(
        &browser,
        &format!("file://{}#bare&time=12", p("moving.html").display()),
        &[
            "--window-size=320,240",
            &format!("--screenshot={}", shot.display()),
        ],
    );
    let image = image::open(&shot).unwrap().to_rgb8();
    let drawn: Vec<[u8; 3]> = image
        .pixels()
        .map(|px| px.0)
        .filter(|&px| px != [255, 255, 255])
        .collect();
    assert!(drawn.len() > 1000, "{} pixels drawn", drawn.len());
    for px in drawn {
        assert!(is_shade(px, label_colour(2)), "{px:?} at time 12");
    }
    // The colour menu: another colouring from the URL, and the selftest switches away from by value.
    let (status, _) = page_status(&browser, &p("many.html"), "#colour=depth");
    assert_eq!(get(&status, "colour"), "depth");
    let (status, errors) = page_status(&browser, &p("many.html"), "#selftest");
    assert_eq!(get(&status, "errors"), "0", "{errors}");
    assert_eq!(get(&status, "selftest_colour"), "1", "{status:?}");
    // Without values: by normal as before, whatever the URL asks; no legend.
    for hash in ["", "#colour=value"] {
        let (status, errors) = page_status(&browser, &p("shape.html"), hash);
        assert_eq!(get(&status, "errors"), "0", "{errors}");
        assert_eq!(get(&status, "colour"), "normal", "{hash}");
        assert!(!status.iter().any(|(k, _)| k == "legend"));
    }
    // The quadtree's picture: seen from above, a face's colour is its label's palette colour times the
    // page's shading of an upward face, 0.72 + 0.28 · (light · z) with the light 1, 0.6, 0.3 on the
    // camera's forward (reversed), up and right axes: 0.72 + 0.28 / √1.45; outlines are darker shades.
    let shot = p("labels2d.png");
    run_chromium(
        &browser,
        &format!("file://{}#bare", p("labels2d.html").display()),
        &[
            "--window-size=320,240",
            &format!("--screenshot={}", shot.display()),
        ],
    );
    let image = image::open(&shot).unwrap().to_rgb8();
    let k = 0.72 + 0.28 / 1.45f64.sqrt();
    let labels: Vec<u8> = distinct.iter().map(|v| v.parse().unwrap()).collect();
    let mut faces = vec![0u32; labels.len()];
    for px in image.pixels() {
        let px = px.0;
        if px == [255, 255, 255] {
            continue;
        }
        let shade_of = labels
            .iter()
            .position(|&l| is_shade(px, label_colour(u64::from(l))));
        let Some(i) = shade_of else {
            panic!("{px:?} is the shade of no label's colour");
        };
        let base = label_colour(u64::from(labels[i]));
        if (0..3).all(|c| (f64::from(px[c]) - f64::from(base[c]) * k).abs() <= 2.0) {
            faces[i] += 1;
        }
    }
    for (label, n) in labels.iter().zip(&faces) {
        assert!(*n > 200, "label {label}: {n} pixels of its face colour");
    }
}
