//! Least-significant-digit radix sorting by `u64` keys of known width: linear time where a comparison
//! sort takes `n log n`. Stacking sorts its dimension-level lists with it, the mesh voxelizer its edges
//! and crossings, and the batched point queries their points in Morton order.

/// Below this many items a comparison sort is faster than clearing histograms.
const SMALL: usize = 192;

/// Sorts `keys` (whose values are below `2^bits`) using `scratch` as a second buffer.
///
/// Cost: `O(passes · (n + 2^digit))` with passes = ⌈bits / 10⌉ (⌈bits / 12⌉ for 65 536 keys or more);
/// passes in which every key has the same digit are skipped.
pub(crate) fn radix_sort(keys: &mut Vec<u64>, bits: u32, scratch: &mut Vec<u64>) {
    sort_by_key(keys, bits, scratch, |&k| k);
}

/// Sorts `items` stably by `key`, whose values are below `2^bits`, using `scratch` as a second buffer:
/// items of equal keys keep their order. Costs as [`radix_sort`].
pub(crate) fn sort_by_key<T: Copy>(
    items: &mut Vec<T>,
    bits: u32,
    scratch: &mut Vec<T>,
    key: impl Fn(&T) -> u64,
) {
    let n = items.len();
    if n < SMALL || bits == 0 {
        items.sort_by_key(&key);
        return;
    }
    // Wider digits for long lists: fewer passes, and the larger histogram is amortised.
    let max_digit = if n >= 1 << 16 { 12 } else { 10 };
    let passes = bits.div_ceil(max_digit).max(1);
    let digit_bits = bits.div_ceil(passes);
    let buckets = 1usize << digit_bits;
    let mask = (buckets - 1) as u64;
    scratch.clear();
    scratch.extend_from_slice(items);
    let mut counts = vec![0usize; buckets];
    for pass in 0..passes {
        let shift = pass * digit_bits;
        counts.iter_mut().for_each(|c| *c = 0);
        for item in items.iter() {
            counts[((key(item) >> shift) & mask) as usize] += 1;
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
        for item in items.iter() {
            let d = ((key(item) >> shift) & mask) as usize;
            scratch[counts[d]] = *item;
            counts[d] += 1;
        }
        std::mem::swap(items, scratch);
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

    #[test]
    fn pairs_sort_stably_by_key() {
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        for (len, bits) in [
            (0, 3),
            (10, 64),
            (63, 5),
            (64, 1),
            (1000, 12),
            (5000, 30),
            (3000, 64),
        ] {
            let order: Vec<(u64, u32)> = (0..len)
                .map(|i| {
                    state = state
                        .wrapping_mul(6_364_136_223_846_793_005)
                        .wrapping_add(1);
                    let key = if bits == 64 {
                        state
                    } else {
                        state >> (64 - bits)
                    };
                    (key, i)
                })
                .collect();
            let mut expect = order.clone();
            expect.sort_unstable();
            let mut got = order;
            sort_by_key(&mut got, bits, &mut Vec::new(), |p| p.0);
            assert_eq!(got, expect, "{len} pairs of {bits}-bit keys");
        }
    }
}
