//! Helpers of the library's unit tests.

/// A seeded linear congruential generator (Knuth's MMIX constants): test data that is the same on every
/// run. Its low bits are weak; take numbers from the high ones, as [`Lcg::below`] does.
pub(crate) struct Lcg(pub(crate) u64);

impl Lcg {
    /// Steps the generator and returns its new state.
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        self.0
    }

    /// A number below `n` (not 0), from the state's high bits.
    pub(crate) fn below(&mut self, n: u64) -> u64 {
        (self.next_u64() >> 33) % n
    }
}
