//! The rule for a test whose tool is missing (`ktree_verify::tools`): a visible `SKIPPED:` line and a pass,
//! or a failure naming what to install under `KTREE_REQUIRE_TOOLS=1`; and the interpreter with OpenVDB's
//! module found where `KTREE_PYTHON_OPENVDB` says. Each case runs this test binary again as a child, with
//! its own environment, on one of the `child_` tests below (which do nothing in an ordinary run).

use std::ffi::OsStr;
use std::io::Write as _;
use std::os::unix::fs::PermissionsExt as _;
use std::path::Path;
use std::process::{Command, Output};
use std::sync::Mutex;

use ktree_verify::tools::{self, PythonOpenVdb, PYTHON_OPENVDB, REQUIRE_TOOLS};

/// Set in the children's environment: the `child_` tests act only when it is.
const CHILD: &str = "KTREE_VERIFY_TOOLS_CHILD";

/// Held while a child runs and while a stand-in program is written: a child forked while another test
/// holds a program open for writing would keep it open, and running that program would fail as busy.
static SPAWNING: Mutex<()> = Mutex::new(());

#[test]
fn child_without_a_tool() {
    if std::env::var_os(CHILD).is_some() {
        tools::missing("the tool frobnicate", "install frobnicate");
    }
}

#[test]
fn child_finding_python_openvdb() {
    if std::env::var_os(CHILD).is_some() {
        let found = PythonOpenVdb::find();
        let ran = found
            .as_ref()
            .map(|p| p.run("print(vdb)", &[OsStr::new("an argument")]));
        let _ = writeln!(std::io::stderr(), "found {found:?}\nran {ran:?}");
    }
}

/// Runs the test `name` of this binary as a child, `KTREE_REQUIRE_TOOLS` set to `require` (or unset) and
/// `KTREE_PYTHON_OPENVDB` to `python` (or unset); the harness captures what the test prints, as usual.
fn child(name: &str, require: Option<&str>, python: Option<&Path>) -> (Output, String) {
    let mut command = Command::new(std::env::current_exe().unwrap());
    command.args([name, "--exact"]).env(CHILD, "1");
    match require {
        Some(value) => command.env(REQUIRE_TOOLS, value),
        None => command.env_remove(REQUIRE_TOOLS),
    };
    match python {
        Some(path) => command.env(PYTHON_OPENVDB, path),
        None => command.env_remove(PYTHON_OPENVDB),
    };
    let out = {
        let _alone = SPAWNING.lock().unwrap_or_else(|e| e.into_inner());
        command.output().unwrap()
    };
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out, text)
}

#[test]
fn a_missing_tool_skips_visibly_or_fails_when_tools_are_required() {
    for require in [None, Some(""), Some("0")] {
        let (out, text) = child("child_without_a_tool", require, None);
        assert!(out.status.success(), "{require:?}: {text}");
        // On the standard error itself, not in the output the harness captured (shown only on failure).
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains(
                "SKIPPED: child_without_a_tool: needs the tool frobnicate: install frobnicate"
            ),
            "{require:?}: {text}"
        );
    }
    for require in ["1", "yes"] {
        let (out, text) = child("child_without_a_tool", Some(require), None);
        assert!(!out.status.success(), "{require}: {text}");
        assert!(
            text.contains("child_without_a_tool needs the tool frobnicate: install frobnicate")
                && text.contains(REQUIRE_TOOLS),
            "{require}: {text}"
        );
        assert!(!text.contains("SKIPPED"), "{require}: {text}");
    }
}

#[test]
fn the_python_named_by_the_environment_is_the_one_used() {
    let dir = tempfile::tempdir().unwrap();
    // Stand-ins for interpreters: one "imports" `openvdb` and echoes the script and argument it runs, one
    // has no module, and one does not exist.
    let write_program = |name: &str, body: &str| {
        let path = dir.path().join(name);
        let _alone = SPAWNING.lock().unwrap_or_else(|e| e.into_inner());
        std::fs::write(&path, format!("#!/bin/sh\n{body}\n")).unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
        path
    };
    let with = write_program(
        "with-openvdb",
        "case \"$2\" in for*) echo openvdb ;; *) printf '%s|%s' \"$2\" \"$3\" ;; esac",
    );
    let without = write_program("without-openvdb", "exit 0");
    let absent = dir.path().join("absent");

    let (out, text) = child("child_finding_python_openvdb", None, Some(&with));
    assert!(out.status.success(), "{text}");
    let want = PythonOpenVdb {
        python: with.clone(),
        module: "openvdb".into(),
    };
    assert!(text.contains(&format!("found Ok({want:?})")), "{text}");
    assert!(
        text.contains(r#"ran Ok(Ok("import openvdb as vdb\nprint(vdb)|an argument"))"#),
        "{text}"
    );

    for python in [&without, &absent] {
        let (out, text) = child("child_finding_python_openvdb", None, Some(python));
        assert!(out.status.success(), "{text}");
        // Only the interpreter named was tried, and the error says what it lacked.
        let found = text.lines().find(|l| l.starts_with("found ")).unwrap();
        assert!(
            found.starts_with("found Err(") && found.contains(&python.display().to_string()),
            "{text}"
        );
        assert!(!found.contains("/usr/bin/python3"), "{text}");
    }
    let (_, text) = child("child_finding_python_openvdb", None, Some(&without));
    assert!(
        text.contains("imports neither pyopenvdb nor openvdb"),
        "{text}"
    );
}
