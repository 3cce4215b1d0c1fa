//! Asking the processor to bring memory into its caches ahead of a read, so that a stream read in an
//! order the hardware prefetchers follow poorly (across pages) is not stalled by each miss.

/// Hints that the cache line holding `slice[at]` will be read soon, to be brought into the outer caches
/// (the second level and beyond): a hint into the first level holds one of its few fill buffers until
/// memory answers, and so stalls the reads themselves when many lines are asked for. Nothing when `at`
/// is past the end, and nothing on processors without the instruction. Changes no result, only when
/// memory arrives.
#[inline(always)]
pub(super) fn prefetch<T>(slice: &[T], at: usize) {
    #[cfg(target_arch = "x86_64")]
    if at < slice.len() {
        let address = slice[at..].as_ptr().cast::<i8>();
        // SAFETY: `_mm_prefetch` is a hint: it reads nothing architecturally, never faults, and SSE (which
        // it requires) is part of every x86-64 processor; the address is inside `slice` besides.
        unsafe { std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T2 }>(address) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (slice, at);
}
