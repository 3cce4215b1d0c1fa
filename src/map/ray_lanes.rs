//! Many rays' traversals stepped side by side: eight rays at a time on a processor with AVX-512F, four
//! with AVX2, one in each lane of the vectors, each lane stepping its ray exactly as [`super::traverse`]
//! steps one (the same `f64` sums and comparisons, the same tie-breaking), so every ray crosses the same
//! voxels; only the order in which the voxels of different rays are handed on changes. A lane whose ray
//! ends takes the next ray. Elsewhere the rays are walked one after another.
//!
//! A ray's step is a chain of dependent operations (add, compare, choose the axis) that one ray alone
//! cannot overlap; the rays in the lanes of one vector go through that chain together.

use super::grid::MapGrid;
use super::traverse::visit_morton_ray;
#[cfg(target_arch = "x86_64")]
use super::traverse::{MortonWalk, RayOrigin};
use super::voxel_set::VoxelSet;

/// Adds to `set` the Morton key of every voxel that each ray from `origin` to one of `ends` crosses, as
/// [`visit_morton_ray`] finds them. Returns the number of rays that leave the map (they add nothing).
pub(crate) fn add_rays<const K: usize>(
    set: &mut VoxelSet,
    grid: &MapGrid,
    origin: [f32; K],
    ends: &[[f32; K]],
) -> usize {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: `add_rays` is compiled for AVX-512F, which the processor was just found to have;
            // it requires nothing else of its caller.
            return unsafe { avx512::add_rays(set, grid, origin, ends) };
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: as above, for AVX2.
            return unsafe { avx2::add_rays(set, grid, origin, ends) };
        }
    }
    one_by_one(set, grid, origin, ends)
}

/// The rays walked one after another.
fn one_by_one<const K: usize>(
    set: &mut VoxelSet,
    grid: &MapGrid,
    origin: [f32; K],
    ends: &[[f32; K]],
) -> usize {
    ends.iter()
        .filter(|&&end| !visit_morton_ray(grid, origin, end, |code| set.insert(code)))
        .count()
}

/// The walks of the rays in `N` lanes, one array of lanes for each field.
#[cfg(target_arch = "x86_64")]
struct Lanes<const K: usize, const N: usize> {
    code: [u64; N],
    code_end: [u64; N],
    length: [f64; N],
    t_max: [[f64; N]; K],
    t_delta: [[f64; N]; K],
    carry: [[u64; N]; K],
    add: [[u64; N]; K],
    /// The set's block each lane added to last, and the index of its first word in the set's words.
    block: [u64; N],
    first_word: [u64; N],
}

#[cfg(target_arch = "x86_64")]
impl<const K: usize, const N: usize> Lanes<K, N> {
    fn new() -> Self {
        Self {
            code: [0; N],
            code_end: [0; N],
            length: [0.0; N],
            t_max: [[f64::MAX; N]; K],
            t_delta: [[0.0; N]; K],
            carry: [[0; N]; K],
            add: [[0; N]; K],
            // No block: a Morton key shifted by the block's bits is below 2^49.
            block: [u64::MAX; N],
            first_word: [0; N],
        }
    }

    fn set(&mut self, lane: usize, walk: &MortonWalk<K>) {
        self.code[lane] = walk.code;
        self.code_end[lane] = walk.code_end;
        self.length[lane] = walk.length;
        for i in 0..K {
            self.t_max[i][lane] = walk.t_max[i];
            self.t_delta[i][lane] = walk.t_delta[i];
            self.carry[i][lane] = walk.carry[i];
            self.add[i][lane] = walk.add[i];
        }
    }
}

/// [`add_rays`] with `N` lanes stepped by `step`, which steps the rays of the lanes whose bits are set
/// in its `live` mask, adding the voxels they cross to the set, until at least one of them ends, and
/// returns the mask of the lanes whose rays ended. Each free lane takes the next ray that crosses a voxel.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn in_lanes<const K: usize, const N: usize>(
    set: &mut VoxelSet,
    grid: &MapGrid,
    origin: [f32; K],
    ends: &[[f32; K]],
    mut step: impl FnMut(&mut Lanes<K, N>, u32, &mut VoxelSet) -> u32,
) -> usize {
    let Some(from) = RayOrigin::new(grid, origin) else {
        return ends.len();
    };
    let mut lanes = Lanes::<K, N>::new();
    let (mut next_ray, mut outside) = (0, 0);
    // The lanes holding a ray.
    let mut live = 0u32;
    loop {
        for lane in 0..N {
            if live & (1 << lane) != 0 {
                continue;
            }
            while let Some(&end) = ends.get(next_ray) {
                next_ray += 1;
                match MortonWalk::start_from(grid, &from, end) {
                    None => outside += 1,
                    Some(None) => {}
                    Some(Some((first, walk))) => {
                        set.insert(first);
                        lanes.set(lane, &walk);
                        live |= 1 << lane;
                        break;
                    }
                }
            }
        }
        if live == 0 {
            return outside;
        }
        live &= !step(&mut lanes, live, set);
    }
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    use super::super::grid::MapGrid;
    use super::super::traverse;
    use super::super::voxel_set::{VoxelSet, BLOCK_BITS, WORDS};

    /// The rays stepped side by side.
    const LANES: usize = 8;

    type Lanes<const K: usize> = super::Lanes<K, LANES>;

    /// [`super::add_rays`] eight rays at a time.
    ///
    /// # Safety
    /// The processor must have AVX-512F.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn add_rays<const K: usize>(
        set: &mut VoxelSet,
        grid: &MapGrid,
        origin: [f32; K],
        ends: &[[f32; K]],
    ) -> usize {
        // The bits of each axis in a Morton key: the same for every ray.
        let axis_bits: [__m512i; K] =
            std::array::from_fn(|i| _mm512_set1_epi64(traverse::axis_bits::<K>(i) as i64));
        super::in_lanes(set, grid, origin, ends, |lanes, live, set| {
            u32::from(step_until_one_ends(
                lanes,
                &axis_bits,
                live as __mmask8,
                set,
            ))
        })
    }

    /// Steps the rays of the `live` lanes, adding the voxels they cross to `set`, until at least one of
    /// them ends; returns the lanes whose rays ended.
    /// (Its own function, so that the refilling of lanes does not crowd its registers.)
    #[inline(never)]
    #[target_feature(enable = "avx512f")]
    fn step_until_one_ends<const K: usize>(
        lanes: &mut Lanes<K>,
        axis_bits: &[__m512i; K],
        live: __mmask8,
        set: &mut VoxelSet,
    ) -> __mmask8 {
        let mut code = load_u64(&lanes.code);
        let code_end = load_u64(&lanes.code_end);
        let length = load_f64(&lanes.length);
        let mut t_max: [__m512d; K] = std::array::from_fn(|i| load_f64(&lanes.t_max[i]));
        let t_delta: [__m512d; K] = std::array::from_fn(|i| load_f64(&lanes.t_delta[i]));
        let carry: [__m512i; K] = std::array::from_fn(|i| load_u64(&lanes.carry[i]));
        let add: [__m512i; K] = std::array::from_fn(|i| load_u64(&lanes.add[i]));
        let mut block = load_u64(&lanes.block);
        let mut first_word = load_u64(&lanes.first_word);
        let mut nearest = minimum(&t_max);
        let ended = loop {
            // The axis each ray steps: the last whose time is the smallest (OctoMap's comparisons).
            let mut step = [0 as __mmask8; K];
            let mut taken: __mmask8 = 0;
            for i in (0..K).rev() {
                let equal = _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(t_max[i], nearest);
                step[i] = equal & !taken;
                taken |= equal;
            }
            let (mut bits, mut up, mut plus) = (axis_bits[0], carry[0], add[0]);
            for i in 1..K {
                bits = _mm512_mask_mov_epi64(bits, step[i], axis_bits[i]);
                up = _mm512_mask_mov_epi64(up, step[i], carry[i]);
                plus = _mm512_mask_mov_epi64(plus, step[i], add[i]);
            }
            // The chosen axis's bits counted up or down by one, as `MortonWalk::next_voxel` counts them.
            let stepped = _mm512_and_si512(
                _mm512_add_epi64(_mm512_or_si512(_mm512_and_si512(code, bits), up), plus),
                bits,
            );
            code = _mm512_or_si512(stepped, _mm512_andnot_si512(bits, code));
            for i in 0..K {
                t_max[i] = _mm512_mask_add_pd(t_max[i], step[i], t_max[i], t_delta[i]);
            }
            nearest = minimum(&t_max);
            let at_end = _mm512_cmpeq_epi64_mask(code, code_end);
            let past_end = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(nearest, length);
            let ended = (at_end | past_end) & live;
            let crossed = live & !ended;
            // Each lane's voxel: its block's bitmap (looked up only when the lane enters another
            // block), the word and the bit in it.
            let now_in = _mm512_srli_epi64::<BLOCK_BITS>(code);
            let moved = _mm512_mask_cmpneq_epi64_mask(crossed, now_in, block);
            if moved != 0 {
                let blocks = store_u64(now_in);
                let mut left = moved;
                while left != 0 {
                    let lane = left.trailing_zeros() as usize;
                    let word = (set.bitmap_of(blocks[lane]) * WORDS) as i64;
                    // Into the lane's register (no store to memory read back whole).
                    first_word = _mm512_mask_set1_epi64(first_word, 1 << lane, word);
                    left &= left - 1;
                }
                block = _mm512_mask_mov_epi64(block, moved, now_in);
            }
            let local = _mm512_and_si512(code, _mm512_set1_epi64((1 << BLOCK_BITS) - 1));
            // The word of each lane's voxel and its bit; for a lane that crossed nothing, word 0 and
            // no bit, so that every lane is written without a branch.
            let word = store_u64(_mm512_maskz_add_epi64(
                crossed,
                first_word,
                _mm512_srli_epi64::<6>(local),
            ));
            let bit = store_u64(_mm512_maskz_sllv_epi64(
                crossed,
                _mm512_set1_epi64(1),
                _mm512_and_si512(local, _mm512_set1_epi64(63)),
            ));
            let words = set.words_mut();
            if !words.is_empty() {
                for lane in 0..LANES {
                    words[word[lane] as usize] |= bit[lane];
                }
            }
            if ended != 0 {
                break ended;
            }
        };
        lanes.code = store_u64(code);
        lanes.block = store_u64(block);
        lanes.first_word = store_u64(first_word);
        for (lane_times, &times) in lanes.t_max.iter_mut().zip(&t_max) {
            *lane_times = store_f64(times);
        }
        ended
    }

    /// The smallest of the `K` times, lane by lane.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn minimum<const K: usize>(t_max: &[__m512d; K]) -> __m512d {
        let mut nearest = t_max[0];
        for &t in &t_max[1..] {
            nearest = _mm512_min_pd(nearest, t);
        }
        nearest
    }

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn load_f64(lanes: &[f64; LANES]) -> __m512d {
        // SAFETY: the pointer is valid for reading 64 bytes (the array's); unaligned loads are allowed.
        unsafe { _mm512_loadu_pd(lanes.as_ptr()) }
    }

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn load_u64(lanes: &[u64; LANES]) -> __m512i {
        // SAFETY: as in `load_f64`.
        unsafe { _mm512_loadu_si512(lanes.as_ptr().cast()) }
    }

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn store_f64(vector: __m512d) -> [f64; LANES] {
        let mut lanes = [0.0; LANES];
        // SAFETY: the pointer is valid for writing 64 bytes (the array's); unaligned stores are allowed.
        unsafe { _mm512_storeu_pd(lanes.as_mut_ptr(), vector) };
        lanes
    }

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn store_u64(vector: __m512i) -> [u64; LANES] {
        let mut lanes = [0; LANES];
        // SAFETY: as in `store_f64`.
        unsafe { _mm512_storeu_si512(lanes.as_mut_ptr().cast(), vector) };
        lanes
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use super::super::grid::MapGrid;
    use super::super::traverse;
    use super::super::voxel_set::{VoxelSet, BLOCK_BITS, WORDS};

    /// The rays stepped side by side.
    const LANES: usize = 4;

    type Lanes<const K: usize> = super::Lanes<K, LANES>;

    /// [`super::add_rays`] four rays at a time.
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn add_rays<const K: usize>(
        set: &mut VoxelSet,
        grid: &MapGrid,
        origin: [f32; K],
        ends: &[[f32; K]],
    ) -> usize {
        // The bits of each axis in a Morton key: the same for every ray.
        let axis_bits: [__m256i; K] =
            std::array::from_fn(|i| _mm256_set1_epi64x(traverse::axis_bits::<K>(i) as i64));
        super::in_lanes(set, grid, origin, ends, |lanes, live, set| {
            step_until_one_ends(lanes, &axis_bits, live, set)
        })
    }

    /// Steps the rays of the `live` lanes (a bit a lane), adding the voxels they cross to `set`, until at
    /// least one of them ends; returns the lanes whose rays ended. As the AVX-512 version, with each
    /// mask a vector of lanes all ones or all zeros.
    #[inline(never)]
    #[target_feature(enable = "avx2")]
    fn step_until_one_ends<const K: usize>(
        lanes: &mut Lanes<K>,
        axis_bits: &[__m256i; K],
        live: u32,
        set: &mut VoxelSet,
    ) -> u32 {
        let mut code = load_u64(&lanes.code);
        let code_end = load_u64(&lanes.code_end);
        let length = load_f64(&lanes.length);
        let mut t_max: [__m256d; K] = std::array::from_fn(|i| load_f64(&lanes.t_max[i]));
        let t_delta: [__m256d; K] = std::array::from_fn(|i| load_f64(&lanes.t_delta[i]));
        let carry: [__m256i; K] = std::array::from_fn(|i| load_u64(&lanes.carry[i]));
        let add: [__m256i; K] = std::array::from_fn(|i| load_u64(&lanes.add[i]));
        let mut block = load_u64(&lanes.block);
        let mut first_word = load_u64(&lanes.first_word);
        let live_lanes = load_u64(&std::array::from_fn(|lane| {
            if live & (1 << lane) != 0 {
                u64::MAX
            } else {
                0
            }
        }));
        let mut nearest = minimum(&t_max);
        let ended = loop {
            // The axis each ray steps: the last whose time is the smallest (OctoMap's comparisons).
            let mut step = [_mm256_setzero_si256(); K];
            let mut taken = _mm256_setzero_si256();
            for i in (0..K).rev() {
                let equal = _mm256_castpd_si256(_mm256_cmp_pd::<_CMP_EQ_OQ>(t_max[i], nearest));
                step[i] = _mm256_andnot_si256(taken, equal);
                taken = _mm256_or_si256(taken, equal);
            }
            let (mut bits, mut up, mut plus) = (axis_bits[0], carry[0], add[0]);
            for i in 1..K {
                bits = _mm256_blendv_epi8(bits, axis_bits[i], step[i]);
                up = _mm256_blendv_epi8(up, carry[i], step[i]);
                plus = _mm256_blendv_epi8(plus, add[i], step[i]);
            }
            // The chosen axis's bits counted up or down by one, as `MortonWalk::next_voxel` counts them.
            let stepped = _mm256_and_si256(
                _mm256_add_epi64(_mm256_or_si256(_mm256_and_si256(code, bits), up), plus),
                bits,
            );
            code = _mm256_or_si256(stepped, _mm256_andnot_si256(bits, code));
            for i in 0..K {
                let later = _mm256_add_pd(t_max[i], t_delta[i]);
                t_max[i] = _mm256_blendv_pd(t_max[i], later, _mm256_castsi256_pd(step[i]));
            }
            nearest = minimum(&t_max);
            let at_end = _mm256_cmpeq_epi64(code, code_end);
            let past_end = _mm256_castpd_si256(_mm256_cmp_pd::<_CMP_GT_OQ>(nearest, length));
            let ended = _mm256_and_si256(_mm256_or_si256(at_end, past_end), live_lanes);
            let crossed = _mm256_andnot_si256(ended, live_lanes);
            // Each lane's voxel: its block's bitmap (looked up only when the lane enters another
            // block), the word and the bit in it.
            let now_in = _mm256_srli_epi64::<{ BLOCK_BITS as i32 }>(code);
            let moved = _mm256_andnot_si256(_mm256_cmpeq_epi64(now_in, block), crossed);
            let moved_lanes = mask_bits(moved);
            if moved_lanes != 0 {
                let blocks = store_u64(now_in);
                let mut words = store_u64(first_word);
                let mut left = moved_lanes;
                while left != 0 {
                    let lane = left.trailing_zeros() as usize;
                    words[lane] = (set.bitmap_of(blocks[lane]) * WORDS) as u64;
                    left &= left - 1;
                }
                first_word = load_u64(&words);
                block = _mm256_blendv_epi8(block, now_in, moved);
            }
            let local = _mm256_and_si256(code, _mm256_set1_epi64x((1 << BLOCK_BITS) - 1));
            // The word of each lane's voxel and its bit; for a lane that crossed nothing, word 0 and
            // no bit, so that every lane is written without a branch.
            let word = store_u64(_mm256_and_si256(
                _mm256_add_epi64(first_word, _mm256_srli_epi64::<6>(local)),
                crossed,
            ));
            let bit = store_u64(_mm256_and_si256(
                _mm256_sllv_epi64(
                    _mm256_set1_epi64x(1),
                    _mm256_and_si256(local, _mm256_set1_epi64x(63)),
                ),
                crossed,
            ));
            let words = set.words_mut();
            if !words.is_empty() {
                for lane in 0..LANES {
                    words[word[lane] as usize] |= bit[lane];
                }
            }
            let ended = mask_bits(ended);
            if ended != 0 {
                break ended;
            }
        };
        lanes.code = store_u64(code);
        lanes.block = store_u64(block);
        lanes.first_word = store_u64(first_word);
        for (lane_times, &times) in lanes.t_max.iter_mut().zip(&t_max) {
            *lane_times = store_f64(times);
        }
        ended
    }

    /// The lanes of a mask (each all ones or all zeros) as bits.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn mask_bits(mask: __m256i) -> u32 {
        _mm256_movemask_pd(_mm256_castsi256_pd(mask)) as u32
    }

    /// The smallest of the `K` times, lane by lane.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn minimum<const K: usize>(t_max: &[__m256d; K]) -> __m256d {
        let mut nearest = t_max[0];
        for &t in &t_max[1..] {
            nearest = _mm256_min_pd(nearest, t);
        }
        nearest
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn load_f64(lanes: &[f64; LANES]) -> __m256d {
        // SAFETY: the pointer is valid for reading 32 bytes (the array's); unaligned loads are allowed.
        unsafe { _mm256_loadu_pd(lanes.as_ptr()) }
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn load_u64(lanes: &[u64; LANES]) -> __m256i {
        // SAFETY: as in `load_f64`.
        unsafe { _mm256_loadu_si256(lanes.as_ptr().cast()) }
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn store_f64(vector: __m256d) -> [f64; LANES] {
        let mut lanes = [0.0; LANES];
        // SAFETY: the pointer is valid for writing 32 bytes (the array's); unaligned stores are allowed.
        unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), vector) };
        lanes
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn store_u64(vector: __m256i) -> [u64; LANES] {
        let mut lanes = [0; LANES];
        // SAFETY: as in `store_f64`.
        unsafe { _mm256_storeu_si256(lanes.as_mut_ptr().cast(), vector) };
        lanes
    }
}

#[cfg(test)]
mod tests {
    use super::super::voxel_set::Union;
    use super::*;
    use proptest::prelude::*;

    /// The rays add the voxels the rays walked one by one cross, and count the rays leaving the map.
    fn same_as_one_by_one<const K: usize>(
        origin: [f32; K],
        ends: &[[f32; K]],
        res: f64,
    ) -> Result<(), TestCaseError> {
        let grid = MapGrid::new(res).unwrap();
        let mut expected = Vec::new();
        let mut outside = 0;
        for &end in ends {
            if !visit_morton_ray(&grid, origin, end, |k| expected.push(k)) {
                outside += 1;
            }
        }
        expected.sort_unstable();
        expected.dedup();
        // The lanes where the processor has them, and the rays one by one as elsewhere.
        let mut lanes = VoxelSet::new();
        prop_assert_eq!(add_rays(&mut lanes, &grid, origin, ends), outside);
        let mut single = VoxelSet::new();
        prop_assert_eq!(one_by_one(&mut single, &grid, origin, ends), outside);
        let mut sets = vec![lanes, single];
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let mut four = VoxelSet::new();
            // SAFETY: the processor has AVX2, all `avx2::add_rays` asks of its caller.
            prop_assert_eq!(
                unsafe { avx2::add_rays(&mut four, &grid, origin, ends) },
                outside
            );
            sets.push(four);
        }
        for set in sets {
            prop_assert_eq!(&Union::of(vec![set]).into_keys_without(&[]), &expected);
        }
        Ok(())
    }

    /// Ends near the origin and far from it, some beyond the map, some in the origin's voxel.
    fn end<const K: usize>() -> impl Strategy<Value = [f32; K]> {
        prop_oneof![
            16 => prop::array::uniform(-5.0f32..5.0),
            4 => prop::array::uniform(-0.05f32..0.05),
            // Long rays to the map's edge or beyond it (few: each crosses thousands of voxels).
            1 => prop::array::uniform(prop_oneof![-4000.0f32..-3270.0, 3270.0f32..4000.0]),
        ]
    }

    /// Coordinates on voxel centres and borders of a resolution that is a power of two (so exact in
    /// `f32`): rays along diagonals, whose times along two axes are equal at every border (the ties
    /// between axes), and rays ending on a border (the end reached exactly).
    fn aligned<const K: usize>() -> impl Strategy<Value = ([f32; K], Vec<[f32; K]>, f64)> {
        (
            prop_oneof![Just(0.25f64), Just(0.5), Just(1.0)],
            prop::array::uniform::<_, K>(-4i32..4),
            prop::collection::vec(
                (
                    1i32..30,
                    prop::array::uniform::<_, K>(-1i32..=1),
                    prop::array::uniform::<_, K>(-1i32..=1),
                ),
                0..40,
            ),
        )
            .prop_map(|(res, at, rays)| {
                let half = res as f32 / 2.0;
                let origin = at.map(|a| (2 * a + 1) as f32 * half);
                let ends = rays
                    .into_iter()
                    .map(|(n, along, off): (i32, [i32; K], [i32; K])| {
                        std::array::from_fn(|i| {
                            origin[i] + (2 * n * along[i] + off[i]) as f32 * half
                        })
                    })
                    .collect();
                (origin, ends, res)
            })
    }

    proptest! {
        #[test]
        fn lanes_cross_the_voxels_of_aligned_rays_k2((o, ends, res) in aligned::<2>()) {
            same_as_one_by_one(o, &ends, res)?;
        }

        #[test]
        fn lanes_cross_the_voxels_of_aligned_rays_k3((o, ends, res) in aligned::<3>()) {
            same_as_one_by_one(o, &ends, res)?;
        }

        #[test]
        fn lanes_cross_the_voxels_of_each_ray_k1(o in prop::array::uniform(-1.0f32..1.0), ends in prop::collection::vec(end::<1>(), 0..40), res in 0.05f64..0.5) {
            same_as_one_by_one(o, &ends, res)?;
        }

        #[test]
        fn lanes_cross_the_voxels_of_each_ray_k2(o in prop::array::uniform(-1.0f32..1.0), ends in prop::collection::vec(end::<2>(), 0..40), res in 0.05f64..0.5) {
            same_as_one_by_one(o, &ends, res)?;
        }

        #[test]
        fn lanes_cross_the_voxels_of_each_ray_k3(o in prop::array::uniform(-1.0f32..1.0), ends in prop::collection::vec(end::<3>(), 0..40), res in 0.05f64..0.5) {
            same_as_one_by_one(o, &ends, res)?;
        }

        #[test]
        fn lanes_cross_the_voxels_of_each_ray_k4(o in prop::array::uniform(-1.0f32..1.0), ends in prop::collection::vec(end::<4>(), 0..40), res in 0.05f64..0.5) {
            same_as_one_by_one(o, &ends, res)?;
        }
    }
}
