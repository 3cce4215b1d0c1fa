//! `ktree view FILE [--out view.html] [--budget N] [--camera VIEW] [--time-axis A] [--open]`: an
//! interactive 3-D view of a tree in one self-contained HTML page (see `ktree::export::view`); a tree with
//! values is coloured by value, with a legend.

use crate::common::error::{CliError, CliResult};
use crate::outln;

use std::path::{Path, PathBuf};

use ktree::display::View;
use ktree::export::view::{write_values_view, write_view, Page, ViewOptions, DEFAULT_BUDGET};
use ktree::tree::cursor::TreeStorage;
use ktree::with_tree;

/// Arguments of `ktree view`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The tree: a `.ktree` file or any format `ktree convert` reads (K = 2: flat squares; K = 3: boxes;
    /// K = 4: a slider over the time axis; a tree with values: coloured by value, with a legend).
    file: PathBuf,
    /// The page to write (default: a new file in the temporary folder, its path printed).
    #[arg(long)]
    out: Option<PathBuf>,
    /// The most boxes in the page: coarser levels are drawn as boxes of their partial cells where the
    /// budget does not reach.
    #[arg(long, default_value_t = DEFAULT_BUDGET, value_name = "N")]
    budget: usize,
    /// The first camera, as `ktree render --camera` takes it: iso, top, bottom, front, back, left, right
    /// or X,Y,Z (default: iso; top for a quadtree).
    #[arg(long, value_name = "VIEW|X,Y,Z", allow_hyphen_values = true)]
    camera: Option<String>,
    /// 4-D trees: the axis the slider moves along.
    #[arg(long, default_value_t = 3)]
    time_axis: usize,
    /// Open the page in the system's browser (xdg-open), when there is one.
    #[arg(long)]
    open: bool,
}

/// Writes the page.
pub fn run(args: Args) -> CliResult {
    let camera = match &args.camera {
        Some(name) => Some(name.parse::<View>().map_err(CliError::caused)?),
        None => None,
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| temporary_page(&args.file));
    let options = ViewOptions {
        budget: args.budget,
        camera,
        time_axis: args.time_axis,
        title: args
            .file
            .file_name()
            .map_or_else(|| "ktree".into(), |n| n.to_string_lossy().into_owned()),
    };
    if crate::values::is_valued(&args.file) {
        let tree = crate::values::read_valued(&args.file)?;
        let page = ktree::with_valued!(&tree, t => {
            write_values_view(&out, t, &options).map_err(CliError::caused)
        })?;
        return report(&args, &out, &page);
    }
    // A version 2 file is read through its memory map, whatever its size.
    let file = ktree::input::open_tree(&args.file, &ktree::io::ReadOptions::default())
        .map_err(CliError::caused)?;
    let page = with_tree!(&file, t => page_of(t, &out, &options))?;
    report(&args, &out, &page)
}

/// Says what was written, and opens it if asked.
fn report(args: &Args, out: &Path, page: &Page) -> CliResult {
    outln!(
        "wrote {} ({} boxes{}, {} bytes)",
        out.display(),
        page.boxes,
        if page.complete {
            String::new()
        } else {
            format!(
                ", {} of them coarse: the budget of {} was reached",
                page.coarse, args.budget
            )
        },
        page.html.len()
    );
    if args.open {
        open(out)?;
    }
    Ok(())
}

fn page_of<const K: usize, T: TreeStorage<K>>(
    tree: &T,
    out: &Path,
    options: &ViewOptions,
) -> CliResult<Page> {
    write_view(out, tree, options).map_err(CliError::caused)
}

/// A new page's path in the temporary folder, named after the input.
fn temporary_page(file: &Path) -> PathBuf {
    let stem = file
        .file_stem()
        .map_or_else(|| "tree".into(), |s| s.to_string_lossy().into_owned());
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    std::env::temp_dir().join(format!(
        "ktree-view-{stem}-{}-{nanos:09}.html",
        std::process::id()
    ))
}

/// Opens the page with `xdg-open` when it is on the `PATH`; says so when it is not (never an error).
fn open(page: &Path) -> CliResult {
    let found = std::env::var_os("PATH").is_some_and(|paths| {
        std::env::split_paths(&paths).any(|dir| dir.join("xdg-open").is_file())
    });
    if !found {
        outln!(
            "no browser to open it with (xdg-open is not installed): open {} in a browser",
            page.display()
        );
        return Ok(());
    }
    match std::process::Command::new("xdg-open").arg(page).spawn() {
        Ok(_) => outln!("opening {} with xdg-open", page.display()),
        Err(e) => outln!(
            "could not run xdg-open ({e}): open {} in a browser",
            page.display()
        ),
    }
    Ok(())
}
