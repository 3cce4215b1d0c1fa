//! The library's modules import only downward, as the crate docs draw its layers: a module may name
//! (in a `use` or a path) only modules of a lower layer. The test reads every source file of `src/` (outside
//! `#[cfg(test)]` modules and comments) and fails on an import that goes up or sideways, naming the file.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The layers, lowest first; a module may import the modules of the layers before its own.
const LAYERS: &[&[&str]] = &[
    &["space", "fs", "radix", "dim", "value", "testing"],
    &["rays"],
    &["tree"],
    &["solid"],
    &["stacking", "reference"],
    &["query"],
    &["shape"],
    &["ops"],
    &["map"],
    &["display"],
    &["export"],
    &["io"],
    &["input"],
];

/// Imports that go up today, each `(from, to)`: the list may only shrink (an entry no longer found fails
/// the test, so that it is removed).
const KNOWN: &[(&str, &str)] = &[];

/// Names at the crate's root that belong to a module: the exported macros.
fn owner(name: &str) -> &str {
    match name {
        "with_dim" => "dim",
        "with_tree" => "io",
        other => other,
    }
}

fn layer(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The text of a source file without comments, string contents and its `#[cfg(test)]` module.
fn code(text: &str) -> String {
    let text = match text.find("#[cfg(test)]") {
        Some(at) => &text[..at],
        None => text,
    };
    text.lines()
        .map(|line| match line.find("//") {
            Some(at) => &line[..at],
            None => line,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The crate modules a piece of code names: `crate::m`, and each `m` of `crate::{m, …}`.
/// (`$crate::` paths inside macro definitions are not imports of the defining module.)
fn named_modules(code: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let bytes = code.as_bytes();
    let mut at = 0;
    while let Some(i) = code[at..].find("crate::") {
        let start = at + i;
        at = start + "crate::".len();
        if start > 0
            && (bytes[start - 1] == b'$'
                || bytes[start - 1].is_ascii_alphanumeric()
                || bytes[start - 1] == b'_')
        {
            continue;
        }
        let rest = &code[at..];
        if let Some(group) = rest.strip_prefix('{') {
            let end = group.find('}').unwrap_or(group.len());
            for item in group[..end].split(',') {
                let name: String = item
                    .trim()
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                if !name.is_empty() {
                    found.insert(name);
                }
            }
        } else {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            found.insert(name);
        }
    }
    found
}

/// The modules that the code of module `top`, of layer `from`, names in its own layer or above (a root
/// item — a re-exported type, `max_level`, … — belongs to no module and is passed over).
fn not_below(from: usize, top: &str, code: &str) -> Vec<String> {
    named_modules(code)
        .iter()
        .map(|name| owner(name).to_string())
        .filter(|m| m != top && layer(m).is_some_and(|to| to >= from))
        .collect()
}

#[test]
fn modules_import_only_downward() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut upward = Vec::new();
    let mut seen_known = BTreeSet::new();
    for file in &files {
        let rel = file.strip_prefix(&src).unwrap();
        let top = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy()
            .trim_end_matches(".rs")
            .to_string();
        if top == "lib" {
            continue;
        }
        let from = layer(&top).unwrap_or_else(|| {
            panic!(
                "src/{} belongs to module `{top}`, which no layer lists",
                rel.display()
            )
        });
        let text = std::fs::read_to_string(file).unwrap();
        for to_module in not_below(from, &top, &code(&text)) {
            if KNOWN.contains(&(top.as_str(), to_module.as_str())) {
                seen_known.insert((top.clone(), to_module.clone()));
                continue;
            }
            upward.push(format!("src/{} ({top}) imports {to_module}", rel.display()));
        }
    }
    assert!(
        upward.is_empty(),
        "imports that go up or sideways in the layers (lowest first: {LAYERS:?}):\n{}",
        upward.join("\n")
    );
    for (from, to) in KNOWN {
        assert!(
            seen_known.contains(&(from.to_string(), to.to_string())),
            "{from} no longer imports {to}: remove the pair from KNOWN"
        );
    }
}

#[test]
fn the_scan_finds_grouped_and_plain_imports_but_not_macro_paths() {
    let found =
        named_modules("use crate::{io::X, tree};\nlet a = crate::ops::f();\n$crate::shape::g");
    assert_eq!(found.into_iter().collect::<Vec<_>>(), ["io", "ops", "tree"]);
}

#[test]
fn io_may_not_import_input() {
    // io reads and writes files only: `input`, which voxelizes meshes and volumes on the way in, is above
    // it (and above solid), so io naming it is an upward import.
    let io = layer("io").unwrap();
    let input = layer("input").unwrap();
    assert!(io < input && layer("solid").unwrap() < input);
    let upward = "use crate::input::voxelize;\nuse crate::solid::mesh::TriangleMesh;";
    assert_eq!(not_below(io, "io", &code(upward)), ["input"]);
    let downward =
        "use crate::io::{self, FileTree};\nlet m = crate::solid::mesh::MeshSource::new();";
    assert!(not_below(input, "input", &code(downward)).is_empty());
}
