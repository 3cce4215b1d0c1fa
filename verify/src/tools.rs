//! The real tools some tests check ktree against — Chromium, OctoMap, OpenVDB (its C++ library and Python
//! module), a tmpfs only root may mount — found on this machine, with one rule for a test whose tool is
//! missing ([`missing`]): it fails, saying what to install, when the environment variable
//! `KTREE_REQUIRE_TOOLS=1` is set (as `.ci/run` sets it), and otherwise writes a visible `SKIPPED:` line and
//! the test returns. A check that never ran cannot pass CI.

use std::ffi::OsStr;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The environment variable that turns a missing tool from a skipped test into a failed one: set to
/// anything but empty or `0` (`.ci/run` sets it to `1`).
pub const REQUIRE_TOOLS: &str = "KTREE_REQUIRE_TOOLS";

/// The environment variable naming the Python interpreter that has OpenVDB's module (see
/// [`PythonOpenVdb::find`]).
pub const PYTHON_OPENVDB: &str = "KTREE_PYTHON_OPENVDB";

/// Whether a missing tool fails the test: [`REQUIRE_TOOLS`] is set to anything but empty or `0`.
pub fn tools_required() -> bool {
    std::env::var_os(REQUIRE_TOOLS).is_some_and(|v| !v.is_empty() && v != "0")
}

/// What a test does without something it needs, `needed` saying what that is and `install` how to get it:
/// when [`tools_required`], it panics (the test fails) with both; otherwise it writes `SKIPPED: TEST: needs …`
/// to the standard error — straight to it, past the test harness's capture, so the line shows in every run
/// — and returns, and the test returns after it.
///
/// # Panics
/// When [`tools_required`]: that is its purpose.
#[track_caller]
pub fn missing(needed: &str, install: &str) {
    let current = std::thread::current();
    let test = current.name().filter(|n| *n != "main").unwrap_or("test");
    if tools_required() {
        panic!("{test} needs {needed}: {install} ({REQUIRE_TOOLS} is set: a missing tool is an error; unset it to skip)");
    }
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED: {test}: needs {needed}: {install} (set {REQUIRE_TOOLS}=1 to make this an error)"
    );
}

/// The first of `names` found as a file in a folder of the `PATH`, in the `PATH`'s order for each name.
///
/// ```
/// let sh = ktree_verify::tools::find_program(&["sh"]);
/// assert!(sh.is_none_or(|p| p.ends_with("sh")));
/// assert_eq!(ktree_verify::tools::find_program(&["no-such-program-here"]), None);
/// ```
pub fn find_program(names: &[&str]) -> Option<PathBuf> {
    let paths = std::env::var_os("PATH")?;
    names
        .iter()
        .flat_map(|name| std::env::split_paths(&paths).map(move |dir| dir.join(name)))
        .find(|p| p.is_file())
}

/// The first of `names` on the `PATH` (a program may go by several: `chromium`, `google-chrome`), or `None`
/// after [`missing`] with `install`.
///
/// ```
/// if let Some(sh) = ktree_verify::tools::require(&["sh"], "install a POSIX shell") {
///     assert!(std::process::Command::new(sh).arg("-c").arg("true").status().unwrap().success());
/// }
/// ```
#[track_caller]
pub fn require(names: &[&str], install: &str) -> Option<PathBuf> {
    let found = find_program(names);
    if found.is_none() {
        missing(&names.join(" or "), install);
    }
    found
}

/// Builds the C++ program `source` against the installed OctoMap (liboctomap, liboctomath) into
/// `dir`, named as the source's stem; `None` after [`missing`] without `g++` or OctoMap's headers.
///
/// # Panics
/// If the program does not build with both there (with the compiler's messages).
#[track_caller]
pub fn build_octomap_program(dir: &Path, source: &Path) -> Option<PathBuf> {
    let headers = "/usr/include/octomap/octomap.h";
    let install = "install Debian's liboctomap-dev (OctoMap's headers and library)";
    build_program(
        dir,
        source,
        (headers, install),
        &["-O2", "-loctomap", "-loctomath"],
    )
}

/// Builds the C++ program `source` against the installed OpenVDB (libopenvdb, TBB, Imath) into `dir`,
/// named as the source's stem; `None` after [`missing`] without `g++` or OpenVDB's headers.
///
/// # Panics
/// If the program does not build with both there (with the compiler's messages).
#[track_caller]
pub fn build_openvdb_program(dir: &Path, source: &Path) -> Option<PathBuf> {
    let headers = "/usr/include/openvdb/openvdb.h";
    let install = "install Debian's libopenvdb-dev (OpenVDB's headers and library)";
    build_program(
        dir,
        source,
        (headers, install),
        &["-O1", "-lopenvdb", "-ltbb", "-lImath"],
    )
}

/// Builds `source` with `g++` (C++17) and `flags` (optimisation, libraries) into `dir`, once the
/// library's `header` exists (else [`missing`] with its `install` advice).
#[track_caller]
fn build_program(
    dir: &Path,
    source: &Path,
    (header, install): (&str, &str),
    flags: &[&str],
) -> Option<PathBuf> {
    let compiler = require(&["g++"], "install g++")?;
    if !require_file(Path::new(header), install) {
        return None;
    }
    let exe = dir.join(source.file_stem().expect("a source file"));
    let built = std::process::Command::new(compiler)
        .args(["-std=c++17", "-o"])
        .arg(&exe)
        .arg(source)
        .args(flags)
        .output()
        .expect("g++ runs");
    assert!(
        built.status.success(),
        "{} does not build: {}",
        source.display(),
        String::from_utf8_lossy(&built.stderr)
    );
    Some(exe)
}

/// Whether the file `path` (a library's header, say) exists; `false` after [`missing`] with `install`.
#[track_caller]
pub fn require_file(path: &Path, install: &str) -> bool {
    let found = path.is_file();
    if !found {
        missing(&path.display().to_string(), install);
    }
    found
}

/// A Python interpreter that imports OpenVDB's module (`pyopenvdb`, as Debian's `python3-openvdb` installs it
/// for Debian's own `/usr/bin/python3`, or `openvdb`, its name in newer OpenVDB releases).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PythonOpenVdb {
    /// The interpreter, as it was found (a path, or a name looked up on the `PATH`).
    pub python: PathBuf,
    /// The module's name: `pyopenvdb` or `openvdb`.
    pub module: String,
}

impl PythonOpenVdb {
    /// Finds the interpreter (once a process): the one [`PYTHON_OPENVDB`] names when it is set, else the first
    /// of `python3` on the `PATH` and `/usr/bin/python3` that imports the module. The error says what was
    /// tried and what each lacked.
    pub fn find() -> Result<Self, String> {
        static FOUND: OnceLock<Result<PythonOpenVdb, String>> = OnceLock::new();
        FOUND
            .get_or_init(|| {
                let candidates: Vec<PathBuf> = match std::env::var_os(PYTHON_OPENVDB) {
                    Some(python) if !python.is_empty() => vec![python.into()],
                    _ => vec!["python3".into(), "/usr/bin/python3".into()],
                };
                let mut tried = Vec::new();
                for python in candidates {
                    match openvdb_module(&python) {
                        Ok(module) => return Ok(Self { python, module }),
                        Err(why) => tried.push(format!("{}: {why}", python.display())),
                    }
                }
                Err(tried.join("; "))
            })
            .clone()
    }

    /// Runs `script` with the module imported as `vdb` and `args` as `sys.argv[1:]`: its standard output, or
    /// the interpreter's standard error when it fails.
    pub fn run(&self, script: &str, args: &[&OsStr]) -> Result<String, String> {
        let out = Command::new(&self.python)
            .arg("-c")
            .arg(format!("import {} as vdb\n{script}", self.module))
            .args(args)
            .output()
            .map_err(|e| format!("{}: {e}", self.python.display()))?;
        if !out.status.success() {
            return Err(format!(
                "{} failed ({}): {}",
                self.python.display(),
                out.status,
                String::from_utf8_lossy(&out.stderr)
            ));
        }
        String::from_utf8(out.stdout).map_err(|e| format!("{}: {e}", self.python.display()))
    }
}

/// [`PythonOpenVdb::find`] for a test: the interpreter, or `None` after [`missing`].
#[track_caller]
pub fn require_python_openvdb() -> Option<PythonOpenVdb> {
    match PythonOpenVdb::find() {
        Ok(found) => Some(found),
        Err(tried) => {
            missing(
                &format!("a Python with OpenVDB's module (tried {tried})"),
                &format!(
                    "install Debian's python3-openvdb (for /usr/bin/python3), or set {PYTHON_OPENVDB} to an \
                     interpreter that imports pyopenvdb or openvdb"
                ),
            );
            None
        }
    }
}

/// The OpenVDB module `python` imports, `pyopenvdb` first; or why there is none.
fn openvdb_module(python: &Path) -> Result<String, String> {
    const PROBE: &str = "for m in ('pyopenvdb', 'openvdb'):\n    try:\n        __import__(m)\n    \
                         except ImportError:\n        continue\n    print(m)\n    break";
    let out = Command::new(python)
        .args(["-c", PROBE])
        .output()
        .map_err(|e| e.to_string())?;
    let module = String::from_utf8_lossy(&out.stdout).trim().to_string();
    if out.status.success() && !module.is_empty() {
        Ok(module)
    } else if out.status.success() {
        Err("imports neither pyopenvdb nor openvdb".into())
    } else {
        Err(format!(
            "failed ({}): {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        ))
    }
}

/// A Python interpreter that imports `module` (the first of `python3` on the `PATH` and Debian's
/// `/usr/bin/python3` that does, where Debian's `python3-…` packages install), or `None` after [`missing`]
/// with `install`.
///
/// ```
/// // `sys` is always there; a test asks for e.g. `nibabel`.
/// if let Some(python) = ktree_verify::tools::require_python_module("sys", "install Python 3") {
///     assert!(std::process::Command::new(python).arg("-V").status().unwrap().success());
/// }
/// ```
#[track_caller]
pub fn require_python_module(module: &str, install: &str) -> Option<PathBuf> {
    let mut tried = Vec::new();
    for python in ["python3", "/usr/bin/python3"] {
        let ok = Command::new(python)
            .args(["-c", &format!("import {module}")])
            .output()
            .is_ok_and(|o| o.status.success());
        if ok {
            return Some(PathBuf::from(python));
        }
        tried.push(python);
    }
    missing(
        &format!(
            "a Python that imports {module} (tried {})",
            tried.join(", ")
        ),
        install,
    );
    None
}
