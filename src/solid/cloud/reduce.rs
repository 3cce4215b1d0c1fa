//! How the points of a voxel give it one value ([`CloudVoxelizer::voxelize_values`]): the mean colour,
//! the mean or largest intensity, the most frequent class. Each takes the values of one voxel's points
//! (never none).
//!
//! [`CloudVoxelizer::voxelize_values`]: super::CloudVoxelizer::voxelize_values

pub use crate::value::mean_colour;

/// The mean intensity (summed in `f64`).
///
/// ```
/// assert_eq!(ktree::solid::cloud::mean_intensity(&[1.0, 2.0]), 1.5);
/// ```
pub fn mean_intensity(intensities: &[f32]) -> f32 {
    let sum: f64 = intensities.iter().map(|&i| f64::from(i)).sum();
    (sum / intensities.len().max(1) as f64) as f32
}

/// The largest intensity.
///
/// ```
/// assert_eq!(ktree::solid::cloud::max_intensity(&[1.0, 7.0, 2.0]), 7.0);
/// ```
pub fn max_intensity(intensities: &[f32]) -> f32 {
    intensities
        .iter()
        .copied()
        .fold(f32::NEG_INFINITY, f32::max)
}

/// The most frequent class; of classes equally frequent, the smallest.
///
/// ```
/// assert_eq!(ktree::solid::cloud::most_frequent_class(&[5, 2, 5, 2, 9]), 2);
/// ```
pub fn most_frequent_class(classes: &[u8]) -> u8 {
    let mut counts = [0u32; 256];
    for &c in classes {
        counts[usize::from(c)] += 1;
    }
    // `max_by_key` keeps the last of equals: walk from 255 down so the smallest class wins ties.
    (0..=255u8)
        .rev()
        .max_by_key(|&c| counts[usize::from(c)])
        .unwrap_or(0)
}
