//! Where the subtrees of the stacked cells wait until the tree is written: a [`PieceStore`], appended to
//! while the cells are stacked, then read back level by level ([`StoredPieces`], [`LevelPieces`]).

/// Where the pieces of the stacked cells' subtrees are appended while the cells are stacked;
/// [`finish`](Self::finish) makes them readable.
///
/// A stacked cell's subtree is kept as one *piece* per level below its root (levels `1 … t`, `t = L − m`):
/// its nodes packed two bits a node, 32 to a little-endian `u64` word as in
/// [`PackedStates::words`](crate::tree::PackedStates::words), in whole words (`⌈nodes / 32⌉` of them). The
/// pieces of a level are appended in the order the cells are spilled and read back in the Morton order of
/// the cells, each once, so a store can give a piece's room back as soon as it is read. The builder
/// knows nothing else of the store: `io` keeps the pieces in spill files
/// ([`Builder::to_file`](crate::stacking::Builder::to_file)); a store in memory is a `Vec` per level.
///
/// # Example
/// A store in memory, and an output that counts the nodes of each level:
/// ```
/// use ktree::rays::ball_rays;
/// use ktree::stacking::{Builder, LevelOrderSink, LevelPieces, PieceStore, StoredPieces};
/// use ktree::LevelCounts;
///
/// /// The pieces of each level one after the other in a `Vec`.
/// #[derive(Default)]
/// struct InMemory(Vec<Vec<u64>>);
///
/// impl PieceStore for InMemory {
///     type Error = std::io::Error;
///     type Stored = InMemory;
///     fn append(&mut self, depth: usize, words: &[u64], _nodes: u64) -> std::io::Result<()> {
///         if self.0.len() < depth {
///             self.0.resize(depth, Vec::new());
///         }
///         self.0[depth - 1].extend_from_slice(words);
///         Ok(())
///     }
///     fn finish(self) -> std::io::Result<InMemory> {
///         Ok(self)
///     }
/// }
///
/// /// Level `depth` being read: its words and where its pieces start.
/// struct Level<'a> {
///     words: Vec<u64>,
///     offsets: &'a [u64],
/// }
///
/// impl StoredPieces for InMemory {
///     type Error = std::io::Error;
///     type Level<'a> = Level<'a>;
///     fn level<'a>(&'a mut self, depth: usize, offsets: &'a [u64], _words: u64) -> Level<'a> {
///         let words = self.0.get_mut(depth - 1).map(std::mem::take).unwrap_or_default();
///         Level { words, offsets }
///     }
/// }
///
/// impl LevelPieces for Level<'_> {
///     type Error = std::io::Error;
///     fn read(&mut self, piece: usize, at: u64, out: &mut [u64]) -> std::io::Result<()> {
///         let start = (self.offsets[piece] + at) as usize;
///         out.copy_from_slice(&self.words[start..start + out.len()]);
///         Ok(())
///     }
///     fn finish(self) {}
/// }
///
/// /// The tree's levels, counted (a real output would keep them).
/// #[derive(Default)]
/// struct Counted(Vec<u64>, u64);
///
/// impl LevelOrderSink for Counted {
///     type Error = std::io::Error;
///     type Output = Vec<u64>;
///     fn append_words(&mut self, _words: &[u64], nodes: u64) -> std::io::Result<()> {
///         self.1 += nodes;
///         Ok(())
///     }
///     fn end_level(&mut self) -> std::io::Result<()> {
///         self.0.push(std::mem::take(&mut self.1));
///         Ok(())
///     }
///     fn counts_per_level(&self) -> Vec<LevelCounts> {
///         Vec::new()
///     }
///     fn finish(self) -> std::io::Result<Vec<u64>> {
///         Ok(self.0)
///     }
/// }
///
/// let ball = ball_rays::<3>(5, [32, 32, 32], 40).unwrap();
/// let builder = Builder::new(&ball).split_depth(2);
/// let (nodes, _) = builder.build_into(InMemory::default(), Counted::default(), 1 << 30).unwrap();
/// let tree = builder.build().unwrap();
/// let expected: Vec<u64> = tree.counts_per_level().iter().map(|c| c.nodes()).collect();
/// assert_eq!(nodes, expected);
/// ```
pub trait PieceStore: Send {
    /// Why a piece could not be stored or read back.
    type Error: Send;
    /// The pieces stored, to be read back.
    type Stored: StoredPieces<Error = Self::Error> + Send;

    /// Appends a piece of `nodes` nodes, packed in `words` (`⌈nodes / 32⌉` words; a valued build's pieces
    /// hold their full nodes' values in the words after them, see
    /// [`ValueSlabs::build_into`](crate::stacking::ValueSlabs::build_into)), to level `depth ≥ 1` of the
    /// subtrees (after the pieces appended to it before).
    ///
    /// # Errors
    /// The store's error.
    fn append(&mut self, depth: usize, words: &[u64], nodes: u64) -> Result<(), Self::Error>;

    /// Ends the appending: every piece appended can be read back.
    ///
    /// # Errors
    /// The store's error.
    fn finish(self) -> Result<Self::Stored, Self::Error>;
}

/// The pieces of a [`PieceStore`], read back one level at a time.
pub trait StoredPieces {
    /// Why a piece could not be read back.
    type Error;
    /// A level being read back.
    type Level<'a>: LevelPieces<Error = Self::Error>
    where
        Self: 'a;

    /// Starts reading level `depth ≥ 1` back: its pieces, in the order they were appended, start at the
    /// word offsets `offsets` (a piece ends where the next starts), and the level is `words` words long.
    /// A level no piece was appended to has no words.
    fn level<'a>(&'a mut self, depth: usize, offsets: &'a [u64], words: u64) -> Self::Level<'a>;
}

/// One level of a [`StoredPieces`] being read back: each piece's words once, in order (in one read or
/// several), the pieces in any order (the builder takes them in the Morton order of their cells; a valued
/// build reads every piece's codes, then every piece's values).
pub trait LevelPieces {
    /// Why a piece could not be read back.
    type Error;

    /// Fills `out` with the words `at … at + out.len()` of piece `piece` (of its own words, from 0). Once
    /// the last word of a piece is read the store may give back the room it takes.
    ///
    /// # Errors
    /// The store's error (a piece shorter than asked for included).
    fn read(&mut self, piece: usize, at: u64, out: &mut [u64]) -> Result<(), Self::Error>;

    /// Ends reading the level (no piece of it is read again): the store may give back what it holds.
    fn finish(self);
}

/// A stream of words cut into chunks of at most a given length, each handed to `send` once full (the
/// last when [`finish`](Self::finish)ed): how a part streams its pieces to the part that writes the tree.
pub(crate) struct ChunkedSend<'a> {
    chunk: Vec<u64>,
    chunk_words: usize,
    send: &'a mut dyn FnMut(&[u64]) -> std::io::Result<()>,
    sent: u64,
}

impl<'a> ChunkedSend<'a> {
    /// Chunks of at most `chunk_words` words (at least one).
    pub(crate) fn new(
        chunk_words: usize,
        send: &'a mut dyn FnMut(&[u64]) -> std::io::Result<()>,
    ) -> Self {
        let chunk_words = chunk_words.max(1);
        Self {
            chunk: Vec::with_capacity(chunk_words),
            chunk_words,
            send,
            sent: 0,
        }
    }

    /// Appends `count` words, `read(at, out)` filling `out` with the words from `at` on.
    ///
    /// # Errors
    /// The error of `read` or of `send`.
    pub(crate) fn push_from(
        &mut self,
        count: u64,
        mut read: impl FnMut(u64, &mut [u64]) -> std::io::Result<()>,
    ) -> std::io::Result<()> {
        let mut at = 0;
        while at < count {
            let take = (count - at).min((self.chunk_words - self.chunk.len()) as u64);
            let filled = self.chunk.len();
            self.chunk.resize(filled + take as usize, 0);
            read(at, &mut self.chunk[filled..])?;
            at += take;
            if self.chunk.len() == self.chunk_words {
                (self.send)(&self.chunk)?;
                self.sent += self.chunk.len() as u64;
                self.chunk.clear();
            }
        }
        Ok(())
    }

    /// Sends what is left; returns the words sent.
    ///
    /// # Errors
    /// The error of `send`.
    pub(crate) fn finish(mut self) -> std::io::Result<u64> {
        if !self.chunk.is_empty() {
            (self.send)(&self.chunk)?;
            self.sent += self.chunk.len() as u64;
        }
        Ok(self.sent)
    }
}
