//! Every operation over the one storage and through the one sink, K = 1 … 4: on a `.ktree` file read in
//! place (a [`MappedTree`] over the written bytes) each operation gives what it gives on the tree in
//! memory (itself held against brute force by the other `ops_*` tests); written through a reference sink
//! (every node appended one at a time, each level checked to arrive in order, the tree rebuilt through
//! the checked public constructor) each tree-making operation gives the tree of its in-memory form; and a
//! storage whose reads start failing, or a sink whose writes do, makes every operation return the error —
//! never a panic, never a wrong tree.

use std::cell::Cell;
use std::convert::Infallible;
use std::fmt;

use ktree::io::{write_ktree, KtreeFileError, KtreeView, MappedTree};
use ktree::ops::{self, Affine, AxisMap, BoolOp, OpsError, Projective};
use ktree::tree::sink::{LevelSink, MemorySink};
use ktree::tree::storage::TreeStorage;
use ktree::tree::{LevelCounts, PackedStates, StorageError};
use ktree::{KTree, NodeState, Universe};
use ktree_verify::objects::{pair, Obj};
use proptest::prelude::*;

// ---------------------------------------------------------------------------------------------------
// The storages and sinks under test.

/// The bytes of `tree` as a version 2 `.ktree` file, read in place.
fn view_of<const K: usize>(tree: &KTree<K>) -> KtreeView {
    let mut bytes = Vec::new();
    write_ktree(&mut bytes, tree).unwrap();
    KtreeView::from_bytes(bytes, "mem").unwrap()
}

/// A write refused by [`NaiveSink`] once its budget of appends is spent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Full;

/// The simplest sink: each append split into single states, kept per level; at the end the levels are
/// packed one state at a time and the tree built by the checked constructor. It fails every append past
/// its budget.
struct NaiveSink<const K: usize> {
    level: u32,
    levels: Vec<Vec<NodeState>>,
    budget: usize,
}

impl<const K: usize> NaiveSink<K> {
    fn new(level: u32, budget: usize) -> Self {
        Self {
            level,
            levels: Vec::new(),
            budget,
        }
    }
}

impl<const K: usize> LevelSink for NaiveSink<K> {
    type Error = Full;
    type Output = KTree<K>;

    fn append(&mut self, depth: usize, word: u64, n: usize) -> Result<(), Full> {
        if self.budget == 0 {
            return Err(Full);
        }
        self.budget -= 1;
        assert!(
            depth >= 1 && (1..=32).contains(&n),
            "append of {n} to level {depth}"
        );
        assert!(n == 32 || word >> (2 * n) == 0, "bits above the {n} states");
        if self.levels.len() <= depth {
            self.levels.resize(depth + 1, Vec::new());
        }
        for i in 0..n {
            let state = match word >> (2 * i) & 3 {
                0 => NodeState::Empty,
                1 => NodeState::Full,
                2 => NodeState::Partial,
                _ => panic!("the unused code 11 appended to level {depth}"),
            };
            self.levels[depth].push(state);
        }
        Ok(())
    }

    fn finish(mut self, root: NodeState) -> Result<KTree<K>, Full> {
        if root != NodeState::Partial {
            self.levels.clear();
        }
        self.levels.resize(self.levels.len().max(1), Vec::new());
        self.levels[0] = vec![root];
        let packed = self
            .levels
            .iter()
            .map(|states| {
                let mut words = vec![0u64; states.len().div_ceil(32)];
                for (i, &s) in states.iter().enumerate() {
                    words[i / 32] |= (s as u64) << (2 * (i % 32));
                }
                PackedStates::from_words(words, states.len()).unwrap()
            })
            .collect();
        // The constructor checks every level's length against the partial nodes above it, so a block
        // appended to the wrong level or out of order fails here.
        Ok(KTree::from_level_states(self.level, packed).unwrap())
    }
}

/// A [`MemorySink`] whose (impossible) write errors have the type `E`: a sink for the read errors of a
/// storage `T` alone (`E = T::Error`).
struct MemoryAs<const K: usize, E>(MemorySink<K>, std::marker::PhantomData<E>);

impl<const K: usize, E> MemoryAs<K, E> {
    fn new(universe: Universe<K>) -> Self {
        Self(MemorySink::new(universe), std::marker::PhantomData)
    }
}

impl<const K: usize, E> LevelSink for MemoryAs<K, E> {
    type Error = E;
    type Output = KTree<K>;
    fn append(&mut self, depth: usize, word: u64, n: usize) -> Result<(), E> {
        let Ok(()) = self.0.append(depth, word, n);
        Ok(())
    }
    fn finish(self, root: NodeState) -> Result<KTree<K>, E> {
        let Ok(tree) = self.0.finish(root);
        Ok(tree)
    }
}

/// A read refused by [`Flaky`] once its budget of reads is spent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Broken;

impl fmt::Display for Broken {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("the storage broke")
    }
}

impl std::error::Error for Broken {}

impl From<Broken> for StorageError {
    fn from(e: Broken) -> Self {
        StorageError::new(e)
    }
}

/// A tree in memory whose fallible reads fail once `budget` of them have been made.
struct Flaky<'a, const K: usize> {
    tree: &'a KTree<K>,
    budget: Cell<usize>,
}

impl<'a, const K: usize> Flaky<'a, K> {
    fn new(tree: &'a KTree<K>, budget: usize) -> Self {
        Self {
            tree,
            budget: Cell::new(budget),
        }
    }

    fn spend(&self) -> Result<(), Broken> {
        let left = self.budget.get();
        if left == 0 {
            return Err(Broken);
        }
        self.budget.set(left - 1);
        Ok(())
    }
}

impl<const K: usize> TreeStorage<K> for Flaky<'_, K> {
    type Error = Broken;
    fn universe(&self) -> Universe<K> {
        self.tree.universe()
    }
    fn depth_count(&self) -> usize {
        self.tree.depth_count()
    }
    fn level_len(&self, depth: usize) -> usize {
        TreeStorage::level_len(self.tree, depth)
    }
    fn counts_per_level(&self) -> Vec<LevelCounts> {
        self.tree.counts_per_level()
    }
    fn root_state(&self) -> Result<NodeState, Broken> {
        self.spend()?;
        Ok(self.tree.root_state())
    }
    fn partial_rank(&self, depth: usize, index: usize) -> Result<usize, Broken> {
        self.spend()?;
        Ok(self.tree.level_states(depth).partial_rank(index))
    }
    fn block_codes(&self, depth: usize, first: usize) -> Result<u32, Broken> {
        self.spend()?;
        Ok(ktree::tree::storage::infallible(TreeStorage::block_codes(
            self.tree, depth, first,
        )))
    }
}

/// Why an operation written to a sink failed, in the tests: a read, a write or the operation's own error.
#[derive(Debug)]
enum Failure {
    Read(String),
    Write,
    Ops(String),
}

impl From<Infallible> for Failure {
    fn from(never: Infallible) -> Self {
        match never {}
    }
}

impl From<Full> for Failure {
    fn from(_: Full) -> Self {
        Failure::Write
    }
}

impl From<Broken> for Failure {
    fn from(e: Broken) -> Self {
        Failure::Read(e.to_string())
    }
}

impl From<KtreeFileError> for Failure {
    fn from(e: KtreeFileError) -> Self {
        Failure::Read(e.to_string())
    }
}

impl From<OpsError> for Failure {
    fn from(e: OpsError) -> Self {
        Failure::Ops(e.to_string())
    }
}

// ---------------------------------------------------------------------------------------------------
// The operations, as one list over any storage and any sink.

/// The parameters of one case: the operations' arguments drawn at random.
#[derive(Debug, Clone)]
struct Params<const K: usize> {
    shift: [i64; K],
    fine: ([i64; K], u32),
    axis_map: usize,
    affine: Vec<f64>,
    projective: Vec<f64>,
    scale: (u32, u32),
    path: Vec<usize>,
}

fn params<const K: usize>() -> impl Strategy<Value = Params<K>> {
    (
        prop::array::uniform::<_, K>(-40i64..40),
        (prop::array::uniform::<_, K>(-200i64..200), 0u32..4),
        0usize..1000,
        prop::collection::vec(-0.9f64..0.9, K * (K + 1)),
        prop::collection::vec(-1f64..1.0, (K + 1) * (K + 1)),
        (1u32..6, 1u32..6),
        prop::collection::vec(0usize..16, 0..3),
    )
        .prop_map(
            |(shift, fine, axis_map, affine, projective, scale, path)| Params {
                shift,
                fine,
                axis_map,
                affine,
                projective,
                scale,
                path: path.into_iter().map(|c| c % (1 << K)).collect(),
            },
        )
}

impl<const K: usize> Params<K> {
    fn axis_map(&self) -> AxisMap<K> {
        let all = AxisMap::<K>::all();
        all[self.axis_map % all.len()]
    }

    /// An affine map near the identity, translated by up to 0.9 of the universe.
    fn affine(&self, level: u32) -> Affine<K> {
        let side = (1u64 << level) as f64;
        let e = &self.affine;
        let mut m = Affine::<K>::identity();
        for i in 0..K {
            for j in 0..K {
                m.a[i][j] = e[i * K + j] + if i == j { 1.0 } else { 0.0 };
            }
            m.b[i] = e[K * K + i] * side;
        }
        m
    }

    /// A mildly projective map.
    fn projective(&self, level: u32) -> Projective<K> {
        let u = (1u64 << level) as f64;
        let (n, e) = (K + 1, &self.projective);
        let mut m = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let id = if i == j { 1.0 } else { 0.0 };
                m[i * n + j] = id
                    + if i == K && j < K {
                        e[i * n + j] * 0.2 / u
                    } else if j == K && i < K {
                        e[i * n + j] * u / 4.0
                    } else if i < K && j < K {
                        e[i * n + j] * 0.5
                    } else {
                        0.0
                    };
            }
        }
        Projective::from_homogeneous(&m).unwrap()
    }

    /// A zoom path no longer than the level.
    fn zoom_path(&self, level: u32) -> &[usize] {
        &self.path[..self.path.len().min(level as usize)]
    }
}

/// The names of the tree-making operations [`make`] runs.
const MAKERS: &[&str] = &[
    "translate",
    "translate_fine",
    "rotate_axes",
    "transform",
    "transform_fixed",
    "transform_projective",
    "scale",
    "grow",
    "zoom",
    "union",
    "intersection",
    "difference",
    "symmetric_difference",
    "complement",
];

/// The universe level of the result of the operation `name` on a tree of level `level`.
fn out_level<const K: usize>(name: &str, level: u32, p: &Params<K>) -> u32 {
    match name {
        "grow" => level + p.path.len() as u32,
        "zoom" => level - p.zoom_path(level).len() as u32,
        _ => level,
    }
}

/// The tree-making operation `name` on `a` (and `b`), written to `sink` through its `*_into` form.
fn make<const K: usize, T, S>(
    name: &str,
    a: &T,
    b: &T,
    p: &Params<K>,
    sink: S,
) -> Result<KTree<K>, Failure>
where
    T: TreeStorage<K>,
    S: LevelSink<Output = KTree<K>>,
    Failure: From<T::Error> + From<S::Error>,
{
    let level = a.level();
    match name {
        "translate" => ops::translate_into(a, p.shift, sink),
        "translate_fine" => ops::translate_fine_into(a, p.fine.0, p.fine.1, sink),
        "rotate_axes" => ops::rotate_axes_into(a, &p.axis_map(), sink),
        "transform" => ops::transform_into(a, &p.affine(level), sink),
        "transform_fixed" => ops::transform_fixed_into(a, &p.affine(level), 32, sink),
        "transform_projective" => ops::transform_projective_into(a, &p.projective(level), sink),
        "scale" => ops::scale_into(a, p.scale.0, p.scale.1, sink),
        "grow" => ops::grow_into(a, &p.path, sink),
        "zoom" => ops::zoom_into(a, p.zoom_path(level), sink),
        "union" => ops::boolean_into(a, b, BoolOp::Union, sink),
        "intersection" => ops::boolean_into(a, b, BoolOp::Intersection, sink),
        "difference" => ops::boolean_into(a, b, BoolOp::Difference, sink),
        "symmetric_difference" => ops::boolean_into(a, b, BoolOp::SymmetricDifference, sink),
        "complement" => ops::complement_into(a, sink),
        other => panic!("unknown operation {other}"),
    }
}

/// The plain (tree-returning) form of the tree-making operation `name`, its error as text.
fn plain<const K: usize, T>(name: &str, a: &T, b: &T, p: &Params<K>) -> Result<KTree<K>, String>
where
    T: TreeStorage<K>,
{
    let level = a.level();
    let text = |e: T::Error| e.to_string();
    let ops_text = |e: OpsError| e.to_string();
    match name {
        "translate" => ops::translate(a, p.shift).map_err(text),
        "translate_fine" => ops::translate_fine(a, p.fine.0, p.fine.1).map_err(text),
        "rotate_axes" => ops::rotate_axes(a, &p.axis_map()).map_err(text),
        "transform" => ops::transform(a, &p.affine(level)).map_err(ops_text),
        "transform_fixed" => ops::transform_fixed(a, &p.affine(level), 32).map_err(ops_text),
        "transform_projective" => {
            ops::transform_projective(a, &p.projective(level)).map_err(ops_text)
        }
        "scale" => ops::scale(a, p.scale.0, p.scale.1).map_err(ops_text),
        "grow" => ops::grow(a, &p.path).map_err(ops_text),
        "zoom" => ops::zoom(a, p.zoom_path(level)).map_err(ops_text),
        "union" => ops::union(a, b).map_err(ops_text),
        "intersection" => ops::intersection(a, b).map_err(ops_text),
        "difference" => ops::difference(a, b).map_err(ops_text),
        "symmetric_difference" => ops::symmetric_difference(a, b).map_err(ops_text),
        "complement" => {
            let sink = MemoryAs::<K, T::Error>::new(a.universe());
            ops::complement_into::<K, _, _, T::Error>(a, sink).map_err(text)
        }
        other => panic!("unknown operation {other}"),
    }
}

/// Everything the operations that do not make a tree answer, as text (so that `NaN`s compare equal),
/// an error as its message.
fn answers<const K: usize, T: TreeStorage<K>>(a: &T, b: &T) -> Vec<String> {
    let maps = [
        Affine::<K>::identity(),
        Affine::rotation_about(0, K - 1, 30.0, Affine::<K>::universe_centre(a.level()))
            .unwrap_or_else(|_| Affine::scaling_about(0.75, [0.0; K])),
    ];
    vec![
        format!("{:?}", ops::interferes(a, b).map_err(|e| e.to_string())),
        format!("{:?}", ops::overlap_cells(a, b).map_err(|e| e.to_string())),
        format!(
            "{:?}",
            ops::first_contact(a, b, K - 1).map_err(|e| e.to_string())
        ),
        format!(
            "{:?}",
            ops::collision(a, b, Some(0)).map_err(|e| e.to_string())
        ),
        format!("{:?}", ops::min_separation(a, b).map_err(|e| e.to_string())),
        format!("{:?}", ops::mass_properties(a).map_err(|e| e.to_string())),
        format!(
            "{:?}",
            ops::mass_progressive(a, 0.1).map_err(|e| e.to_string())
        ),
        format!(
            "{:?}",
            ops::mass_progressive(a, 0.0).map_err(|e| e.to_string())
        ),
        format!("{:?}", ops::complexity(a)),
        format!(
            "{:?}",
            ops::normalise_to_origin(a)
                .map(|t| t.leaves().collect::<Vec<_>>())
                .map_err(|e| e.to_string())
        ),
        format!(
            "{:?}",
            ops::over_translations(a, 1).map_err(|e| e.to_string())
        ),
        format!("{:?}", ops::over_maps(a, &maps).map_err(|e| e.to_string())),
    ]
}

// ---------------------------------------------------------------------------------------------------
// The properties.

fn check<const K: usize>((oa, ob): &(Obj<K>, Obj<K>), p: &Params<K>) -> Result<(), TestCaseError> {
    let (ta, tb) = (oa.tree(), ob.tree());
    let (va, vb) = (view_of(&ta), view_of(&tb));
    let (ma, mb) = (
        MappedTree::<K>::new(&va).unwrap(),
        MappedTree::<K>::new(&vb).unwrap(),
    );
    let level = ta.level();
    for &name in MAKERS {
        let memory = plain(name, &ta, &tb, p);
        // On the mapped file, as in memory.
        prop_assert_eq!(
            &plain(name, &ma, &mb, p),
            &memory,
            "{} on the mapped file",
            name
        );
        let Ok(expect) = memory else {
            continue; // the operation's own error (a singular matrix), seen alike on both
        };
        expect.assert_well_formed();
        // Through the reference sink, from memory and from the mapped file.
        let out = out_level(name, level, p);
        let sink = || NaiveSink::<K>::new(out, usize::MAX);
        let through = make(name, &ta, &tb, p, sink()).map_err(|e| format!("{e:?}"));
        prop_assert_eq!(through, Ok(expect.clone()), "{} through the sink", name);
        let through = make(name, &ma, &mb, p, sink()).map_err(|e| format!("{e:?}"));
        prop_assert_eq!(
            through,
            Ok(expect.clone()),
            "{} from the mapped file through the sink",
            name
        );
        // Through the public in-memory sink.
        let memory_sink = MemorySink::new(Universe::new(out).unwrap());
        let through = make(name, &ma, &mb, p, memory_sink).map_err(|e| format!("{e:?}"));
        prop_assert_eq!(through, Ok(expect.clone()), "{} through MemorySink", name);
        // A sink that refuses its first append: the error, unless the result has no level to append.
        let refused = make(name, &ta, &tb, p, NaiveSink::<K>::new(out, 0));
        match refused {
            Err(Failure::Write) => prop_assert!(expect.depth_count() > 1, "{}", name),
            Ok(t) => {
                prop_assert_eq!(t.depth_count(), 1, "{} appended nothing", name);
                prop_assert_eq!(&t, &expect, "{}", name);
            }
            Err(e) => prop_assert!(false, "{}: {:?}", name, e),
        }
    }
    prop_assert_eq!(answers(&ma, &mb), answers(&ta, &tb));
    Ok(())
}

/// With a storage that fails after `budget` reads, every operation returns the read error or, if it
/// needed no more reads, the right answer.
fn check_failing_reads<const K: usize>(
    (oa, ob): &(Obj<K>, Obj<K>),
    p: &Params<K>,
    budget: usize,
) -> Result<(), TestCaseError> {
    let (ta, tb) = (oa.tree(), ob.tree());
    let broken = Broken.to_string();
    for &name in MAKERS {
        let Ok(expect) = plain(name, &ta, &tb, p) else {
            continue;
        };
        let (fa, fb) = (Flaky::new(&ta, budget), Flaky::new(&tb, budget));
        match plain(name, &fa, &fb, p) {
            Ok(t) => prop_assert_eq!(&t, &expect, "{} with {} reads", name, budget),
            Err(e) => prop_assert!(e.contains(&broken), "{}: {}", name, e),
        }
        // The same through a sink.
        let (fa, fb) = (Flaky::new(&ta, budget), Flaky::new(&tb, budget));
        let sink = NaiveSink::<K>::new(out_level(name, ta.level(), p), usize::MAX);
        match make(name, &fa, &fb, p, sink) {
            Ok(t) => prop_assert_eq!(&t, &expect, "{} with {} reads", name, budget),
            Err(Failure::Read(e)) => prop_assert_eq!(e, broken.clone(), "{}", name),
            Err(Failure::Ops(e)) => prop_assert!(false, "{}: {}", name, e),
            Err(Failure::Write) => prop_assert!(false, "{}: the sink refused a write", name),
        }
    }
    let (fa, fb) = (Flaky::new(&ta, budget), Flaky::new(&tb, budget));
    let (good, got) = (answers(&ta, &tb), answers(&fa, &fb));
    for (g, e) in got.iter().zip(&good) {
        prop_assert!(g == e || g.contains(&broken), "{} against {}", g, e);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ktree_verify::config(24))]
    #[test] fn mapped_and_sinks_k1(ab in pair::<1>(), p in params::<1>()) { check(&ab, &p)?; }
    #[test] fn mapped_and_sinks_k2(ab in pair::<2>(), p in params::<2>()) { check(&ab, &p)?; }
    #[test] fn mapped_and_sinks_k3(ab in pair::<3>(), p in params::<3>()) { check(&ab, &p)?; }
    #[test] fn mapped_and_sinks_k4(ab in pair::<4>(), p in params::<4>()) { check(&ab, &p)?; }

    #[test] fn failing_reads_k1(ab in pair::<1>(), p in params::<1>(), n in 0usize..40) { check_failing_reads(&ab, &p, n)?; }
    #[test] fn failing_reads_k2(ab in pair::<2>(), p in params::<2>(), n in 0usize..40) { check_failing_reads(&ab, &p, n)?; }
    #[test] fn failing_reads_k3(ab in pair::<3>(), p in params::<3>(), n in 0usize..40) { check_failing_reads(&ab, &p, n)?; }
    #[test] fn failing_reads_k4(ab in pair::<4>(), p in params::<4>(), n in 0usize..40) { check_failing_reads(&ab, &p, n)?; }
}

#[test]
fn a_storage_error_keeps_its_cause() {
    let tree = KTree::<2>::from_dense(2, &(0..16).map(|i| i % 3 == 0).collect::<Vec<_>>()).unwrap();
    let broken = Flaky::new(&tree, 1);
    let e = ops::transform(&broken, &Affine::translation([1.0, 0.0])).unwrap_err();
    assert!(matches!(e, OpsError::Storage(_)), "{e:?}");
    let OpsError::Storage(cause) = &e else {
        unreachable!()
    };
    assert_eq!(cause.downcast_ref::<Broken>(), Some(&Broken));
    assert_eq!(e.to_string(), Broken.to_string());
}
