//! Case counts for the property tests: each property has a default, and the environment variable
//! `PROPTEST_CASES` (or `QUICKCHECK_TESTS` for the quickcheck properties), when set, replaces it for every
//! property at once — so the thorough run (`verify/thorough.sh`) raises all of them with one variable.

use proptest::test_runner::Config;

/// The proptest configuration of a block whose default is `default_cases` cases: `PROPTEST_CASES`, when set
/// to a number, wins. The number of rejected cases allowed (by `prop_assume!`) grows with the case count,
/// so a raised count does not fail only for running more cases.
///
/// ```
/// let config = ktree_verify::config(48);
/// if std::env::var("PROPTEST_CASES").is_err() {
///     assert_eq!(config.cases, 48);
/// }
/// assert!(config.max_global_rejects >= config.cases);
/// ```
pub fn config(default_cases: u32) -> Config {
    let cases = cases_from_env("PROPTEST_CASES").unwrap_or(default_cases);
    let defaults = Config::default();
    Config {
        cases,
        max_global_rejects: defaults.max_global_rejects.max(cases.saturating_mul(4)),
        ..defaults
    }
}

/// The number of quickcheck tests of a property whose default is `default_tests`: `QUICKCHECK_TESTS` or,
/// failing that, `PROPTEST_CASES` wins when set to a number.
///
/// ```
/// if std::env::var("QUICKCHECK_TESTS").is_err() && std::env::var("PROPTEST_CASES").is_err() {
///     assert_eq!(ktree_verify::quickcheck_tests(200), 200);
/// }
/// ```
pub fn quickcheck_tests(default_tests: u64) -> u64 {
    cases_from_env("QUICKCHECK_TESTS")
        .or_else(|| cases_from_env("PROPTEST_CASES"))
        .map_or(default_tests, u64::from)
}

/// The case count in the environment variable `name`, if it is set to a number.
fn cases_from_env(name: &str) -> Option<u32> {
    std::env::var(name).ok()?.trim().parse().ok()
}
