//! A least-significant-digit radix sort for `u64` keys of known width, used by stacking to sort its
//! dimension-level lists in linear time.

/// Below this many keys a comparison sort is faster than clearing histograms.
const SMALL: usize = 192;

/// Sorts `keys` (whose values are below `2^bits`) using `scratch` as a second buffer.
///
/// Cost: `O(passes · (n + 2^digit))` with passes = ⌈bits / 10⌉ (⌈bits / 12⌉ for 65 536 keys or more); passes in which every key has the same
/// digit are skipped.
pub(crate) fn radix_sort(keys: &mut Vec<u64>, bits: u32, scratch: &mut Vec<u64>) {
    let n = keys.len();
    if n < SMALL || bits == 0 {
        keys.sort_unstable();
        return;
    }
    // Wider digits for long lists: fewer passes, and the larger histogram is amortised.
    let max_digit = if n >= 1 << 16 { 12 } else { 10 };
    let passes = bits.div_ceil(max_digit).max(1);
    let digit_bits = bits.div_ceil(passes);
    let buckets = 1usize << digit_bits;
    let mask = (buckets - 1) as u64;
    scratch.clear();
    scratch.resize(n, 0);
    let mut counts = vec![0usize; buckets];
    for pass in 0..passes {
        let shift = pass * digit_bits;
        counts.iter_mut().for_each(|c| *c = 0);
        for &k in keys.iter() {
            counts[((k >> shift) & mask) as usize] += 1;
        }
        if counts.contains(&n) {
            continue; // every key has the same digit: this pass would not move anything
        }
        let mut sum = 0;
        for c in counts.iter_mut() {
            let here = *c;
            *c = sum;
            sum += here;
        }
        for &k in keys.iter() {
            let d = ((k >> shift) & mask) as usize;
            scratch[counts[d]] = k;
            counts[d] += 1;
        }
        std::mem::swap(keys, scratch);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sorts_like_the_standard_library() {
        let mut x = 88172645463325252u64;
        for (n, bits) in [
            (0, 5),
            (10, 5),
            (1000, 3),
            (5000, 20),
            (20000, 42),
            (3000, 64),
        ] {
            let mut v: Vec<u64> = (0..n)
                .map(|_| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    if bits == 64 {
                        x
                    } else {
                        x & ((1u64 << bits) - 1)
                    }
                })
                .collect();
            let mut expected = v.clone();
            expected.sort_unstable();
            radix_sort(&mut v, bits, &mut Vec::new());
            assert_eq!(v, expected, "n={n} bits={bits}");
        }
    }
}
