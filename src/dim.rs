//! The dimension `K` known only at run time: the macros that make an enum of the four dimensions of a
//! const-generic type and run generic code on whichever one a value holds. Below every other module, so
//! that any layer can define or use such an enum ([`AnyTree`](crate::AnyTree),
//! [`AnyRaySet`](crate::AnyRaySet), `io::AnyMappedTree`, …) without importing the layer of another.
//!
//! ```
//! use ktree::{with_dim, AnyTree, KTree};
//! let any = AnyTree::from(KTree::<2>::full(3).unwrap());
//! // The expression is compiled once per K; `t` is the `KTree<K>` inside.
//! assert_eq!(with_dim!(&any, AnyTree, t => t.node_count()), 1);
//! ```

/// Runs an expression on the typed value inside an enum of the four dimensions (variants `K1` … `K4`):
/// `with_dim!(any, AnyTree, t => t.node_count())`. The expression is compiled once per `K`. The enum is
/// named by a path in scope at the call, or by one of the crate's own names (`AnyTree`, `AnyRaySet`,
/// `AnyRaysFileSource`, `AnyMappedTree`), which need not be imported.
#[macro_export]
macro_rules! with_dim {
    ($value:expr, AnyTree, $name:ident => $body:expr) => {
        $crate::with_dim!(@match $value, $crate::tree::AnyTree, $name => $body)
    };
    ($value:expr, AnyRaySet, $name:ident => $body:expr) => {
        $crate::with_dim!(@match $value, $crate::rays::AnyRaySet, $name => $body)
    };
    ($value:expr, AnyRaysFileSource, $name:ident => $body:expr) => {
        $crate::with_dim!(@match $value, $crate::io::AnyRaysFileSource, $name => $body)
    };
    ($value:expr, AnyMappedTree, $name:ident => $body:expr) => {
        $crate::with_dim!(@match $value, $crate::io::AnyMappedTree, $name => $body)
    };
    (@match $value:expr, $($kind:ident)::+, $name:ident => $body:expr) => {
        match $value {
            $($kind)::+::K1($name) => $body,
            $($kind)::+::K2($name) => $body,
            $($kind)::+::K3($name) => $body,
            $($kind)::+::K4($name) => $body,
        }
    };
    ($value:expr, $($kind:ident)::+, $name:ident => $body:expr) => {
        $crate::with_dim!(@match $value, $($kind)::+, $name => $body)
    };
}

/// `From<$typed<K>>` for an enum of the four dimensions, by downcasting to the one `K` that matches.
macro_rules! from_typed {
    ($typed:ident, $any:ident) => {
        impl<const K: usize> From<$typed<K>> for $any {
            fn from(value: $typed<K>) -> Self {
                let boxed: Box<dyn std::any::Any> = Box::new(value);
                let boxed = match boxed.downcast::<$typed<1>>() {
                    Ok(v) => return Self::K1(*v),
                    Err(b) => b,
                };
                let boxed = match boxed.downcast::<$typed<2>>() {
                    Ok(v) => return Self::K2(*v),
                    Err(b) => b,
                };
                let boxed = match boxed.downcast::<$typed<3>>() {
                    Ok(v) => return Self::K3(*v),
                    Err(b) => b,
                };
                match boxed.downcast::<$typed<4>>() {
                    Ok(v) => Self::K4(*v),
                    Err(_) => unreachable!("K is checked to be 1..=4 when the value is made"),
                }
            }
        }
    };
}

pub(crate) use from_typed;
