//! Triangle meshes to rays.
