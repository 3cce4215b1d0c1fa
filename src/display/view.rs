//! Named views: a direction from the object towards the eye, parsed from a name (`iso`, `top`, `bottom`,
//! `front`, `back`, `left`, `right`) or three numbers `X,Y,Z` — the names every command and binding takes;
//! and rendering an octree to a PNG file in one call.
//!
//! ```
//! use ktree::display::{View, ISO_TOWARD_EYE};
//! assert_eq!("iso".parse::<View>().unwrap().toward_eye(), ISO_TOWARD_EYE);
//! assert_eq!("top".parse::<View>().unwrap().toward_eye(), [0.0, 0.0, 1.0]);
//! assert_eq!("1, 2,3".parse::<View>().unwrap().toward_eye(), [1.0, 2.0, 3.0]);
//! assert!("0,0,0".parse::<View>().is_err());
//! assert!("sideways".parse::<View>().is_err());
//! ```

use std::fmt;
use std::str::FromStr;

use super::camera::ISO_TOWARD_EYE;

/// A view direction, from the object towards the eye (finite, not zero).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    toward_eye: [f64; 3],
}

/// The named views and their directions towards the eye.
pub const NAMED_VIEWS: [(&str, [f64; 3]); 7] = [
    ("iso", ISO_TOWARD_EYE),
    ("top", [0.0, 0.0, 1.0]),
    ("bottom", [0.0, 0.0, -1.0]),
    ("front", [0.0, -1.0, 0.0]),
    ("back", [0.0, 1.0, 0.0]),
    ("right", [1.0, 0.0, 0.0]),
    ("left", [-1.0, 0.0, 0.0]),
];

/// Why a text is not a view.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ParseViewError {
    /// Neither a name nor three numbers.
    #[error("view '{0}' must be iso, top, bottom, front, back, left, right or X,Y,Z")]
    Unknown(String),
    /// Three numbers that are all zero or not all finite.
    #[error("the view direction '{0}' must be finite and not zero")]
    Degenerate(String),
}

impl View {
    /// The view towards the eye along `direction`.
    ///
    /// # Errors
    /// [`ParseViewError::Degenerate`] for a zero or non-finite direction.
    pub fn new(direction: [f64; 3]) -> Result<Self, ParseViewError> {
        if direction.iter().all(|x| x.is_finite()) && direction.iter().any(|&x| x != 0.0) {
            Ok(Self {
                toward_eye: direction,
            })
        } else {
            Err(ParseViewError::Degenerate(format!(
                "{},{},{}",
                direction[0], direction[1], direction[2]
            )))
        }
    }

    /// The direction from the object towards the eye.
    pub fn toward_eye(&self) -> [f64; 3] {
        self.toward_eye
    }
}

impl Default for View {
    /// The isometric view ([`ISO_TOWARD_EYE`]).
    fn default() -> Self {
        Self {
            toward_eye: ISO_TOWARD_EYE,
        }
    }
}

impl FromStr for View {
    type Err = ParseViewError;

    fn from_str(text: &str) -> Result<Self, ParseViewError> {
        let name = text.trim();
        if let Some((_, direction)) = NAMED_VIEWS.iter().find(|(n, _)| *n == name) {
            return Ok(Self {
                toward_eye: *direction,
            });
        }
        let numbers: Vec<f64> = name
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| ParseViewError::Unknown(text.to_string()))?;
        let [x, y, z] = numbers[..] else {
            return Err(ParseViewError::Unknown(text.to_string()));
        };
        Self::new([x, y, z]).map_err(|_| ParseViewError::Degenerate(text.to_string()))
    }
}

impl fmt::Display for View {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match NAMED_VIEWS.iter().find(|(_, d)| *d == self.toward_eye) {
            Some((name, _)) => f.write_str(name),
            None => {
                let [x, y, z] = self.toward_eye;
                write!(f, "{x},{y},{z}")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_view_reads_back_from_its_text() {
        for (name, direction) in NAMED_VIEWS {
            let view: View = name.parse().unwrap();
            assert_eq!(view.toward_eye(), direction);
            assert_eq!(view.to_string(), name);
        }
        let odd = View::new([0.5, -2.0, 3.25]).unwrap();
        assert_eq!(odd.to_string().parse::<View>().unwrap(), odd);
        for bad in ["", "1,2", "1,2,3,4", "x,1,2", "nan,0,1", "inf,0,0", "0,0,0"] {
            assert!(bad.parse::<View>().is_err(), "{bad}");
        }
    }
}
