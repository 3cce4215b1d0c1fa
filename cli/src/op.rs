//! `ktree op union|intersect|diff|xor A B --out C` and `ktree op not A --out B`: Boolean operations on
//! `.ktree` files.
//!
//! When the inputs are `.ktree` version 2 files and the output is one too, the operation streams from the
//! inputs' memory maps to the output in bounded memory ([`ktree::io::boolean_files`]), with its spill
//! files in `--temp-dir`; it is also faster than loading the trees. Otherwise (a version 1 file) the trees
//! are read into memory, if they and the result fit in the budget (`--max-memory`).

use crate::common::error::{CliError, CliResult};
use std::path::PathBuf;

use ktree::io::{self, ktree_file_version, BooleanFileReport};
use ktree::ops::BoolOp;

use crate::common::tree_file::{pair_error, print_summary, read_framed, write_framed};

/// Arguments of `ktree op`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The operation: union, intersect, diff (A minus B), xor, or not (complement of A).
    operation: Operation,
    /// The input tree files: two for union/intersect/diff/xor, one for not.
    #[arg(required = true, num_args = 1..=2)]
    inputs: Vec<PathBuf>,
    #[command(flatten)]
    out: crate::common::args::TreeOut,
    #[command(flatten)]
    threads: crate::common::args::ThreadsArg,
    #[command(flatten)]
    budget: crate::common::memory::BudgetArgs,
    /// Folder for the temporary spill files of an operation streamed out of core (default: the output's
    /// folder).
    #[arg(long, value_name = "DIR")]
    temp_dir: Option<PathBuf>,
}

/// The operations `ktree op` runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Operation {
    /// A ∪ B.
    Union,
    /// A ∩ B.
    Intersect,
    /// A ∖ B.
    Diff,
    /// A △ B.
    Xor,
    /// The complement of A.
    Not,
}

impl Operation {
    /// The Boolean of two trees, or `None` for the complement.
    fn binary(self) -> Option<BoolOp> {
        match self {
            Self::Union => Some(BoolOp::Union),
            Self::Intersect => Some(BoolOp::Intersection),
            Self::Diff => Some(BoolOp::Difference),
            Self::Xor => Some(BoolOp::SymmetricDifference),
            Self::Not => None,
        }
    }
}

/// Checks that the operation fits in the budget: it holds its input trees (about as large in memory as in
/// their files) and a result at most as large as them together.
fn check_budget(args: &Args) -> CliResult {
    let mut files = 0u64;
    for input in &args.inputs {
        files += std::fs::metadata(input)
            .map_err(|e| CliError::in_file(input, e))?
            .len();
    }
    let names: Vec<String> = args
        .inputs
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    args.budget.left_after(
        &format!(
            "the trees of {} and the result (held in memory)",
            names.join(" and ")
        ),
        files.saturating_mul(2),
    )?;
    Ok(())
}

/// The operation streamed from the inputs' memory maps to the output, if the inputs and the output are
/// `.ktree` version 2 files (`None` otherwise).
fn stream_op(args: &Args) -> Option<CliResult> {
    let all_v2 = crate::common::tree_file::version() == 2
        && args
            .inputs
            .iter()
            .all(|p| ktree_file_version(p).is_ok_and(|v| v == 2));
    if !all_v2 {
        return None;
    }
    let temp = args.temp_dir.as_deref();
    let report: Result<BooleanFileReport, _> = match args.inputs.as_slice() {
        [a] if args.operation == Operation::Not => io::complement_file(a, &args.out.out, temp),
        [a, b] => io::boolean_files(a, b, args.operation.binary()?, &args.out.out, temp),
        _ => return None,
    };
    Some(
        report
            .map_err(CliError::caused)
            .and_then(|r| print_summary(&args.out.out, r.k, r.level, &r.counts_per_level)),
    )
}

/// Runs the operation and writes the result, on a pool of `--threads` worker threads.
pub fn run(args: Args) -> CliResult {
    let threads = args.threads.threads;
    crate::common::threads::with_threads(threads, || run_op(args))?
}

fn run_op(args: Args) -> CliResult {
    if let Some(streamed) = stream_op(&args) {
        return streamed;
    }
    check_budget(&args)?;
    let Some(op) = args.operation.binary() else {
        let [a] = args.inputs.as_slice() else {
            return Err("`ktree op not` takes exactly one input tree".into());
        };
        let (tree, frame, notes) = read_framed(a)?;
        let out = tree.complement();
        return ktree::with_dim!(&out, AnyTree, t => write_framed(&args.out.out, t, frame.as_ref(), &notes));
    };
    let [a, b] = args.inputs.as_slice() else {
        return Err(format!("`ktree op {}` takes exactly two input trees", op.name()).into());
    };
    let ((ta, fa, na), (tb, fb, nb)) = (read_framed(a)?, read_framed(b)?);
    let out = ta.boolean(&tb, op).map_err(|e| pair_error(a, b, e))?;
    // The frame and notes a streamed Boolean keeps.
    let (a, b) = (a.display().to_string(), b.display().to_string());
    let (frame, notes) =
        io::boolean_header((&a, fa, &na), (&b, fb, &nb)).map_err(CliError::caused)?;
    ktree::with_dim!(&out, AnyTree, t => write_framed(&args.out.out, t, frame.as_ref(), &notes))
}
