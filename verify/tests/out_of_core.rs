//! Out-of-core stacking writes, for K = 1 … 4 and every split depth, exactly the bytes of the tree built in
//! memory (and equal to naive insertion) written as a `.ktree` version 2 file; with a budget too small it
//! names a larger budget, and the budgets named lead to one with which the build runs and keeps to it; it leaves no
//! temporary file behind and the target untouched on failure, and removes the spill folders of killed
//! builds; and the file does not depend on the number of threads. Built in parts (as the ranks of a
//! distributed run build it: balanced shares of the slabs stacked apart, their indexes added to one part
//! and their levels streamed to it in chunks), the file is the same, for 1 … 5 parts and any chunk size;
//! a damaged index or a stream that breaks off is an error that leaves the target and no temporary file.
//! The builder knows its storage only through its traits: with a store of pieces and an output in memory
//! (written here, outside the library) it builds the tree of the in-memory build, whole or in parts,
//! reads each piece it stored once and whole, and accounts for memory as with files.

use ktree::fs::SpillError;
use std::path::Path;

use ktree::io::write_ktree;
use ktree::rays::RaySource;
use ktree::reference::{Dim, Fanout, NaiveTree};
use ktree::stacking::{
    balanced_parts, paper::stack, BuildError, Builder, LevelOrderSink, LevelPieces, PieceStore,
    StoredPieces,
};
use ktree::tree::PackedStates;
use ktree::{KTree, LevelCounts, NodeState, RaySet};
use ktree_verify::cases::{ray_sets, Case};
use proptest::prelude::*;

/// The bytes the in-memory build writes.
fn in_memory_bytes<const K: usize>(rays: &RaySet<K>) -> Vec<u8> {
    let mut bytes = Vec::new();
    write_ktree(&mut bytes, &stack(rays)).unwrap();
    bytes
}

/// The names in a folder (temporary files and folders included).
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn needed_of<E: std::fmt::Debug, F: std::fmt::Debug>(
    e: BuildError<E, F>,
) -> Result<u64, TestCaseError> {
    match e {
        BuildError::BudgetTooSmall { needed, .. } => Ok(needed),
        other => Err(TestCaseError::fail(format!(
            "expected a budget error, got {other:?}"
        ))),
    }
}

fn out_of_core_agrees<const K: usize, S>(source: &S, expected: &[u8]) -> Result<(), TestCaseError>
where
    S: RaySource<K>,
    S::Error: std::fmt::Display + std::fmt::Debug,
{
    let level = source.universe().level();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tree.ktree");
    for depth in 0..=level {
        let report = Builder::new(source)
            .split_depth(depth)
            .to_file(&out, u64::MAX)
            .map_err(|e| TestCaseError::fail(format!("depth {depth}: {e}")))?;
        let written = std::fs::read(&out).unwrap();
        prop_assert!(
            written == expected,
            "split depth {}: the out-of-core file differs from the in-memory one",
            depth
        );
        prop_assert_eq!(report.file_bytes, written.len() as u64);
        // A budget of nothing: refused at once, naming a budget needed; each budget named is larger than
        // the one refused, and in a few steps the build runs.
        std::fs::write(&out, b"old").unwrap();
        let mut budget = 0u64;
        let (report, needed) = loop {
            match Builder::new(source)
                .split_depth(depth)
                .to_file(&out, budget)
            {
                Ok(report) => break (report, budget),
                Err(e) => {
                    let needed = needed_of(e)?;
                    prop_assert!(needed > budget, "budget {} named after {}", needed, budget);
                    prop_assert_eq!(std::fs::read(&out).unwrap(), b"old".to_vec());
                    prop_assert_eq!(
                        entries(dir.path()),
                        vec!["tree.ktree".to_string()],
                        "a failed build leaves no temporary file"
                    );
                    budget = needed;
                }
            }
        };
        prop_assert!(report.peak_accounted_bytes <= needed);
        prop_assert!(
            std::fs::read(&out).unwrap() == expected,
            "split depth {}: the file written at the smallest budget differs",
            depth
        );
        prop_assert_eq!(entries(dir.path()), vec!["tree.ktree".to_string()]);
    }
    Ok(())
}

/// Builds the file in `parts` parts: part 0 writes, the others' levels reach it as chunks of
/// `chunk` words; checks the bytes, the balance of the parts and that no spill folder remains.
fn parts_agree<const K: usize, S>(
    source: &S,
    expected: &[u8],
    parts: usize,
    chunk: usize,
) -> Result<(), TestCaseError>
where
    S: RaySource<K>,
    S::Error: std::fmt::Display + std::fmt::Debug,
{
    let level = source.universe().level();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tree.ktree");
    for depth in 0..=level {
        let builder = Builder::new(source).split_depth(depth);
        let slabs = builder.slabs();
        let costs: Vec<u64> = slabs
            .iter()
            .map(|&b0| builder.slab_cost(b0).unwrap())
            .collect();
        let ranges = balanced_parts(&costs, parts);
        prop_assert_eq!(ranges.len(), parts);
        prop_assert_eq!(ranges[0].start, 0);
        prop_assert_eq!(ranges[parts - 1].end, slabs.len());
        for w in ranges.windows(2) {
            prop_assert_eq!(w[0].end, w[1].start, "the parts follow one another");
        }
        // No part is more than one slab away from an equal share.
        let total: u64 = costs.iter().map(|&c| c.max(1)).sum();
        let largest = costs.iter().map(|&c| c.max(1)).max().unwrap_or(0);
        for r in &ranges {
            let cost: u64 = costs[r.clone()].iter().map(|&c| c.max(1)).sum();
            prop_assert!(
                cost <= total / parts as u64 + largest + 1,
                "unbalanced: {:?}",
                ranges
            );
        }
        let mut stacked: Vec<_> = ranges
            .iter()
            .map(|r| {
                builder
                    .stack_part(&slabs[r.clone()], &out, u64::MAX)
                    .unwrap()
            })
            .collect();
        let mut writer = stacked.remove(0);
        let mut streams = Vec::new();
        for mut other in stacked {
            let words = writer.add_part(&other.index_words()).unwrap();
            let mut stream = Vec::new();
            let sent = other
                .stream_levels(chunk, &mut |c| {
                    assert!(!c.is_empty() && c.len() <= chunk);
                    stream.extend_from_slice(c);
                    Ok(())
                })
                .unwrap();
            prop_assert_eq!(sent, words);
            prop_assert_eq!(stream.len() as u64, words);
            streams.push(stream.into_iter());
        }
        writer
            .write::<String>(
                &out,
                &mut |owner, words| {
                    for w in words.iter_mut() {
                        *w = streams[owner - 1]
                            .next()
                            .expect("the stream holds the piece");
                    }
                    Ok(())
                },
                &|_| {},
            )
            .unwrap();
        prop_assert!(
            std::fs::read(&out).unwrap() == expected,
            "split depth {}, {} parts: the file differs from the in-memory one",
            depth,
            parts
        );
        for (i, s) in streams.iter_mut().enumerate() {
            prop_assert!(s.next().is_none(), "part {} sent words not written", i + 1);
        }
        prop_assert_eq!(entries(dir.path()), vec!["tree.ktree".to_string()]);
    }
    Ok(())
}

fn rays_agree<const K: usize>(case: &Case<K>) -> Result<(), TestCaseError>
where
    Dim<K>: Fanout,
{
    let rays = &case.rays;
    prop_assert!(
        stack(rays) == NaiveTree::from_rays(rays).unwrap().to_tree(),
        "stacking and naive insertion differ"
    );
    out_of_core_agrees::<K, _>(rays, &in_memory_bytes(rays))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn out_of_core_equals_in_memory_k1(case in ray_sets::<1>()) { rays_agree(&case)?; }
    #[test]
    fn out_of_core_equals_in_memory_k2(case in ray_sets::<2>()) { rays_agree(&case)?; }
    #[test]
    fn out_of_core_equals_in_memory_k3(case in ray_sets::<3>()) { rays_agree(&case)?; }
    #[test]
    fn out_of_core_equals_in_memory_k4(case in ray_sets::<4>()) { rays_agree(&case)?; }

    #[test]
    fn parts_k1(case in ray_sets::<1>(), parts in 1usize..=5, chunk in 1usize..40) {
        parts_agree::<1, _>(&case.rays, &in_memory_bytes(&case.rays), parts, chunk)?;
    }
    #[test]
    fn parts_k2(case in ray_sets::<2>(), parts in 1usize..=5, chunk in 1usize..40) {
        parts_agree::<2, _>(&case.rays, &in_memory_bytes(&case.rays), parts, chunk)?;
    }
    #[test]
    fn parts_k3(case in ray_sets::<3>(), parts in 1usize..=5, chunk in 1usize..40) {
        parts_agree::<3, _>(&case.rays, &in_memory_bytes(&case.rays), parts, chunk)?;
    }
    #[test]
    fn parts_k4(case in ray_sets::<4>(), parts in 1usize..=5, chunk in 1usize..40) {
        parts_agree::<4, _>(&case.rays, &in_memory_bytes(&case.rays), parts, chunk)?;
    }

    #[test]
    fn solids_out_of_core(c in prop::array::uniform3(-8i64..72), r in 1i64..60) {
        use ktree::solid::{Frame, Quadric, Rational, Sample, Solid, SolidSource};
        let ball = Solid::Quadric(Quadric::<3>::ball(
            c.map(|v| Rational::new(v, 2).unwrap()),
            Rational::new(r, 2).unwrap(),
            Frame::Voxel,
        ).unwrap());
        let source = SolidSource::new(&ball, 5, Sample::Centre).unwrap();
        let expected = in_memory_bytes(&ball.to_rays(5, Sample::Centre, false).unwrap());
        out_of_core_agrees::<3, _>(&source, &expected)?;
    }
}

/// A store of pieces in memory: each level's pieces one after the other in a `Vec`, and the length of
/// each piece, to check that the builder reads every piece once, whole and in order.
#[derive(Default)]
struct VecPieces {
    levels: Vec<Vec<u64>>,
    piece_words: Vec<Vec<u64>>,
}

impl PieceStore for VecPieces {
    type Error = std::io::Error;
    type Stored = VecPieces;

    fn append(&mut self, depth: usize, words: &[u64], nodes: u64) -> std::io::Result<()> {
        assert!(depth >= 1, "pieces go to the levels below the cells");
        assert_eq!(
            words.len() as u64,
            nodes.div_ceil(32),
            "a piece in whole words"
        );
        if self.levels.len() < depth {
            self.levels.resize(depth, Vec::new());
            self.piece_words.resize(depth, Vec::new());
        }
        self.levels[depth - 1].extend_from_slice(words);
        self.piece_words[depth - 1].push(words.len() as u64);
        Ok(())
    }

    fn finish(self) -> std::io::Result<VecPieces> {
        Ok(self)
    }
}

/// A level of a [`VecPieces`] being read: its words, the offsets the builder gave, and the words of
/// each piece read so far.
struct VecLevel<'a> {
    words: Vec<u64>,
    offsets: &'a [u64],
    read: Vec<u64>,
}

impl StoredPieces for VecPieces {
    type Error = std::io::Error;
    type Level<'a> = VecLevel<'a>;

    fn level<'a>(&'a mut self, depth: usize, offsets: &'a [u64], words: u64) -> VecLevel<'a> {
        let level = self.levels.get_mut(depth - 1).map(std::mem::take);
        let sizes = self.piece_words.get(depth - 1).cloned().unwrap_or_default();
        // The builder's index places the pieces where they were stored: empty pieces (a subtree not
        // that deep) were not stored at all.
        let stored: Vec<u64> = offsets
            .iter()
            .enumerate()
            .map(|(s, &at)| offsets.get(s + 1).copied().unwrap_or(words) - at)
            .filter(|&n| n > 0)
            .collect();
        let nonempty: Vec<u64> = sizes.iter().copied().filter(|&n| n > 0).collect();
        assert_eq!(
            stored, nonempty,
            "level {depth}: the pieces are not where they were stored"
        );
        VecLevel {
            words: level.unwrap_or_default(),
            offsets,
            read: vec![0; offsets.len()],
        }
    }
}

impl VecLevel<'_> {
    fn piece_len(&self, piece: usize) -> u64 {
        let end = self
            .offsets
            .get(piece + 1)
            .copied()
            .unwrap_or(self.words.len() as u64);
        end - self.offsets[piece]
    }
}

impl LevelPieces for VecLevel<'_> {
    type Error = std::io::Error;

    fn read(&mut self, piece: usize, at: u64, out: &mut [u64]) -> std::io::Result<()> {
        assert_eq!(
            at, self.read[piece],
            "piece {piece} not read in order, or read twice"
        );
        assert!(
            at + out.len() as u64 <= self.piece_len(piece),
            "piece {piece} read past its end"
        );
        let start = (self.offsets[piece] + at) as usize;
        out.copy_from_slice(&self.words[start..start + out.len()]);
        self.read[piece] += out.len() as u64;
        Ok(())
    }

    fn finish(self) {
        for piece in 0..self.offsets.len() {
            assert_eq!(
                self.read[piece],
                self.piece_len(piece),
                "piece {piece} not read whole"
            );
        }
    }
}

/// An output in memory: the levels as node states, made a [`KTree`] when finished.
struct MemoryLevels<const K: usize> {
    level: u32,
    levels: Vec<Vec<NodeState>>,
    current: Vec<NodeState>,
}

impl<const K: usize> MemoryLevels<K> {
    fn new(level: u32) -> Self {
        Self {
            level,
            levels: Vec::new(),
            current: Vec::new(),
        }
    }
}

impl<const K: usize> LevelOrderSink for MemoryLevels<K> {
    type Error = std::io::Error;
    type Output = KTree<K>;

    fn append_words(&mut self, words: &[u64], nodes: u64) -> std::io::Result<()> {
        for i in 0..nodes as usize {
            self.current
                .push(match words[i / 32] >> (2 * (i % 32)) & 3 {
                    0 => NodeState::Empty,
                    1 => NodeState::Full,
                    2 => NodeState::Partial,
                    _ => return Err(std::io::Error::other("the unused code 11")),
                });
        }
        Ok(())
    }

    fn end_level(&mut self) -> std::io::Result<()> {
        self.levels.push(std::mem::take(&mut self.current));
        Ok(())
    }

    fn counts_per_level(&self) -> Vec<LevelCounts> {
        (0..self.levels.len())
            .map(|d| {
                let count = |state| self.levels[d].iter().filter(|&&s| s == state).count() as u64;
                LevelCounts {
                    level: d as u32,
                    empty: count(NodeState::Empty),
                    full: count(NodeState::Full),
                    partial: count(NodeState::Partial),
                }
            })
            .collect()
    }

    fn finish(self) -> std::io::Result<KTree<K>> {
        assert!(self.current.is_empty(), "a level left open");
        let levels = self
            .levels
            .iter()
            .map(|states| {
                let mut words = vec![0u64; states.len().div_ceil(32)];
                for (i, &s) in states.iter().enumerate() {
                    words[i / 32] |= (s as u64) << (2 * (i % 32));
                }
                PackedStates::from_words(words, states.len()).map_err(std::io::Error::other)
            })
            .collect::<std::io::Result<Vec<_>>>()?;
        KTree::from_level_states(self.level, levels).map_err(std::io::Error::other)
    }
}

/// With a store of pieces and an output in memory, at every split depth: the tree of the in-memory
/// build, whole and in `parts` parts streaming their levels in chunks of `chunk` words; the counts and
/// the spilled bytes reported; and the budget needed is the one the build to a file names.
fn in_memory_storage_agrees<const K: usize>(
    rays: &RaySet<K>,
    parts: usize,
    chunk: usize,
) -> Result<(), TestCaseError> {
    let expected = stack(rays);
    let level = rays.level();
    let dir = tempfile::tempdir().unwrap();
    for depth in 0..=level {
        let builder = Builder::new(rays).split_depth(depth);
        let store = VecPieces::default();
        let (tree, report) = builder
            .build_into(store, MemoryLevels::<K>::new(level), u64::MAX)
            .map_err(|e| TestCaseError::fail(format!("depth {depth}: {e}")))?;
        prop_assert!(tree == expected, "split depth {}: the tree differs", depth);
        prop_assert_eq!(&report.counts_per_level, &expected.counts_per_level());
        prop_assert_eq!(report.file_bytes, 0);
        let file = builder
            .to_file(&dir.path().join("tree.ktree"), u64::MAX)
            .unwrap();
        prop_assert_eq!(report.spilled_bytes, file.spilled_bytes);
        prop_assert_eq!(report.subtrees, file.subtrees);
        prop_assert_eq!(report.peak_accounted_bytes, file.peak_accounted_bytes);
        // The memory accounted does not depend on the storage: a budget of nothing names the same need.
        let needed_memory = needed_of(
            builder
                .build_into(VecPieces::default(), MemoryLevels::<K>::new(level), 0)
                .unwrap_err(),
        )?;
        let needed_file = needed_of(
            builder
                .to_file(&dir.path().join("tree.ktree"), 0)
                .unwrap_err(),
        )?;
        prop_assert_eq!(needed_memory, needed_file);

        // In parts, every part's pieces in memory.
        let slabs = builder.slabs();
        let costs: Vec<u64> = slabs
            .iter()
            .map(|&b0| builder.slab_cost(b0).unwrap())
            .collect();
        let mut stacked: Vec<_> = balanced_parts(&costs, parts)
            .into_iter()
            .map(|r| {
                builder
                    .stack_part_into(&slabs[r], VecPieces::default(), u64::MAX)
                    .unwrap()
            })
            .collect();
        let mut writer = stacked.remove(0);
        let mut streams = Vec::new();
        for mut other in stacked {
            let words = writer.add_part(&other.index_words()).unwrap();
            let mut stream = Vec::new();
            other
                .stream_levels(chunk, &mut |c| {
                    stream.extend_from_slice(c);
                    Ok(())
                })
                .unwrap();
            prop_assert_eq!(stream.len() as u64, words);
            streams.push(stream.into_iter());
        }
        let (tree, _) = writer
            .write_into::<String, _, _>(
                MemoryLevels::<K>::new(level),
                |owner: usize, words: &mut [u64]| {
                    for w in words.iter_mut() {
                        *w = streams[owner - 1]
                            .next()
                            .ok_or_else(|| std::io::Error::other("a stream ended early"))?;
                    }
                    Ok(())
                },
                &|_| {},
            )
            .map_err(|e| TestCaseError::fail(format!("depth {depth}, {parts} parts: {e}")))?;
        prop_assert!(
            tree == expected,
            "split depth {}, {} parts: the tree differs",
            depth,
            parts
        );
        for (i, s) in streams.iter_mut().enumerate() {
            prop_assert!(s.next().is_none(), "part {} sent words not written", i + 1);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn in_memory_storage_k1(case in ray_sets::<1>(), parts in 1usize..=4, chunk in 1usize..40) {
        in_memory_storage_agrees(&case.rays, parts, chunk)?;
    }
    #[test]
    fn in_memory_storage_k2(case in ray_sets::<2>(), parts in 1usize..=4, chunk in 1usize..40) {
        in_memory_storage_agrees(&case.rays, parts, chunk)?;
    }
    #[test]
    fn in_memory_storage_k3(case in ray_sets::<3>(), parts in 1usize..=4, chunk in 1usize..40) {
        in_memory_storage_agrees(&case.rays, parts, chunk)?;
    }
    #[test]
    fn in_memory_storage_k4(case in ray_sets::<4>(), parts in 1usize..=4, chunk in 1usize..40) {
        in_memory_storage_agrees(&case.rays, parts, chunk)?;
    }
}

/// The file is the same for any number of threads and any budget that lets several slabs run at once.
#[test]
fn any_thread_count_and_budget_give_the_same_file() {
    let level = 7;
    let u = 1i64 << level;
    let rays = ktree::rays::ball_rays::<3>(level, [u, u, u], u - 3).unwrap();
    let expected = in_memory_bytes(&rays);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ball.ktree");
    for threads in [1, 2, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        for depth in [1, 3, 5] {
            for budget in [u64::MAX, 4 << 20] {
                let report = pool
                    .install(|| Builder::new(&rays).split_depth(depth).to_file(&out, budget))
                    .unwrap();
                assert_eq!(
                    std::fs::read(&out).unwrap(),
                    expected,
                    "{threads} threads, depth {depth}"
                );
                assert!(report.peak_accounted_bytes <= budget);
            }
        }
    }
}

/// Progress reaches every slab and every level, in order.
#[test]
fn progress_counts_slabs_then_levels() {
    let rays = ktree::rays::ball_rays::<3>(6, [64, 64, 64], 50).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let seen = std::sync::Mutex::new(Vec::new());
    let progress = |p| seen.lock().unwrap().push(p);
    let report = Builder::new(&rays)
        .split_depth(3)
        .progress(&progress)
        .to_file(&dir.path().join("b.ktree"), u64::MAX)
        .unwrap();
    let seen = seen.into_inner().unwrap();
    use ktree::stacking::Stage;
    let stacking: Vec<_> = seen.iter().filter(|p| p.stage == Stage::Stacking).collect();
    let writing: Vec<_> = seen.iter().filter(|p| p.stage == Stage::Writing).collect();
    assert_eq!(stacking.first().unwrap().done, 0);
    assert_eq!(stacking.last().unwrap().done, stacking[0].total);
    assert!(stacking.windows(2).all(|w| w[0].done < w[1].done));
    assert_eq!(
        writing.last().unwrap().done,
        report.counts_per_level.len() as u64
    );
    assert_eq!(writing.last().unwrap().total, writing.last().unwrap().done);
}

/// A temporary folder that cannot hold files is a clear error naming it; the target is untouched and
/// nothing is left behind.
#[test]
fn an_unusable_temporary_folder_is_a_clear_error() {
    let rays = ktree::rays::ball_rays::<2>(6, [64, 64], 50).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b.ktree");
    std::fs::write(&out, b"old").unwrap();
    // A plain file where the folder should be: no one, not even root, can create files in it.
    let not_a_folder = dir.path().join("not-a-folder");
    std::fs::write(&not_a_folder, b"").unwrap();
    let e = Builder::new(&rays)
        .split_depth(3)
        .temp_dir(&not_a_folder)
        .to_file(&out, u64::MAX)
        .unwrap_err();
    assert!(
        matches!(e, BuildError::Files(SpillError::TempDir { .. })),
        "unexpected error {e:?}"
    );
    let message = e.to_string();
    assert!(message.contains("not-a-folder"), "{message}");
    assert_eq!(std::fs::read(&out).unwrap(), b"old");
    assert_eq!(entries(dir.path()), vec!["b.ktree", "not-a-folder"]);
}

/// Small objects in universes of the largest level for each K, split anywhere: the file is the in-memory
/// one.
#[test]
fn extreme_levels_split_anywhere() {
    fn check<const K: usize>() {
        let level = ktree::max_level(K);
        let side = 1u64 << level;
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let rays: Vec<ktree::Ray<K>> = (0..6)
            .map(|_| {
                let start: [u32; K] = std::array::from_fn(|_| (next() % side) as u32);
                let z2 = (u64::from(start[K - 1]) + 1 + next() % 40).min(side);
                ktree::Ray::new(start, z2 as u32)
            })
            .collect();
        let set = RaySet::from_rays(level, rays).unwrap();
        let expected = in_memory_bytes(&set);
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("t.ktree");
        for depth in [0, 1, level / 2, level - 1, level] {
            Builder::new(&set)
                .split_depth(depth)
                .to_file(&out, u64::MAX)
                .unwrap();
            assert_eq!(
                std::fs::read(&out).unwrap(),
                expected,
                "K={K} depth {depth}"
            );
        }
    }
    check::<1>();
    check::<2>();
    check::<3>();
    check::<4>();
}

/// The spill folder of a build that was killed (its process no longer runs) is removed by the next build
/// of the same output; a live process's folder and other outputs' folders are kept.
#[test]
fn the_next_build_removes_the_spill_folders_of_killed_builds() {
    let rays = ktree::rays::ball_rays::<3>(6, [64, 64, 64], 50).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let dead = dir.path().join(".b.ktree.abc123.4294967295.ktree-spill");
    let live = dir.path().join(format!(
        ".b.ktree.abc123.{}.ktree-spill",
        std::process::id()
    ));
    let other = dir.path().join(".c.ktree.abc123.4294967295.ktree-spill");
    for folder in [&dead, &live, &other] {
        std::fs::create_dir(folder).unwrap();
        std::fs::write(folder.join("level-1"), b"spilled").unwrap();
    }
    Builder::new(&rays)
        .split_depth(3)
        .to_file(&dir.path().join("b.ktree"), u64::MAX)
        .unwrap();
    assert!(!dead.exists(), "a killed build's spill folder stays");
    assert!(live.exists() && other.exists());
    assert_eq!(
        entries(dir.path()),
        [
            ".b.ktree.abc123.".to_string() + &std::process::id().to_string() + ".ktree-spill",
            ".c.ktree.abc123.4294967295.ktree-spill".to_string(),
            "b.ktree".to_string(),
        ]
    );
}

/// The writing part refuses an index that is not that of a part of its build, without panicking.
#[test]
fn a_foreign_or_damaged_part_index_is_refused() {
    let ball = ktree::rays::ball_rays::<3>(5, [16, 16, 16], 20).unwrap();
    let other = ktree::rays::ball_rays::<3>(6, [16, 16, 16], 20).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tree.ktree");
    let builder = Builder::new(&ball).split_depth(2);
    let slabs = builder.slabs();
    let (first, second) = slabs.split_at(slabs.len() / 2);
    let mut writer = builder.stack_part(first, &out, u64::MAX).unwrap();
    let part = builder.stack_part(second, &out, u64::MAX).unwrap();
    let other = Builder::new(&other).split_depth(2);
    let foreign = other.stack_part(&other.slabs(), &out, u64::MAX).unwrap();
    let words = part.index_words();
    let mut damaged = vec![
        foreign.index_words(),
        words[..words.len() - 1].to_vec(),
        Vec::new(),
        vec![0; 20],
    ];
    let mut bad_count = words.clone();
    let last = bad_count.len() - 1;
    bad_count[last] = u64::MAX;
    damaged.push(bad_count);
    for index in damaged {
        let e = writer.add_part(&index).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidData, "{e}");
    }
    assert_eq!(writer.add_part(&words).unwrap(), {
        let mut part = part;
        part.stream_levels(64, &mut |_| Ok(())).unwrap()
    });
}

/// A part whose stream breaks off while the file is written: the write fails naming the cause, the
/// target keeps its old bytes, and no temporary file or spill folder remains.
#[test]
fn a_stream_that_breaks_off_fails_the_write_and_keeps_the_target() {
    let ball = ktree::rays::ball_rays::<3>(6, [32, 32, 32], 40).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tree.ktree");
    std::fs::write(&out, b"old").unwrap();
    let builder = Builder::new(&ball).split_depth(3);
    let slabs = builder.slabs();
    let (first, second) = slabs.split_at(slabs.len() / 2);
    let mut writer = builder.stack_part(first, &out, u64::MAX).unwrap();
    let mut part = builder.stack_part(second, &out, u64::MAX).unwrap();
    let words = writer.add_part(&part.index_words()).unwrap();
    let mut stream = Vec::new();
    part.stream_levels(16, &mut |c| {
        stream.extend_from_slice(c);
        Ok(())
    })
    .unwrap();
    drop(part);
    assert_eq!(stream.len() as u64, words);
    assert!(words > 2);
    // The stream breaks off half-way.
    stream.truncate(stream.len() / 2);
    let mut stream = stream.into_iter();
    let e = writer
        .write::<String>(
            &out,
            &mut |_, piece| {
                for w in piece.iter_mut() {
                    *w = stream
                        .next()
                        .ok_or_else(|| std::io::Error::other("the sender stopped"))?;
                }
                Ok(())
            },
            &|_| {},
        )
        .unwrap_err();
    assert!(
        matches!(e, BuildError::Files(SpillError::Output { .. })),
        "{e:?}"
    );
    // The sender's error is the cause, kept in the error's chain.
    let BuildError::Files(files) = &e else {
        unreachable!("checked above")
    };
    let mut chain = files.to_string();
    let mut cause = std::error::Error::source(files);
    while let Some(c) = cause {
        chain = format!("{chain}: {c}");
        cause = c.source();
    }
    assert!(chain.contains("the sender stopped"), "{chain}");
    assert_eq!(std::fs::read(&out).unwrap(), b"old".to_vec());
    assert_eq!(entries(dir.path()), vec!["tree.ktree".to_string()]);
}

/// The non-empty cells of depth `m` of a tree: what a build that lists every such cell holds.
fn nonempty_cells_of_depth<const K: usize>(tree: &ktree::KTree<K>, m: u32) -> u64 {
    let counts = tree.counts_per_level();
    let mut cells = 0u64;
    for c in counts.iter().filter(|c| c.level <= m) {
        cells += c.full << (K as u32 * (m - c.level));
        if c.level == m {
            cells += c.partial;
        }
    }
    cells
}

/// The full interior costs the build a few blocks, not an entry per cell: a ball whose cells of depth
/// `m` are too many to list in the budget (at 24 bytes each, as a list of the non-empty cells would
/// take) builds in it, the file that of the in-memory build.
#[test]
fn a_solid_interior_does_not_fill_the_budget() {
    fn check<const K: usize>(level: u32, depth: u32, radius: i64, budget: u64) {
        let u = 1i64 << level;
        let rays = ktree::rays::ball_rays::<K>(level, [u; K], 2 * radius).unwrap();
        let tree = stack(&rays);
        let listed = 24 * nonempty_cells_of_depth(&tree, depth);
        assert!(
            listed > 4 * budget,
            "K = {K}: the cells listed take {listed} bytes, not beyond the budget {budget}"
        );
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("ball.ktree");
        let report = Builder::new(&rays)
            .split_depth(depth)
            .to_file(&out, budget)
            .unwrap_or_else(|e| panic!("K = {K}, L = {level}: {e}"));
        assert!(report.peak_accounted_bytes <= budget);
        let mut expected = Vec::new();
        write_ktree(&mut expected, &tree).unwrap();
        assert!(
            std::fs::read(&out).unwrap() == expected,
            "K = {K}: the file differs"
        );
    }
    // 1.3·10^7 cells of side 2 in the disk; 1.1·10^6 cells of side 4 in the ball.
    check::<2>(16, 15, 4096, 4 << 20);
    check::<3>(12, 10, 256, 6 << 20);
}
