//! Volumes to rays.
