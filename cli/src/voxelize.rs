//! `ktree voxelize MESH|VOLUME --level L (--fit | --transform s,tx,ty,tz) --out FILE`: a triangle mesh (OBJ,
//! STL, PLY) or a volume (raw + JSON sidecar, NIfTI) to rays or a tree.

use crate::outln;

use std::path::PathBuf;

use ktree::io::{voxelize, Format, ReadOptions};
use ktree::solid::mesh::Placement;
use ktree::solid::volume::Select;

use crate::rays::write_output;

/// Arguments of `ktree voxelize`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The input: a mesh (.obj, .stl, .ply) or a volume (.json sidecar or its .raw, .nii, .nii.gz).
    input: PathBuf,
    /// Universe level L (meshes: required; volumes: default the smallest level that holds the volume).
    #[arg(long)]
    level: Option<u32>,
    /// Mesh: scale uniformly and centre into the universe with a one-voxel margin (prints the transform).
    #[arg(long, conflicts_with = "transform")]
    fit: bool,
    /// Mesh: voxel coordinate = s·v + t, given as s,tx,ty,tz.
    #[arg(long)]
    transform: Option<String>,
    /// Volume: samples with value ≥ this are inside.
    #[arg(long, conflicts_with = "label")]
    threshold: Option<f64>,
    /// Volume: samples equal to this label are inside.
    #[arg(long)]
    label: Option<f64>,
    /// Volume: where the volume's sample (0, 0, 0) goes in the universe, as x,y,z.
    #[arg(long, default_value = "0,0,0")]
    offset: String,
    /// Output: rays in the text format, or a tree if the name ends in .ktree.
    #[arg(long)]
    out: PathBuf,
    /// Worker threads for stacking a tree (default: all cores). The output is the same for any number.
    #[arg(long)]
    threads: Option<usize>,
    #[command(flatten)]
    build: crate::memory::BuildArgs,
}

/// Voxelizes the input and writes it.
pub fn run(a: Args) -> Result<(), String> {
    let mut options = ReadOptions {
        level: a.level,
        ..ReadOptions::default()
    };
    if Format::of(&a.input) == Some(Format::Mesh) {
        if a.level.is_none() {
            return Err("--level L is required for a mesh".into());
        }
        options.mesh_placement = match (&a.transform, a.fit) {
            (Some(t), _) => Some(Placement::parse(t).map_err(|e| e.to_string())?),
            (None, true) => None,
            (None, false) => return Err("a mesh needs --fit or --transform s,tx,ty,tz".into()),
        };
    } else {
        options.select = match (a.threshold, a.label) {
            (Some(t), _) => Some(Select::AtLeast(t)),
            (None, Some(l)) => Some(Select::Label(l)),
            (None, None) => return Err("a volume needs --threshold T or --label V".into()),
        };
        let off: Vec<u32> = a
            .offset
            .split(',')
            .map(|x| x.trim().parse::<u32>())
            .collect::<Result<_, _>>()
            .map_err(|_| {
                format!(
                    "--offset '{}': expected x,y,z (non-negative integers)",
                    a.offset
                )
            })?;
        let off: [u32; 3] = off
            .try_into()
            .map_err(|_| format!("--offset '{}': expected three numbers", a.offset))?;
        options.offset = Some(off.map(i64::from));
    }
    let v = voxelize(&a.input, &options).map_err(|e| e.to_string())?;
    // In a run over several MPI ranks, rank 0 alone reports.
    let root = crate::distributed::ranks().is_root();
    if let (Some(t), true) = (&v.fitted, root) {
        outln!("--fit chose --transform {t}");
    }
    if v.open_edges > 0 && root {
        eprintln!(
            "warning: {}: the mesh is not closed ({} edges not shared by exactly two triangles); inside is \
             decided by the winding along each column, so some columns may leak or lose runs",
            a.input.display(),
            v.open_edges
        );
    }
    crate::rays::print_summary(&write_output(&v.rays, &a.out, a.threads, &a.build)?)?;
    Ok(())
}
