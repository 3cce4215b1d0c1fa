//! `--format-version`: the commands that write trees write `.ktree` version 2 by default and version 1 on
//! request; `stats` reads both (version 2 through a memory map) and prints the same counts; a damaged
//! version 2 file is an error naming the level's section and its byte offset; `mass` of a version 2 file,
//! summed from its memory map (with or without the progressive bounds), equals `mass` of the same tree
//! loaded from version 1, in K = 2, 3 and 4.

mod common;

use common::ktree;

use ktree::io::{ktree_file_version, read_ktree_file};

#[test]
fn both_versions_are_written_and_read_alike() {
    let dir = tempfile::tempdir().unwrap();
    let v2 = dir.path().join("v2.ktree");
    let v1 = dir.path().join("v1.ktree");
    let solid = [
        "rays", "--solid", "ball", "--radius", "11", "--level", "5", "--out",
    ];
    let (ok, _, err) = ktree(&[&solid[..], &[v2.to_str().unwrap()]].concat());
    assert!(ok, "{err}");
    let (ok, _, err) = ktree(
        &[
            &["--format-version", "1"],
            &solid[..],
            &[v1.to_str().unwrap()],
        ]
        .concat(),
    );
    assert!(ok, "{err}");
    assert_eq!(ktree_file_version(&v2).unwrap(), 2);
    assert_eq!(ktree_file_version(&v1).unwrap(), 1);
    assert_eq!(read_ktree_file(&v2).unwrap(), read_ktree_file(&v1).unwrap());
    let (ok2, out2, err) = ktree(&["stats", v2.to_str().unwrap(), "--json"]);
    assert!(ok2, "{err}");
    let (ok1, out1, err) = ktree(&["stats", v1.to_str().unwrap(), "--json"]);
    assert!(ok1, "{err}");
    assert_eq!(out2, out1);
    let (ok, _, _) = ktree(&["--format-version", "3", "stats", v1.to_str().unwrap()]);
    assert!(!ok, "version 3 accepted");
    // Flip a bit in the last level's section: stats names the level and the section's offset.
    let mut bytes = std::fs::read(&v2).unwrap();
    let depth =
        u32::from_le_bytes(bytes[bytes.len() - 8..bytes.len() - 4].try_into().unwrap()) as usize;
    let directory = bytes.len() - 16 - 32 * depth;
    // The last section ends where the directory starts; flip a bit in its first word.
    let mut offset = 16;
    for d in 0..depth - 1 {
        let nodes = u64::from_le_bytes(bytes[directory + 32 * d..][..8].try_into().unwrap());
        let words = nodes.div_ceil(32);
        offset += 8 * (words + words.div_ceil(64)) as usize;
    }
    bytes[offset] ^= 1;
    let bad = dir.path().join("bad.ktree");
    std::fs::write(&bad, &bytes).unwrap();
    let (ok, _, err) = ktree(&["stats", bad.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains(&format!("byte {offset}")), "{err}");
    assert!(err.contains(&format!("level {}", depth - 1)), "{err}");
}

#[test]
fn mass_of_a_mapped_file_equals_mass_of_the_loaded_tree() {
    let dir = tempfile::tempdir().unwrap();
    for k in ["2", "3", "4"] {
        let v2 = dir.path().join(format!("v2-{k}.ktree"));
        let v1 = dir.path().join(format!("v1-{k}.ktree"));
        let args = [
            "rays", "-k", k, "--solid", "ball", "--radius", "9", "--level", "5", "--out",
        ];
        for (version, path) in [("2", &v2), ("1", &v1)] {
            let (ok, _, err) = ktree(
                &[
                    &["--format-version", version],
                    &args[..],
                    &[path.to_str().unwrap()],
                ]
                .concat(),
            );
            assert!(ok, "{err}");
        }
        for tolerance in [&[][..], &["--tolerance", "0.05"], &["--tolerance", "0"]] {
            let (ok2, mapped, err) =
                ktree(&[&["mass", v2.to_str().unwrap(), "--json"], tolerance].concat());
            assert!(ok2, "{err}");
            let (ok1, loaded, err) =
                ktree(&[&["mass", v1.to_str().unwrap(), "--json"], tolerance].concat());
            assert!(ok1, "{err}");
            assert_eq!(mapped, loaded, "K = {k}, {tolerance:?}");
            assert!(mapped.contains("\"volume\""), "{mapped}");
            assert_eq!(
                mapped.contains("\"progressive\": ["),
                !tolerance.is_empty(),
                "{mapped}"
            );
        }
    }
}

#[test]
fn convert_writes_the_version_the_other_commands_write() {
    let dir = tempfile::tempdir().unwrap();
    let rays = dir.path().join("ball.rays");
    let (ok, _, err) = ktree(&[
        "rays",
        "--level",
        "4",
        "--radius",
        "6",
        "--out",
        rays.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let v2 = dir.path().join("v2.ktree");
    let v1 = dir.path().join("v1.ktree");
    let (ok, _, err) = ktree(&["convert", rays.to_str().unwrap(), v2.to_str().unwrap()]);
    assert!(ok, "{err}");
    let (ok, _, err) = ktree(&[
        "--format-version",
        "1",
        "convert",
        rays.to_str().unwrap(),
        v1.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert_eq!(ktree_file_version(&v2).unwrap(), 2);
    assert_eq!(ktree_file_version(&v1).unwrap(), 1);
    assert_eq!(read_ktree_file(&v2).unwrap(), read_ktree_file(&v1).unwrap());
}
