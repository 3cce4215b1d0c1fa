//! The `ktree` binary end to end: build and stats on ray files, the JSON keys users' scripts rely on, and a
//! one-line error with a non-zero exit on bad input.

mod common;

use common::ktree;

use std::path::Path;

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

#[test]
fn build_then_stats_json_has_the_promised_keys() {
    let dir = tempfile::tempdir().unwrap();
    let rays = write(dir.path(), "fig3.rays", "# ktree rays v1\n3 7\n1 1 17 93\n");
    let tree = dir.path().join("fig3.ktree").display().to_string();
    let (ok, _, err) = ktree(&["build", "--rays", &rays, "--out", &tree]);
    assert!(ok, "{err}");
    let (ok, out, err) = ktree(&["stats", &tree, "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for key in [
        "k",
        "level",
        "rays",
        "full",
        "empty",
        "partial",
        "nodes",
        "per_level",
    ] {
        assert!(v.get(key).is_some(), "missing key {key}");
    }
    assert_eq!(v["k"], 3);
    assert_eq!(v["level"], 7);
    assert!(v["rays"].is_null(), "rays is null for a tree file");
    assert_eq!(v["full"], 76);
    // The ray (1, 1, 17, 93): 76 voxels in the box [1, 1, 17] .. [2, 2, 93).
    assert_eq!(v["voxels"], 76);
    assert_eq!(
        v["bounding_box"],
        serde_json::json!([[1, 1, 17], [2, 2, 93]])
    );
    assert!(
        v.get("surface_area").is_none() && v.get("euler_number").is_none(),
        "the measures only when asked for"
    );
    let per_level = v["per_level"].as_array().unwrap();
    for key in ["level", "full", "empty", "partial"] {
        assert!(per_level[0].get(key).is_some(), "per_level misses {key}");
    }
    let sum: u64 = per_level
        .iter()
        .map(|l| {
            l["full"].as_u64().unwrap()
                + l["empty"].as_u64().unwrap()
                + l["partial"].as_u64().unwrap()
        })
        .sum();
    assert_eq!(Some(sum), v["nodes"].as_u64());
    let (ok, out, _) = ktree(&["stats", "--rays", &rays, "--json"]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["rays"], 1);
    // An empty tree: no voxel, no box.
    let empty = write(dir.path(), "empty.rays", "# ktree rays v1\n2 3\n");
    let (ok, out, err) = ktree(&["stats", "--rays", &empty, "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["voxels"], 0);
    assert!(v["bounding_box"].is_null());
}

#[test]
fn bad_input_is_one_line_and_non_zero() {
    let dir = tempfile::tempdir().unwrap();
    for (name, text, needle) in [
        ("empty.rays", "", "empty file"),
        ("fields.rays", "3 5\n1 2 3\n", ":2:"),
        ("range.rays", "3 5\n1 2 3 40\n", ":2:"),
        ("number.rays", "2 5\n1 a 3\n", ":2:"),
        ("k.rays", "7 5\n", ":1:"),
    ] {
        let path = write(dir.path(), name, text);
        let (ok, _, err) = ktree(&["stats", "--rays", &path]);
        assert!(!ok, "{name} accepted");
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(needle) && err.contains(name), "{name}: {err}");
    }
    let garbage = write(dir.path(), "garbage.ktree", "not a tree");
    let (ok, _, err) = ktree(&["stats", &garbage]);
    assert!(!ok && err.contains("garbage.ktree"), "{err}");
    // A failed build leaves no output file behind.
    let bad = write(dir.path(), "bad.rays", "3 5\n1 2 9 3\n");
    let out = dir.path().join("out.ktree");
    let (ok, _, _) = ktree(&["build", "--rays", &bad, "--out", &out.display().to_string()]);
    assert!(!ok && !out.exists());
}

#[test]
fn stats_reports_the_navigable_tree_at_under_2_1_bits_a_node() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ball9.rays");
    let rays = ktree::rays::ball_rays::<3>(9, [512, 512, 512], 512).unwrap();
    ktree::io::write_rays_file(&path, &rays).unwrap();
    let (ok, out, err) = ktree(&["stats", "--rays", &path.display().to_string(), "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let nodes = v["nodes"].as_u64().unwrap();
    let memory = v["memory_bytes"].as_u64().unwrap();
    assert!(nodes > 1_000_000, "{nodes} nodes");
    assert!(
        memory * 8 <= nodes * 21 / 10 + 8 * 4096,
        "{memory} bytes for {nodes} nodes"
    );
    assert!(memory >= v["bytes_at_2_bits"].as_u64().unwrap());
}
