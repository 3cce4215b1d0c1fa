//! The ray text format: read whole ([`read_rays`]) or slab by slab from a sorted file ([`open_rays_file`]),
//! and written from a ray set or a ray source.

mod source;
mod text;

pub use source::{open_rays_file, AnyRaysFileSource, RaysFile, RaysFileSource};
pub use text::{
    read_rays, read_rays_file, write_rays, write_rays_file, write_rays_source, RaysTextError,
    RaysTextErrorKind,
};
