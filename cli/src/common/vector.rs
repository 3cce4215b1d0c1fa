//! Vectors on the command line: `x,y,z` (or any number of coordinates) separated by commas, each of which
//! may be negative.
//!
//! Every flag that takes a vector parses it with [`vector`] (a fixed number of coordinates) or [`list`]
//! (as many as the tree's K, checked by the command) as its clap value parser, and sets
//! `allow_hyphen_values = true` so that `--origin -1,-1,0` reads as written (without it clap takes `-1`
//! for a flag). A test below walks every command and holds each flag whose value is named `X,Y,Z` or `…,…`
//! to that.

use std::fmt::Display;
use std::str::FromStr;

use ktree::solid::Rational;

/// A number a vector is made of, with what a wrong one is called in a message.
pub trait Coordinate: FromStr + Copy + Send + Sync + 'static {
    /// What the coordinates are, in the plural: "numbers", "integers", ….
    const WHAT: &'static str;

    /// Whether a parsed value is acceptable (floating-point numbers: finite).
    fn is_valid(&self) -> bool {
        true
    }
}

impl Coordinate for f64 {
    const WHAT: &'static str = "finite numbers";

    fn is_valid(&self) -> bool {
        self.is_finite()
    }
}

impl Coordinate for i64 {
    const WHAT: &'static str = "integers";
}

impl Coordinate for u32 {
    const WHAT: &'static str = "non-negative integers";
}

impl Coordinate for Rational {
    const WHAT: &'static str = "numbers (decimals or fractions p/q)";
}

/// Coordinates separated by commas, as many as given (a command checks their number against its K).
#[derive(Debug, Clone, PartialEq)]
pub struct List<T>(pub Vec<T>);

/// Parses coordinates separated by commas: the clap value parser of a vector of any length.
///
/// # Errors
/// A message naming the coordinate that is not a `T`.
pub fn list<T: Coordinate>(text: &str) -> Result<List<T>, String>
where
    T::Err: Display,
{
    text.split(',')
        .map(|part| match part.trim().parse::<T>() {
            Ok(v) if v.is_valid() => Ok(v),
            Ok(_) => Err(format!("'{}' is not one of the {}", part.trim(), T::WHAT)),
            Err(e) => Err(format!("'{}': {e}; expected {}", part.trim(), T::WHAT)),
        })
        .collect::<Result<_, _>>()
        .map(List)
}

/// Parses exactly `N` coordinates separated by commas (`x,y,z` for `N` = 3): the clap value parser of a
/// vector of a fixed length.
///
/// # Errors
/// A message saying what was expected.
pub fn vector<T: Coordinate, const N: usize>(text: &str) -> Result<[T; N], String>
where
    T::Err: Display,
{
    let v = list::<T>(text)?.0;
    let n = v.len();
    v.try_into()
        .map_err(|_| format!("expected {N} {} separated by commas, got {n}", T::WHAT))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_parse_negative_and_fractional_coordinates() {
        assert_eq!(vector::<f64, 3>("-1,-1,0").unwrap(), [-1.0, -1.0, 0.0]);
        assert_eq!(
            vector::<f64, 3>(" 0.5 , -2e1,3").unwrap(),
            [0.5, -20.0, 3.0]
        );
        assert_eq!(vector::<i64, 3>("-16,0,7").unwrap(), [-16, 0, 7]);
        assert_eq!(list::<f64>("1,-2").unwrap(), List(vec![1.0, -2.0]));
        let half: Rational = "-1/2".parse().unwrap();
        assert_eq!(list::<Rational>("-1/2").unwrap(), List(vec![half]));
        for bad in ["1,2", "1,2,3,4", "a,b,c", "1,,2", "1,inf,2", "1,NaN,2"] {
            assert!(vector::<f64, 3>(bad).is_err(), "{bad}");
        }
        assert!(vector::<u32, 3>("-1,0,0").is_err());
        assert!(vector::<i64, 3>("1.5,0,0").is_err());
    }

    /// Every flag whose value is a vector takes a negative first coordinate as written.
    #[test]
    fn every_vector_flag_takes_values_that_begin_with_a_minus() {
        use clap::CommandFactory;
        let mut vectors = 0;
        let root = crate::Cli::command();
        for command in root.get_subcommands() {
            for arg in command.get_arguments() {
                let names = arg.get_value_names().unwrap_or_default();
                if names.iter().any(|n| n.as_str().contains(',')) {
                    vectors += 1;
                    assert!(
                        arg.is_allow_hyphen_values_set(),
                        "ktree {} --{}: a vector flag must take values beginning with '-'",
                        command.get_name(),
                        arg.get_id()
                    );
                }
            }
        }
        assert!(vectors >= 15, "only {vectors} vector flags found");
    }
}
