//! What the `.ktree` writers of versions 2 ([`KtreeWriter`](super::KtreeWriter)) and 3
//! ([`ValuedKtreeWriter`](super::v3::ValuedKtreeWriter)) share: a file written level after level, each
//! level's codes appended in pieces at any node offset, counted and rank-sampled as they pass, the bytes
//! buffered and each section's CRC computed on the way, and the directory written at the end.

use std::io::Write;

use super::v2::layout::{directory_tail, invalid, slots_mask, Section, WORDS_PER_SAMPLE};
use crate::space::{max_level, MAX_K};
use crate::tree::words::{children_mask, full_mask, WordPacker, NODES_PER_WORD};
use crate::tree::LevelCounts;

/// Bytes gathered before they are written.
const BUFFER_BYTES: usize = 1 << 16;

/// A `.ktree` file being written level after level, from the root down.
#[derive(Debug)]
pub(super) struct LevelStream<W: Write> {
    out: W,
    k: usize,
    level: u32,
    /// The header (with a version 3 file's frame and notes): the file's last CRC covers it.
    header: Vec<u8>,
    /// Bytes written so far, and where the current section starts.
    written: u64,
    section_start: u64,
    buffer: Vec<u8>,
    hasher: crc32fast::Hasher,
    finished: Vec<Section>,
    codes: LevelCodes,
    /// Whether the full nodes are rank-sampled too (version 3).
    sample_full: bool,
}

/// The codes of the level being written.
#[derive(Debug, Default)]
struct LevelCodes {
    nodes: u64,
    words: u64,
    full: u64,
    /// Nodes with children (partial, or in a version 3 file mixed).
    children: u64,
    packer: WordPacker,
    /// The nodes with children, and (if sampled) the full nodes, before every 64th word.
    children_samples: Vec<u64>,
    full_samples: Vec<u64>,
    /// Whether the codes were ended.
    ended: bool,
}

impl<W: Write> LevelStream<W> {
    /// Starts a file of a `K = k` tree in a level-`level` universe, writing `header`; each level's codes
    /// are followed by rank samples of the nodes with children, then (with `sample_full`, in a version 3
    /// file) of the full nodes.
    ///
    /// # Errors
    /// `InvalidInput` for `k` or `level` out of range; any I/O error.
    pub(super) fn new(
        mut out: W,
        k: usize,
        level: u32,
        header: Vec<u8>,
        sample_full: bool,
    ) -> std::io::Result<Self> {
        if !(1..=MAX_K).contains(&k) || level > max_level(k) {
            return Err(invalid(format!(
                "K = {k}, L = {level} is not a valid universe"
            )));
        }
        out.write_all(&header)?;
        let written = header.len() as u64;
        Ok(Self {
            out,
            k,
            level,
            header,
            written,
            section_start: written,
            buffer: Vec::with_capacity(BUFFER_BYTES),
            hasher: crc32fast::Hasher::new(),
            finished: Vec::new(),
            codes: LevelCodes::default(),
            sample_full,
        })
    }

    /// The depth of the level being written.
    pub(super) fn depth(&self) -> usize {
        self.finished.len()
    }

    /// Whether the current level's codes were ended.
    pub(super) fn codes_ended(&self) -> bool {
        self.codes.ended
    }

    /// Whether nothing was appended to the current level.
    pub(super) fn level_is_empty(&self) -> bool {
        self.codes.nodes == 0 && !self.codes.ended
    }

    /// The full nodes of the current level's codes appended so far.
    pub(super) fn full(&self) -> u64 {
        self.codes.full
    }

    /// Appends `nodes` codes packed in `words` to the current level, shifted to follow the codes before
    /// them.
    ///
    /// # Errors
    /// `InvalidInput` if `words` holds fewer than `nodes` codes or the level's codes were ended; any I/O
    /// error.
    pub(super) fn append_codes(&mut self, words: &[u64], nodes: u64) -> std::io::Result<()> {
        if self.codes.ended {
            return Err(invalid(format!(
                "codes appended to level {} after its values began",
                self.depth()
            )));
        }
        let needed = nodes.div_ceil(NODES_PER_WORD as u64);
        if (words.len() as u64) < needed {
            return Err(invalid(format!(
                "{} words cannot hold {nodes} nodes",
                words.len()
            )));
        }
        let mut remaining = nodes;
        for &word in &words[..needed as usize] {
            let take = remaining.min(NODES_PER_WORD as u64);
            if let Some(whole) = self
                .codes
                .packer
                .push(word & slots_mask(take), take as usize)
            {
                self.emit(whole)?;
            }
            remaining -= take;
        }
        self.codes.nodes += nodes;
        Ok(())
    }

    /// Writes one complete word of codes.
    fn emit(&mut self, word: u64) -> std::io::Result<()> {
        let codes = &mut self.codes;
        if codes.words.is_multiple_of(WORDS_PER_SAMPLE) {
            codes.children_samples.push(codes.children);
            if self.sample_full {
                codes.full_samples.push(codes.full);
            }
        }
        codes.words += 1;
        codes.full += u64::from(full_mask(word).count_ones());
        codes.children += u64::from(children_mask(word).count_ones());
        self.put(&word.to_le_bytes())
    }

    /// Appends bytes to the current section.
    ///
    /// # Errors
    /// Any I/O error.
    pub(super) fn put(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.buffer.extend_from_slice(bytes);
        if self.buffer.len() >= BUFFER_BYTES {
            self.flush_buffer()?;
        }
        Ok(())
    }

    fn flush_buffer(&mut self) -> std::io::Result<()> {
        self.hasher.update(&self.buffer);
        self.out.write_all(&self.buffer)?;
        self.written += self.buffer.len() as u64;
        self.buffer.clear();
        Ok(())
    }

    /// Ends the current level's codes and writes its rank samples.
    ///
    /// # Errors
    /// `InvalidInput` if the codes were ended already, the root level is not one node, the level's size is
    /// not `2^K` times the nodes with children of the level above, or the tree would be deeper than the
    /// universe; any I/O error.
    pub(super) fn end_codes(&mut self) -> std::io::Result<()> {
        let depth = self.depth();
        if self.codes.ended {
            return Err(invalid(format!("the codes of level {depth} ended twice")));
        }
        let nodes = self.codes.nodes;
        let expected = match self.finished.last() {
            None => 1,
            Some(above) => above.partial << self.k,
        };
        if nodes != expected || depth > self.level as usize {
            return Err(invalid(format!(
                "level {depth} has {nodes} nodes, but the levels above call for {expected} (universe level {})",
                self.level
            )));
        }
        if let Some(word) = self.codes.packer.flush() {
            self.emit(word)?;
        }
        let children = std::mem::take(&mut self.codes.children_samples);
        let full = std::mem::take(&mut self.codes.full_samples);
        for s in children.iter().chain(&full) {
            self.put(&s.to_le_bytes())?;
        }
        self.codes.ended = true;
        Ok(())
    }

    /// Closes the current level (its codes ended, and anything after them put): the next append starts
    /// the level below.
    ///
    /// # Errors
    /// Any I/O error.
    pub(super) fn end_level(&mut self) -> std::io::Result<()> {
        debug_assert!(self.codes.ended);
        self.flush_buffer()?;
        let codes = std::mem::take(&mut self.codes);
        let hasher = std::mem::take(&mut self.hasher);
        self.finished.push(Section {
            offset: self.section_start,
            nodes: codes.nodes,
            full: codes.full,
            partial: codes.children,
            crc: hasher.finalize(),
        });
        self.section_start = self.written;
        Ok(())
    }

    /// The node counts of the levels closed so far (`level` = depth).
    pub(super) fn counts_per_level(&self) -> Vec<LevelCounts> {
        super::v2::layout::counts_of(&self.finished)
    }

    /// Writes the directory and returns the output.
    ///
    /// # Errors
    /// `InvalidInput` if no level was written or the last level has nodes with children; any I/O error.
    pub(super) fn finish(mut self) -> std::io::Result<W> {
        let tail = directory_tail(&self.finished, self.written, &self.header)?;
        self.out.write_all(&tail)?;
        self.out.flush()?;
        Ok(self.out)
    }
}
