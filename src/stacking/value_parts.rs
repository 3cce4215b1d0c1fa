//! A valued build cut into parts along the last axis, as the ranks of an MPI run build it: each part reads
//! its own range of slabs of a [`ValueSlabs`] box, builds their cells and spills the levels below every
//! cell with children to a [`PieceStore`] of its own ([`ValueSlabs::stack_part`]); the part that writes
//! the tree takes the others' indexes ([`ValuePart::index_words`], [`ValuePart::add_part`]: the roots of
//! their slabs' cells, and the Morton index and counts of each spilled cell), joins every slab's cells into
//! the top levels and writes the tree level by level ([`ValuePart::write_into`]), each spilled piece taken
//! in the global Morton order of the cells from its owner — its own store, or the stream that each other
//! part sends in its own Morton order ([`ValuePart::stream_levels`]). The output is byte for byte that of
//! the build in one part ([`ValueSlabs::build_into`] is the build of one part).

use std::ops::Range;

use rayon::prelude::*;

use super::out_of_core::{BuildError, ChunkedSend, LevelPieces, PieceStore, StoredPieces};
use super::value_slabs::{join_slabs, spread_across, ValueSlabs};
use super::value_spill::{ValueSlabsReport, ValuedLevelSink};
use crate::rays::RayError;
use crate::tree::top_down::{PackedLevel, Subtree};
use crate::tree::valued::ValueState;
use crate::value::Value;

/// Words read back at once: a multiple of 3, so that as many bytes of values are whole values of 1, 2, 3
/// or 4 bytes.
const CHUNK_WORDS: usize = 3 << 13;

/// The first word of a valued part's index.
const INDEX_MAGIC: u64 = u64::from_le_bytes(*b"ktvpart1");
/// The words of an index header: magic, K, L, m, dtype code, first slab, end of the slabs, layers sent,
/// spilled cells, spilled bytes.
const INDEX_HEADER: usize = 10;
/// The most parts a tree is written from (the owner of a piece is kept in 16 bits).
const MAX_PARTS: usize = 1 << 16;

/// The spilled cells of one part, in the order they were spilled: each one's Morton index among the cells
/// of depth `m`, and per level `1 … t` below it its node count and full node count (0 beyond its depth).
#[derive(Debug, Default)]
struct SpillIndex {
    mortons: Vec<u64>,
    counts: Vec<[u64; 2]>,
}

impl SpillIndex {
    /// The node and full node counts of cell `s`'s level `j` (`1 … t`).
    fn counts(&self, t: usize, s: usize, j: usize) -> [u64; 2] {
        self.counts[s * t + j - 1]
    }

    /// The words of cell `s`'s piece of level `j`: codes, then values of `value_bytes` bytes each.
    fn piece_words(&self, t: usize, s: usize, j: usize, value_bytes: u64) -> (u64, u64) {
        let [nodes, full] = self.counts(t, s, j);
        (nodes.div_ceil(32), (full * value_bytes).div_ceil(8))
    }

    /// Each piece's first word in the store's level `j`; returns the level's words.
    fn offsets(&self, t: usize, j: usize, value_bytes: u64, offsets: &mut [u64]) -> u64 {
        let mut at = 0;
        for (s, offset) in offsets.iter_mut().enumerate() {
            *offset = at;
            let (codes, values) = self.piece_words(t, s, j, value_bytes);
            at += codes + values;
        }
        at
    }

    /// The positions of the cells in Morton order.
    fn morton_order(&self) -> Vec<usize> {
        let mut order: Vec<usize> = (0..self.mortons.len()).collect();
        order.sort_unstable_by_key(|&s| self.mortons[s]);
        order
    }
}

/// The cells of some slabs of a [`ValueSlabs`] box built and their subtrees spilled to the stored pieces
/// `P` ([`ValueSlabs::stack_part`]), and the indexes of the parts other processes built
/// ([`add_part`](Self::add_part)): all that is needed to write the tree
/// ([`write_into`](Self::write_into) any [`ValuedLevelSink`]; `io`'s `ValuePart::write` a `.ktree` file),
/// the levels of the other parts received as streams ([`stream_levels`](Self::stream_levels)).
pub struct ValuePart<const K: usize, V, P> {
    level: u32,
    m: u32,
    /// The slabs read by this part and by the parts added (to refuse overlapping parts).
    read: Vec<Range<u32>>,
    /// The slabs whose cells are not all empty, each with its cells' roots (`2^(m(K − 1))` in the Morton
    /// order of their coordinates along the other axes), in no particular order until written.
    layers: Vec<(u32, Vec<ValueState<V>>)>,
    own: SpillIndex,
    others: Vec<SpillIndex>,
    pieces: P,
    spilled_bytes: u64,
}

/// The word of a cell's root state in an index: its 2-bit code, and a full node's value's little-endian
/// bytes from bit 8 on.
fn state_word<V: Value>(state: ValueState<V>) -> u64 {
    let (code, value) = match state {
        ValueState::Empty => (0, None),
        ValueState::Full(v) => (1, Some(v)),
        ValueState::Partial => (2, None),
        ValueState::Mixed => (3, None),
    };
    let mut bytes = Vec::with_capacity(4);
    if let Some(v) = value {
        v.write_le(&mut bytes);
    }
    let mut word = [0u8; 8];
    word[..bytes.len()].copy_from_slice(&bytes);
    code | u64::from_le_bytes(word) << 8
}

/// The state a [`state_word`] holds; `None` if it holds none (a value refused, stray bits).
fn word_state<V: Value>(word: u64) -> Option<ValueState<V>> {
    let bytes = V::DTYPE.map_or(0, |d| d.bytes());
    let value = word >> 8;
    let full = match word & 0xff {
        1 => {
            if bytes < 7 && value >> (8 * bytes) != 0 {
                return None;
            }
            let v = V::read_le(&(value).to_le_bytes()[..bytes]);
            v.check().ok()?;
            return Some(ValueState::Full(v));
        }
        0 => ValueState::Empty,
        2 => ValueState::Partial,
        3 => ValueState::Mixed,
        _ => return None,
    };
    (value == 0).then_some(full)
}

impl<const K: usize, V: Value + Send + Sync> ValueSlabs<K, V> {
    /// Builds the part of the tree in the slabs `slabs` (those of `0 … slab_count()` in that range, see
    /// [`slab_count`](Self::slab_count)), reading only their rows of the box — `read` is called with
    /// ranges of the last coordinate from `slabs`' first on, in order — and spilling the levels below
    /// each of their cells with children to `store`. The part that writes the tree adds the others'
    /// indexes ([`ValuePart::add_part`]) and writes it ([`ValuePart::write_into`]).
    ///
    /// # Errors
    /// As [`build_into`](Self::build_into): [`BuildError::Source`], the error of `read` or what the box
    /// refuses; [`BuildError::Files`], the store's.
    pub fn stack_part<E, P>(
        &self,
        slabs: Range<u32>,
        mut read: impl FnMut(Range<u32>, &mut Vec<V>) -> Result<(), E>,
        store: P,
    ) -> Result<ValuePart<K, V, P::Stored>, BuildError<E, P::Error>>
    where
        E: From<RayError>,
        P: PieceStore,
    {
        let universe = self
            .check_box()
            .map_err(|e| BuildError::Source(E::from(e)))?;
        let mut slab = Vec::new();
        stack_cells(self.level, self.cell_depth(), slabs, store, |b| {
            self.read_slab(universe, b, &mut read, &mut slab)
        })
    }
}

/// The part of a valued tree of level `level` in the slabs `slabs` of its cells of depth `m` (clamped to
/// the `2^m` slabs along the last axis), `cells_of(b)` giving slab `b`'s cells (in the Morton order of
/// their coordinates along the other axes; `None` if all are empty), the levels below each cell with
/// children spilled to `store`.
pub(crate) fn stack_cells<const K: usize, V, E, P>(
    level: u32,
    m: u32,
    slabs: Range<u32>,
    mut store: P,
    mut cells_of: impl FnMut(u32) -> Result<Option<Vec<Subtree<V>>>, E>,
) -> Result<ValuePart<K, V, P::Stored>, BuildError<E, P::Error>>
where
    V: Value + Send + Sync,
    P: PieceStore,
{
    let t = (level - m) as usize;
    let count = 1u32 << m;
    let slabs = slabs.start.min(count)..slabs.end.min(count);
    let mut own = SpillIndex::default();
    let mut layers = Vec::new();
    let mut spilled_words = 0u64;
    let mut piece = Vec::new();
    for b in slabs.clone() {
        let Some(mut cells) = cells_of(b).map_err(BuildError::Source)? else {
            continue;
        };
        let levels: Vec<Option<Vec<PackedLevel<V>>>> = cells
            .par_iter_mut()
            .map(|cell| cell.root().has_children().then(|| cell.take_levels_below()))
            .collect();
        for (i, levels) in levels.into_iter().enumerate() {
            let Some(levels) = levels else { continue };
            own.mortons
                .push(spread_across::<K>(i as u64) | spread_last::<K>(b));
            for j in 1..=t {
                let Some((codes, values)) = levels.get(j - 1) else {
                    own.counts.push([0, 0]);
                    continue;
                };
                piece.clear();
                piece.extend_from_slice(codes.words());
                push_value_words(values, &mut piece);
                store.append(j, &piece, codes.len() as u64)?;
                spilled_words += piece.len() as u64;
                own.counts.push([codes.len() as u64, values.len() as u64]);
            }
        }
        let roots: Vec<ValueState<V>> = cells.iter().map(Subtree::root).collect();
        if roots.iter().any(|r| !matches!(r, ValueState::Empty)) {
            layers.push((b, roots));
        }
    }
    Ok(ValuePart {
        level,
        m,
        read: vec![slabs],
        layers,
        own,
        others: Vec::new(),
        pieces: store.finish()?,
        spilled_bytes: 8 * spilled_words,
    })
}

impl<const K: usize, V: Value + Send + Sync, P: StoredPieces> ValuePart<K, V, P> {
    /// The level `L` of the tree's universe.
    pub fn level(&self) -> u32 {
        self.level
    }

    /// Levels of a cell's subtree below its root.
    fn t(&self) -> usize {
        (self.level - self.m) as usize
    }

    /// Bytes of a value.
    fn value_bytes() -> u64 {
        V::DTYPE.map_or(0, |d| d.bytes()) as u64
    }

    /// The cells of depth `m` with children built by this part.
    pub fn subtrees(&self) -> u64 {
        self.own.mortons.len() as u64
    }

    /// The index of this part for the part that writes the tree ([`add_part`](Self::add_part)): the
    /// slabs it read, the roots of their cells and, for each cell it spilled, its Morton index and counts
    /// per level — nothing of the subtrees themselves.
    pub fn index_words(&self) -> Vec<u64> {
        let slabs = self.read.first().cloned().unwrap_or(0..0);
        let mut words = vec![
            INDEX_MAGIC,
            K as u64,
            u64::from(self.level),
            u64::from(self.m),
            V::DTYPE.map_or(0, |d| u64::from(d.code())),
            u64::from(slabs.start),
            u64::from(slabs.end),
            self.layers.len() as u64,
            self.own.mortons.len() as u64,
            self.spilled_bytes,
        ];
        for (b, roots) in &self.layers {
            words.push(u64::from(*b));
            words.extend(roots.iter().map(|&r| state_word(r)));
        }
        words.extend(&self.own.mortons);
        words.extend(self.own.counts.iter().flatten());
        words
    }

    /// Adds the index of a part built elsewhere ([`index_words`](Self::index_words) of a part of the
    /// same build, over other slabs), as owner `1, 2, …` in the order added; returns the number of words
    /// its [`stream_levels`](Self::stream_levels) sends.
    ///
    /// # Errors
    /// [`std::io::ErrorKind::InvalidData`] if `words` is not the index of another part of this build.
    pub fn add_part(&mut self, words: &[u64]) -> std::io::Result<u64> {
        let bad = |what: &str| {
            std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("the index of part {}: {what}", self.others.len() + 1),
            )
        };
        if self.others.len() + 1 >= MAX_PARTS {
            return Err(bad("too many parts"));
        }
        if words.len() < INDEX_HEADER || words[0] != INDEX_MAGIC {
            return Err(bad("not a part index"));
        }
        let dtype = V::DTYPE.map_or(0, |d| u64::from(d.code()));
        let expected = [K as u64, u64::from(self.level), u64::from(self.m), dtype];
        if words[1..5] != expected {
            return Err(bad("another K, level, cell depth or value type"));
        }
        let count = 1u64 << self.m;
        let (start, end) = (words[5], words[6]);
        if start > end || end > count {
            return Err(bad("slabs outside the universe"));
        }
        let slabs = start as u32..end as u32;
        if !slabs.is_empty()
            && self
                .read
                .iter()
                .any(|r| r.start < slabs.end && slabs.start < r.end)
        {
            return Err(bad("slabs another part read"));
        }
        let t = self.t();
        let (layers, n) = (words[7], words[8]);
        let per_slab = 1u128 << (u128::from(self.m) * (K as u128 - 1));
        let length = u128::from(layers) * (per_slab + 1)
            + u128::from(n) * (2 * t as u128 + 1)
            + INDEX_HEADER as u128;
        if length != words.len() as u128 {
            return Err(bad("its length does not match its header"));
        }
        let per_slab = per_slab as usize;
        let mut body = &words[INDEX_HEADER..];
        let mut received = Vec::with_capacity(layers as usize);
        // The cells with children its layers hold, to match against the cells it spilled.
        let mut parents = Vec::new();
        for _ in 0..layers {
            let (layer, rest) = body.split_at(per_slab + 1);
            body = rest;
            let b = layer[0];
            if !(start..end).contains(&b)
                || received
                    .last()
                    .is_some_and(|(last, _): &(u32, _)| u64::from(*last) >= b)
            {
                return Err(bad("a slab out of place"));
            }
            let roots = layer[1..]
                .iter()
                .map(|&w| word_state::<V>(w))
                .collect::<Option<Vec<_>>>()
                .ok_or_else(|| bad("a cell's state that is none"))?;
            for (i, r) in roots.iter().enumerate() {
                if r.has_children() {
                    parents.push(spread_across::<K>(i as u64) | spread_last::<K>(b as u32));
                }
            }
            received.push((b as u32, roots));
        }
        let (mortons, counts) = body.split_at(n as usize);
        let mut spilled = mortons.to_vec();
        spilled.sort_unstable();
        parents.sort_unstable();
        if spilled != parents {
            return Err(bad("its spilled cells are not its cells with children"));
        }
        let mut stream = 0u64;
        let mut index = SpillIndex {
            mortons: mortons.to_vec(),
            counts: Vec::with_capacity(n as usize * t),
        };
        for (s, pair) in counts.chunks_exact(2).enumerate() {
            let (nodes, full) = (pair[0], pair[1]);
            let j = s % t + 1;
            if full > nodes || u128::from(nodes) > 1u128 << (K * j).min(127) {
                return Err(bad("more nodes than a subtree level holds"));
            }
            stream += nodes.div_ceil(32) + (full * Self::value_bytes()).div_ceil(8);
            index.counts.push([nodes, full]);
        }
        self.read.push(slabs);
        self.layers.extend(received);
        self.spilled_bytes += words[9];
        self.others.push(index);
        Ok(stream)
    }

    /// Sends this part's spilled levels to the part that writes the tree: for each level `1 … t`, the
    /// codes of its cells' pieces in Morton order, then their values (whole words), concatenated and cut
    /// into chunks of at most `chunk_words` words handed to `send` in order; returns the words sent. The
    /// writer takes them in the same order ([`write_into`](Self::write_into)).
    ///
    /// # Errors
    /// A piece that cannot be read back, or the error of `send`.
    pub fn stream_levels(
        &mut self,
        chunk_words: usize,
        send: &mut dyn FnMut(&[u64]) -> std::io::Result<()>,
    ) -> std::io::Result<u64>
    where
        P::Error: Into<std::io::Error>,
    {
        let t = self.t();
        let value_bytes = Self::value_bytes();
        let order = self.own.morton_order();
        let mut offsets = vec![0u64; order.len()];
        let mut stream = ChunkedSend::new(chunk_words, send);
        for j in 1..=t {
            let at = self.own.offsets(t, j, value_bytes, &mut offsets);
            let mut level = self.pieces.level(j, &offsets, at);
            for values in [false, true] {
                for &s in &order {
                    let (codes, value_words) = self.own.piece_words(t, s, j, value_bytes);
                    let (from, count) = if values {
                        (codes, value_words)
                    } else {
                        (0, codes)
                    };
                    stream.push_from(count, |at, out| {
                        level.read(s, from + at, out).map_err(Into::into)
                    })?;
                }
            }
            level.finish();
        }
        stream.finish()
    }

    /// The writing phase: writes the tree to `sink` level by level — the top levels joined from every
    /// slab's cells, then each level below the cells, its pieces in the Morton order of their cells, each
    /// from its owner: this part's store, or `receive(owner, words)`, which fills `words` with the next
    /// words of that owner's [`stream_levels`](Self::stream_levels). Returns the finished output and the
    /// report (its `file_bytes` 0).
    ///
    /// # Errors
    /// [`BuildError::PartsOverlap`] if two parts spilled one cell; the error of a piece read back, of
    /// `sink` or of `receive`.
    pub fn write_into<E, O, R>(
        self,
        mut sink: O,
        mut receive: R,
    ) -> Result<(O::Output, ValueSlabsReport), BuildError<E, P::Error>>
    where
        O: ValuedLevelSink<Error = P::Error>,
        R: FnMut(usize, &mut [u64]) -> Result<(), P::Error>,
    {
        let t = self.t();
        let value_bytes = Self::value_bytes();
        let ValuePart {
            level: _,
            m,
            read: _,
            mut layers,
            own,
            others,
            mut pieces,
            spilled_bytes,
        } = self;
        // The top levels, joined from the slabs' cells in order.
        layers.sort_unstable_by_key(|(b, _)| std::cmp::Reverse(*b));
        let top = join_slabs::<K, V, BuildError<E, P::Error>>(m, |b| {
            if layers.last().is_some_and(|(next, _)| *next == b) {
                let (_, roots) = layers.pop().expect("a layer");
                return Ok(Some(roots.into_iter().map(Subtree::leaf).collect()));
            }
            Ok(None)
        })?;
        for (codes, values) in top.into_packed_levels() {
            sink.append_words(codes.words(), codes.len() as u64)?;
            sink.end_codes()?;
            let mut bytes = Vec::with_capacity(values.len() * value_bytes as usize);
            for &v in &values {
                v.write_le(&mut bytes);
            }
            sink.append_values(&bytes)?;
            sink.end_level()?;
        }
        // Every part's spilled cells in Morton order, as (owner, position in its index) packed in a word:
        // the owner in the top 16 bits.
        let parts: Vec<&SpillIndex> = std::iter::once(&own).chain(&others).collect();
        let mut order: Vec<u64> = Vec::new();
        for (owner, part) in parts.iter().enumerate() {
            order.extend((0..part.mortons.len() as u64).map(|s| (owner as u64) << 48 | s));
        }
        let unpack = |o: u64| ((o >> 48) as usize, (o & ((1 << 48) - 1)) as usize);
        let morton = |o: u64| {
            let (owner, s) = unpack(o);
            parts[owner].mortons[s]
        };
        order.sort_unstable_by_key(|&o| morton(o));
        if order.windows(2).any(|w| morton(w[0]) == morton(w[1])) {
            return Err(BuildError::PartsOverlap);
        }
        let mut offsets = vec![0u64; own.mortons.len()];
        let mut words = vec![0u64; CHUNK_WORDS];
        let mut bytes = Vec::with_capacity(8 * CHUNK_WORDS);
        for j in 1..=t {
            if order.iter().all(|&o| {
                let (owner, s) = unpack(o);
                parts[owner].counts(t, s, j)[0] == 0
            }) {
                break;
            }
            let at = own.offsets(t, j, value_bytes, &mut offsets);
            let mut level = pieces.level(j, &offsets, at);
            // Each piece's words from `from` on into `chunk`, from its owner.
            let mut take = |owner: usize, s: usize, from: u64, chunk: &mut [u64]| {
                if owner == 0 {
                    level.read(s, from, chunk)
                } else {
                    receive(owner, chunk)
                }
            };
            for &o in &order {
                let (owner, s) = unpack(o);
                let mut nodes = parts[owner].counts(t, s, j)[0];
                let mut from = 0;
                while nodes > 0 {
                    let n = nodes.min(32 * CHUNK_WORDS as u64);
                    let chunk = &mut words[..n.div_ceil(32) as usize];
                    take(owner, s, from, chunk)?;
                    sink.append_words(chunk, n)?;
                    from += chunk.len() as u64;
                    nodes -= n;
                }
            }
            sink.end_codes()?;
            for &o in &order {
                let (owner, s) = unpack(o);
                let index = parts[owner];
                let (mut from, mut left) = index.piece_words(t, s, j, value_bytes);
                let mut value_left = index.counts(t, s, j)[1] * value_bytes;
                while left > 0 {
                    let chunk = &mut words[..left.min(CHUNK_WORDS as u64) as usize];
                    take(owner, s, from, chunk)?;
                    bytes.clear();
                    bytes.extend(chunk.iter().flat_map(|w| w.to_le_bytes()));
                    bytes.truncate(value_left.min(bytes.len() as u64) as usize);
                    sink.append_values(&bytes)?;
                    value_left -= bytes.len() as u64;
                    from += chunk.len() as u64;
                    left -= chunk.len() as u64;
                }
            }
            sink.end_level()?;
            level.finish();
        }
        let counts_per_level = sink.counts_per_level();
        let output = sink.finish()?;
        Ok((
            output,
            ValueSlabsReport {
                counts_per_level,
                file_bytes: 0,
                cell_depth: m,
                subtrees: order.len() as u64,
                spilled_bytes,
            },
        ))
    }
}

/// The Morton key, among cells of `K` dimensions, of the cell whose last coordinate is `b` and whose other
/// coordinates are 0.
fn spread_last<const K: usize>(b: u32) -> u64 {
    (0..32)
        .filter(|bit| b >> bit & 1 == 1)
        .map(|bit| 1u64 << (bit * K + K - 1))
        .sum()
}

/// Appends values as their little-endian bytes, zero-padded to whole words.
fn push_value_words<V: Value>(values: &[V], out: &mut Vec<u64>) {
    let mut bytes = Vec::with_capacity(std::mem::size_of_val(values));
    for &v in values {
        v.write_le(&mut bytes);
    }
    out.extend(bytes.chunks(8).map(|c| {
        let mut word = [0u8; 8];
        word[..c.len()].copy_from_slice(c);
        u64::from_le_bytes(word)
    }));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::space::morton_encode;
    use crate::value::Rgb;

    #[test]
    fn the_last_coordinate_spreads_to_the_last_axis() {
        assert_eq!(spread_last::<3>(0b101), morton_encode::<3>([0, 0, 0b101]));
        assert_eq!(spread_last::<1>(0b1101), 0b1101);
        assert_eq!(
            spread_across::<4>(0b1011) | spread_last::<4>(0b10),
            morton_encode::<4>([0b11, 0b1, 0, 0b10])
        );
    }

    #[test]
    fn a_state_word_holds_its_state() {
        let states = [
            ValueState::Empty,
            ValueState::Full(0xdead_beef_u32),
            ValueState::Full(0),
            ValueState::Partial,
            ValueState::Mixed,
        ];
        for s in states {
            assert_eq!(word_state::<u32>(state_word(s)), Some(s));
        }
        let colour: Rgb = [1, 2, 3];
        let word = state_word(ValueState::Full(colour));
        assert_eq!(word_state::<Rgb>(word), Some(ValueState::Full(colour)));
        // Stray bits, an unknown code, a NaN.
        assert_eq!(word_state::<Rgb>(word | 1 << 40), None);
        assert_eq!(word_state::<u8>(2 | 1 << 8), None);
        assert_eq!(word_state::<u8>(4), None);
        assert_eq!(
            word_state::<f32>(state_word(ValueState::Full(f32::NAN))),
            None
        );
        assert_eq!(
            word_state::<f32>(state_word(ValueState::Full(-0.5f32))),
            Some(ValueState::Full(-0.5))
        );
    }
}
