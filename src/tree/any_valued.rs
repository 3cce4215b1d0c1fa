//! Trees with values whose dimension and value type are known only at run time (read from a file's header,
//! chosen by a numpy dtype): [`AnyValuedTree`], and [`with_valued!`](crate::with_valued!) to run generic code
//! on whichever `KTree<K, V>` one holds.

use crate::tree::{AnyTree, KTree, LevelCounts};
use crate::value::{Dtype, Rgb, Value};

/// Defines the enum of every dimension and value type, its `with_valued!` arms and its `From`.
macro_rules! any_valued {
    ($(($variant:ident, $k:literal, $v:ty, $dtype:ident)),* $(,)?) => {
        /// A [`KTree`] with values, of any dimension `K` = 1…4 and any value type ([`Dtype`]): the run-time
        /// counterpart of `KTree<K, V>` as [`AnyTree`] is of `KTree<K>`. Variants are named by `K` and type
        /// (`K3U16` holds a `KTree<3, u16>`); [`with_valued!`](crate::with_valued!) runs code on the one
        /// inside.
        ///
        /// ```
        /// use ktree::value::Dtype;
        /// use ktree::{AnyValuedTree, KTree};
        /// let tree = KTree::<2, u16>::from_dense_values(1, &[Some(7), None, Some(7), Some(9)]).unwrap();
        /// let any = AnyValuedTree::from(tree);
        /// assert_eq!((any.k(), any.dtype(), any.level()), (2, Dtype::U16, 1));
        /// assert_eq!(any.shape().counts().full, 3);
        /// ```
        #[derive(Debug, Clone, PartialEq)]
        #[allow(missing_docs)]
        pub enum AnyValuedTree {
            $($variant(KTree<$k, $v>),)*
        }

        impl<const K: usize, V: Value> From<KTree<K, V>> for AnyValuedTree {
            /// The tree as one of the enum's variants.
            ///
            /// # Panics
            /// When `V` is `()` (a tree without values is an [`AnyTree`]).
            fn from(tree: KTree<K, V>) -> Self {
                let mut boxed: Box<dyn std::any::Any> = Box::new(tree);
                $(
                    boxed = match boxed.downcast::<KTree<$k, $v>>() {
                        Ok(t) => return Self::$variant(*t),
                        Err(b) => b,
                    };
                )*
                drop(boxed);
                panic!("a tree without values is an AnyTree, not an AnyValuedTree")
            }
        }
    };
}

any_valued!(
    (K1U8, 1, u8, U8),
    (K1U16, 1, u16, U16),
    (K1U32, 1, u32, U32),
    (K1I8, 1, i8, I8),
    (K1F32, 1, f32, F32),
    (K1Rgb, 1, Rgb, Rgb),
    (K2U8, 2, u8, U8),
    (K2U16, 2, u16, U16),
    (K2U32, 2, u32, U32),
    (K2I8, 2, i8, I8),
    (K2F32, 2, f32, F32),
    (K2Rgb, 2, Rgb, Rgb),
    (K3U8, 3, u8, U8),
    (K3U16, 3, u16, U16),
    (K3U32, 3, u32, U32),
    (K3I8, 3, i8, I8),
    (K3F32, 3, f32, F32),
    (K3Rgb, 3, Rgb, Rgb),
    (K4U8, 4, u8, U8),
    (K4U16, 4, u16, U16),
    (K4U32, 4, u32, U32),
    (K4I8, 4, i8, I8),
    (K4F32, 4, f32, F32),
    (K4Rgb, 4, Rgb, Rgb),
);

/// Runs an expression on the `KTree<K, V>` inside an [`AnyValuedTree`]: `with_valued!(any, t =>
/// t.node_count())`, compiled once per dimension and value type; or, where no tree exists yet (a file's
/// header, a numpy dtype), with `K` and `V` bound as a constant and a type: `with_valued!(k, dtype, K, V =>
/// body, else other)` (`other` when `k` is not 1…4).
///
/// ```
/// use ktree::value::Dtype;
/// use ktree::{with_valued, AnyValuedTree, KTree};
/// let any = with_valued!(3, Dtype::F32, K, V => {
///     AnyValuedTree::from(KTree::<K, V>::from_dense_values(0, &[None]).unwrap())
/// }, else unreachable!());
/// assert_eq!(with_valued!(&any, t => t.node_count()), 1);
/// assert_eq!(any.dtype(), Dtype::F32);
/// ```
#[macro_export]
macro_rules! with_valued {
    (@bind $k:literal, $v:ty, $K:ident, $V:ident => $body:expr) => {{
        #[allow(dead_code)]
        const $K: usize = $k;
        #[allow(dead_code)]
        type $V = $v;
        $body
    }};
    ($k:expr, $dtype:expr, $K:ident, $V:ident => $body:expr, else $other:expr) => {
        match ($k, $dtype) {
            (1, $crate::value::Dtype::U8) => $crate::with_valued!(@bind 1, u8, $K, $V => $body),
            (1, $crate::value::Dtype::U16) => $crate::with_valued!(@bind 1, u16, $K, $V => $body),
            (1, $crate::value::Dtype::U32) => $crate::with_valued!(@bind 1, u32, $K, $V => $body),
            (1, $crate::value::Dtype::I8) => $crate::with_valued!(@bind 1, i8, $K, $V => $body),
            (1, $crate::value::Dtype::F32) => $crate::with_valued!(@bind 1, f32, $K, $V => $body),
            (1, $crate::value::Dtype::Rgb) => $crate::with_valued!(@bind 1, $crate::value::Rgb, $K, $V => $body),
            (2, $crate::value::Dtype::U8) => $crate::with_valued!(@bind 2, u8, $K, $V => $body),
            (2, $crate::value::Dtype::U16) => $crate::with_valued!(@bind 2, u16, $K, $V => $body),
            (2, $crate::value::Dtype::U32) => $crate::with_valued!(@bind 2, u32, $K, $V => $body),
            (2, $crate::value::Dtype::I8) => $crate::with_valued!(@bind 2, i8, $K, $V => $body),
            (2, $crate::value::Dtype::F32) => $crate::with_valued!(@bind 2, f32, $K, $V => $body),
            (2, $crate::value::Dtype::Rgb) => $crate::with_valued!(@bind 2, $crate::value::Rgb, $K, $V => $body),
            (3, $crate::value::Dtype::U8) => $crate::with_valued!(@bind 3, u8, $K, $V => $body),
            (3, $crate::value::Dtype::U16) => $crate::with_valued!(@bind 3, u16, $K, $V => $body),
            (3, $crate::value::Dtype::U32) => $crate::with_valued!(@bind 3, u32, $K, $V => $body),
            (3, $crate::value::Dtype::I8) => $crate::with_valued!(@bind 3, i8, $K, $V => $body),
            (3, $crate::value::Dtype::F32) => $crate::with_valued!(@bind 3, f32, $K, $V => $body),
            (3, $crate::value::Dtype::Rgb) => $crate::with_valued!(@bind 3, $crate::value::Rgb, $K, $V => $body),
            (4, $crate::value::Dtype::U8) => $crate::with_valued!(@bind 4, u8, $K, $V => $body),
            (4, $crate::value::Dtype::U16) => $crate::with_valued!(@bind 4, u16, $K, $V => $body),
            (4, $crate::value::Dtype::U32) => $crate::with_valued!(@bind 4, u32, $K, $V => $body),
            (4, $crate::value::Dtype::I8) => $crate::with_valued!(@bind 4, i8, $K, $V => $body),
            (4, $crate::value::Dtype::F32) => $crate::with_valued!(@bind 4, f32, $K, $V => $body),
            (4, $crate::value::Dtype::Rgb) => $crate::with_valued!(@bind 4, $crate::value::Rgb, $K, $V => $body),
            _ => $other,
        }
    };
    ($value:expr, $name:ident => $body:expr) => {
        match $value {
            $crate::AnyValuedTree::K1U8($name) => $body,
            $crate::AnyValuedTree::K1U16($name) => $body,
            $crate::AnyValuedTree::K1U32($name) => $body,
            $crate::AnyValuedTree::K1I8($name) => $body,
            $crate::AnyValuedTree::K1F32($name) => $body,
            $crate::AnyValuedTree::K1Rgb($name) => $body,
            $crate::AnyValuedTree::K2U8($name) => $body,
            $crate::AnyValuedTree::K2U16($name) => $body,
            $crate::AnyValuedTree::K2U32($name) => $body,
            $crate::AnyValuedTree::K2I8($name) => $body,
            $crate::AnyValuedTree::K2F32($name) => $body,
            $crate::AnyValuedTree::K2Rgb($name) => $body,
            $crate::AnyValuedTree::K3U8($name) => $body,
            $crate::AnyValuedTree::K3U16($name) => $body,
            $crate::AnyValuedTree::K3U32($name) => $body,
            $crate::AnyValuedTree::K3I8($name) => $body,
            $crate::AnyValuedTree::K3F32($name) => $body,
            $crate::AnyValuedTree::K3Rgb($name) => $body,
            $crate::AnyValuedTree::K4U8($name) => $body,
            $crate::AnyValuedTree::K4U16($name) => $body,
            $crate::AnyValuedTree::K4U32($name) => $body,
            $crate::AnyValuedTree::K4I8($name) => $body,
            $crate::AnyValuedTree::K4F32($name) => $body,
            $crate::AnyValuedTree::K4Rgb($name) => $body,
        }
    };
}

impl AnyValuedTree {
    /// The dimension `K`.
    pub fn k(&self) -> usize {
        with_valued!(self, t => tree_k(t))
    }

    /// The value type.
    pub fn dtype(&self) -> Dtype {
        with_valued!(self, t => tree_dtype(t))
    }

    /// The universe level `L`.
    pub fn level(&self) -> u32 {
        with_valued!(self, t => t.level())
    }

    /// The voxels that hold a value, as a tree without values.
    pub fn shape(&self) -> AnyTree {
        with_valued!(self, t => AnyTree::from(t.shape()))
    }

    /// Node counts per level (nodes with children and mixed ones counted as partial).
    pub fn counts_per_level(&self) -> Vec<LevelCounts> {
        with_valued!(self, t => t.counts_per_level())
    }

    /// Bytes of memory held by the tree and its values.
    pub fn heap_bytes(&self) -> usize {
        with_valued!(self, t => t.heap_bytes())
    }

    /// The tree as `&KTree<K, V>`, or `None` if it has another dimension or value type.
    pub fn as_typed<const K: usize, V: Value>(&self) -> Option<&KTree<K, V>> {
        with_valued!(self, t => (t as &dyn std::any::Any).downcast_ref::<KTree<K, V>>())
    }

    /// The tree as `KTree<K, V>`, or `self` back if it has another dimension or value type.
    ///
    /// # Errors
    /// `Err(self)` when `K` or `V` differs.
    pub fn into_typed<const K: usize, V: Value>(self) -> Result<KTree<K, V>, Self> {
        if self.k() != K || Some(self.dtype()) != V::DTYPE {
            return Err(self);
        }
        let boxed: Box<dyn std::any::Any> = with_valued!(self, t => Box::new(t));
        Ok(*boxed
            .downcast::<KTree<K, V>>()
            .expect("the dimension and value type matched above"))
    }
}

fn tree_k<const K: usize, V: Value>(_: &KTree<K, V>) -> usize {
    K
}

fn tree_dtype<const K: usize, V: Value>(_: &KTree<K, V>) -> Dtype {
    V::DTYPE.expect("an AnyValuedTree holds values")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tree of level 2 whose voxels hold one of three values of `V` or none, by a fixed pattern.
    fn sample<const K: usize, V: Value>(seed: usize) -> KTree<K, V> {
        let dtype = V::DTYPE.unwrap();
        let voxels = 1usize << (2 * K);
        let dense: Vec<Option<V>> = (0..voxels)
            .map(|i| match (i * 7 + seed) % 5 {
                0 | 1 => None,
                m => Some(V::read_le(&vec![m as u8; dtype.bytes()])),
            })
            .collect();
        KTree::from_dense_values(2, &dense).unwrap()
    }

    fn check<const K: usize, V: Value>() {
        let typed = sample::<K, V>(K);
        let any = AnyValuedTree::from(typed.clone());
        assert_eq!((any.k(), Some(any.dtype()), any.level()), (K, V::DTYPE, 2));
        assert_eq!(any.shape(), AnyTree::from(typed.shape()));
        assert_eq!(any.counts_per_level(), typed.counts_per_level());
        assert_eq!(
            with_valued!(&any, t => t.voxel_count()),
            typed.voxel_count()
        );
        // Another K or value type gives the tree back unchanged.
        let any = if K == 1 {
            any.into_typed::<2, V>().unwrap_err()
        } else {
            any.into_typed::<1, V>().unwrap_err()
        };
        let any = if V::DTYPE == Some(Dtype::U8) {
            any.into_typed::<K, u16>().unwrap_err()
        } else {
            any.into_typed::<K, u8>().unwrap_err()
        };
        assert_eq!(any.as_typed::<K, V>(), Some(&typed));
        assert!(any.as_typed::<K, i8>().is_none() || V::DTYPE == Some(Dtype::I8));
        assert_eq!(any.into_typed::<K, V>().unwrap(), typed);
    }

    #[test]
    fn every_dimension_and_value_type_round_trips() {
        for k in 1..=4 {
            for dtype in Dtype::ALL {
                with_valued!(k, dtype, K, V => check::<K, V>(), else unreachable!());
            }
        }
    }

    #[test]
    fn trees_of_other_values_differ() {
        let a = AnyValuedTree::from(sample::<2, u8>(0));
        let b = AnyValuedTree::from(sample::<2, u8>(1));
        assert_ne!(a, b);
        assert_eq!(a, AnyValuedTree::from(sample::<2, u8>(0)));
        assert_ne!(a, AnyValuedTree::from(sample::<2, u16>(0)));
    }

    #[test]
    fn an_unknown_dimension_takes_the_other_branch() {
        let k = with_valued!(5, Dtype::U8, K, V => K + std::mem::size_of::<V>(), else 0);
        assert_eq!(k, 0);
    }
}
