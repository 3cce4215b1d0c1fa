//! Colours of a map's voxels from coloured points, as OctoMap's `ColorOcTree` keeps them: a colour a voxel,
//! for the voxels the map has observed.

use super::{tree_from_leaves, OccupancyMap, MAP_LEVEL};
use crate::space::morton_encode;
use crate::value::{mean_colour, Rgb};
use crate::KTree;

impl<const K: usize> OccupancyMap<K> {
    /// The colours of the observed voxels holding `points` (world coordinates), each the mean of its
    /// points' `colours` (each channel rounded to the nearest), at the map's keys — what
    /// [`write_color_ot_map`](crate::io::write_color_ot_map) writes with the map. Points in unknown
    /// voxels or outside the map colour nothing (a `ColorOcTree` colours the nodes it has).
    ///
    /// ```
    /// use ktree::map::OccupancyMap;
    /// let mut map = OccupancyMap::<3>::new(0.1).unwrap();
    /// let points = [[1.01, 0.05, 0.05], [1.09, 0.05, 0.05], [5.0, 5.0, 5.0]];
    /// map.insert(&points[..2], [0.05; 3], None).unwrap();
    /// let colours = map.colours_of_points(&points, &[[200, 0, 0], [101, 10, 0], [0, 0, 255]]).unwrap();
    /// // The two points share a voxel: their mean. The third point's voxel is unknown.
    /// assert_eq!(colours.value_at(map.grid().keys([1.05f32, 0.05, 0.05]).unwrap()), Some([151, 5, 0]));
    /// assert_eq!(colours.voxel_count(), 1);
    /// ```
    ///
    /// # Errors
    /// A message if `points` and `colours` differ in length or a point's coordinate is not finite.
    pub fn colours_of_points(
        &self,
        points: &[[f32; K]],
        colours: &[Rgb],
    ) -> Result<KTree<K, Rgb>, String> {
        if points.len() != colours.len() {
            return Err(format!(
                "{} points and {} colours: a colour for each point",
                points.len(),
                colours.len()
            ));
        }
        if let Some(i) = points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(format!("point {i} has a coordinate that is not a number"));
        }
        let mut keyed: Vec<(u64, Rgb)> = points
            .iter()
            .zip(colours)
            .filter_map(|(&p, &c)| {
                let key = self.grid().keys(p)?;
                self.log_odds()
                    .value_at(key)
                    .map(|_| (morton_encode(key), c))
            })
            .collect();
        keyed.sort_unstable_by_key(|k| k.0);
        let mut leaves = Vec::new();
        for voxel in keyed.chunk_by(|a, b| a.0 == b.0) {
            let colours: Vec<Rgb> = voxel.iter().map(|&(_, c)| c).collect();
            let mean = mean_colour(&colours);
            leaves.push((voxel[0].0, 0, mean));
        }
        // Never fails: the leaves are distinct voxels of the map's level and colours are always values.
        tree_from_leaves(MAP_LEVEL, &leaves).map_err(|e| e.to_string())
    }
}
