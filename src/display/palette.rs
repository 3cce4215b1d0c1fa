//! Colours of values for pictures: a categorical palette for labels (neighbouring labels far apart in
//! hue), a colour ramp for floats (dark blue through green to yellow, as viridis), and colours as they are.
//!
//! ```
//! use ktree::display::palette::{label_colour, ramp, value_colours};
//! use ktree::KTree;
//! assert_ne!(label_colour(1), label_colour(2));
//! assert_eq!(ramp(0.0), [68, 1, 84]);
//! let t = KTree::<3, f32>::from_dense_values(1, &[Some(0.0), None, None, None, None, None, None, Some(2.0)]).unwrap();
//! let colour = value_colours(&t);
//! assert_eq!(colour(0.0), ramp(0.0)); // the smallest value at one end of the ramp
//! assert_eq!(colour(2.0), ramp(1.0)); // the largest at the other
//! ```

use crate::value::{Dtype, Value};
use crate::KTree;

/// The colour of label `label`: hues a golden angle apart, so consecutive labels differ clearly.
pub fn label_colour(label: u64) -> [u8; 3] {
    let hue = (label as f64 * 0.618_033_988_749_895).fract() * 6.0;
    let (s, v) = (0.65, 0.95);
    let (i, f) = (hue.floor() as u32 % 6, hue.fract());
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    let (r, g, b) = match i {
        0 => (v, t, p),
        1 => (q, v, p),
        2 => (p, v, t),
        3 => (p, q, v),
        4 => (t, p, v),
        _ => (v, p, q),
    };
    [r, g, b].map(|c| (c * 255.0).round() as u8)
}

/// The colour at `t` (clamped to 0…1) of a ramp through viridis's colours at 0, ¼, ½, ¾ and 1.
pub fn ramp(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) } * 4.0;
    let i = (t.floor() as usize).min(3);
    let f = t - i as f64;
    std::array::from_fn(|c| (STOPS[i][c] + f * (STOPS[i + 1][c] - STOPS[i][c])).round() as u8)
}

/// The colouring of `tree`'s values (any `K`): labels (integer types) by [`label_colour`], floats by
/// [`ramp`] from the tree's smallest value to its largest, colours as they are.
pub fn value_colours<const K: usize, V: Value>(tree: &KTree<K, V>) -> impl Fn(V) -> [u8; 3] {
    colouring(range(tree.value_leaves().filter_map(|(_, v)| v)))
}

/// The colouring of [`value_colours`] for the values `values` (floats ramp from their smallest to their
/// largest): the colours of a tree's values from any list of them.
///
/// ```
/// use ktree::display::palette::{colours_of_values, label_colour, ramp};
/// assert_eq!(colours_of_values([7u16])(7), label_colour(7));
/// assert_eq!(colours_of_values([1.0f32, 3.0])(2.0), ramp(0.5));
/// ```
pub fn colours_of_values<V: Value>(values: impl IntoIterator<Item = V>) -> impl Fn(V) -> [u8; 3] {
    colouring(range(values))
}

/// The number of labels a [`Legend`] lists at most (the most frequent).
pub const LEGEND_LABELS: usize = 32;

/// What the colours of a tree's values mean, for a legend beside its picture.
#[derive(Debug, Clone, PartialEq)]
pub enum Legend<V> {
    /// Labels (integer types): the [`LEGEND_LABELS`] values that fill the most voxels, in increasing order,
    /// each with its colour and its number of voxels, and how many other values the tree holds.
    Labels {
        /// Value, colour, voxels.
        entries: Vec<(V, [u8; 3], u128)>,
        /// Values left out.
        more: usize,
    },
    /// Floats: the [`ramp`] from `min` (at 0) to `max` (at 1); `None` for a tree without values.
    Ramp {
        /// The smallest and largest value.
        range: Option<(V, V)>,
    },
    /// Colours ([`Rgb`](crate::value::Rgb)) drawn as they are stored.
    AsStored,
}

/// The legend of `tree`'s colours ([`value_colours`]).
///
/// ```
/// use ktree::display::palette::{label_colour, value_legend, Legend};
/// use ktree::KTree;
/// let t = KTree::<2, u8>::from_dense_values(1, &[Some(4), Some(4), None, Some(9)]).unwrap();
/// let Legend::Labels { entries, more } = value_legend(&t) else { panic!() };
/// assert_eq!(entries, [(4, label_colour(4), 2), (9, label_colour(9), 1)]);
/// assert_eq!(more, 0);
/// ```
pub fn value_legend<const K: usize, V: Value>(tree: &KTree<K, V>) -> Legend<V> {
    match V::DTYPE {
        Some(Dtype::Rgb) => Legend::AsStored,
        Some(Dtype::F32) => Legend::Ramp {
            range: tree
                .value_leaves()
                .filter_map(|(_, v)| v)
                .fold(None, |range, v| match range {
                    None => Some((v, v)),
                    Some((lo, hi)) => Some((
                        if number(v) < number(lo) { v } else { lo },
                        if number(v) > number(hi) { v } else { hi },
                    )),
                }),
        },
        _ => {
            let mut voxels: std::collections::BTreeMap<i64, (V, u128)> = Default::default();
            for (cell, v) in tree.value_leaves() {
                let Some(v) = v else { continue };
                let n = 1u128
                    .checked_shl(cell.log_side() * K as u32)
                    .unwrap_or(u128::MAX);
                let entry = voxels.entry(number(v) as i64).or_insert((v, 0));
                entry.1 = entry.1.saturating_add(n);
            }
            let mut entries: Vec<(V, u128)> = voxels.into_values().collect();
            let more = entries.len().saturating_sub(LEGEND_LABELS);
            // The most frequent (ties: the smaller value), then shown in increasing order.
            entries.sort_by(|a, b| b.1.cmp(&a.1).then(number(a.0).total_cmp(&number(b.0))));
            entries.truncate(LEGEND_LABELS);
            entries.sort_by(|a, b| number(a.0).total_cmp(&number(b.0)));
            let colour = colouring::<V>((0.0, 1.0));
            Legend::Labels {
                entries: entries
                    .into_iter()
                    .map(|(v, n)| (v, colour(v), n))
                    .collect(),
                more,
            }
        }
    }
}

/// A value as a number.
fn number<V: Value>(v: V) -> f64 {
    v.text().parse().unwrap_or(0.0)
}

/// The smallest and largest of float values (other types: 0 and 1, unused).
fn range<V: Value>(values: impl IntoIterator<Item = V>) -> (f64, f64) {
    if V::DTYPE == Some(Dtype::F32) {
        values
            .into_iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(number(v)), hi.max(number(v)))
            })
    } else {
        (0.0, 1.0)
    }
}

/// The colouring of [`value_colours`], floats ramping from `lo` to `hi`.
fn colouring<V: Value>((lo, hi): (f64, f64)) -> impl Fn(V) -> [u8; 3] {
    move |v: V| match V::DTYPE {
        Some(Dtype::Rgb) => {
            let mut bytes = Vec::with_capacity(3);
            v.write_le(&mut bytes);
            [bytes[0], bytes[1], bytes[2]]
        }
        Some(Dtype::F32) => ramp(if hi > lo {
            (number(v) - lo) / (hi - lo)
        } else {
            0.5
        }),
        _ => label_colour(number(v) as i64 as u64),
    }
}
