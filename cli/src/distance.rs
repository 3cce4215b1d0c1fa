//! `ktree distance FILE --band W --out sdf.vdb [--voxel-size S]`: the narrow band of an octree's signed
//! distances as an OpenVDB level set (`FloatGrid`, class `level set`, background `W · S`, values in world
//! units, a uniform scale by `S`), written atomically.

use std::path::PathBuf;

use crate::common::error::{CliError, CliResult};

use ktree::io::write_vdb_level_set;
use ktree::AnyTree;

use crate::common::tree_file::read;

/// Arguments of `ktree distance`.
#[derive(Debug, clap::Args)]
pub struct DistanceArgs {
    /// The tree file (an octree).
    tree: PathBuf,
    /// The band's half-width W in voxels (≥ 1): the voxels with |signed distance| ≤ W are active.
    #[arg(long, default_value_t = 3.0)]
    band: f64,
    /// The level set to write (.vdb).
    #[arg(long)]
    out: PathBuf,
    /// The voxel size S in world units: values and background are in world units (distance · S).
    #[arg(long, default_value_t = 1.0)]
    voxel_size: f64,
}

/// Runs `ktree distance`.
pub fn run(args: DistanceArgs) -> CliResult {
    if !(args.band.is_finite() && args.band >= 1.0) {
        return Err(format!("--band must be a number ≥ 1, got {}", args.band).into());
    }
    if !(args.voxel_size.is_finite() && args.voxel_size > 0.0) {
        return Err(format!(
            "--voxel-size must be a positive number, got {}",
            args.voxel_size
        )
        .into());
    }
    if args.out.extension().and_then(|e| e.to_str()) != Some("vdb") {
        return Err(format!(
            "{}: the level set is written as OpenVDB (.vdb)",
            args.out.display()
        )
        .into());
    }
    let AnyTree::K3(tree) = read(&args.tree)? else {
        return Err(format!(
            "{}: level sets are written for octrees (K = 3) only",
            args.tree.display()
        )
        .into());
    };
    let mut bytes = Vec::new();
    write_vdb_level_set(&mut bytes, &tree, args.band, args.voxel_size)
        .map_err(|e| CliError::in_file(&args.out, e))?;
    ktree::fs::write_atomic(&args.out, &bytes).map_err(CliError::caused)
}
