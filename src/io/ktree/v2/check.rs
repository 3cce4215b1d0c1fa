//! The checks of a version 2 file's sections (listed in [`layout`](super::layout)), run in bounded windows
//! when a file is opened or read, and reading a checked file's bytes into a tree.

use super::super::notes::Notes;
use super::super::{KtreeFileError, KtreeFileErrorKind};
use super::layout::*;
use crate::space::{Universe, WorldFrame};
use crate::tree::{AnyTree, KTree, PackedStates};

impl Layout {
    /// Checks every section; `window(offset, len, f)` calls `f` with the file's bytes `offset … offset +
    /// len` (`len ≤ WINDOW_BYTES`, a multiple of 8).
    pub(super) fn check_sections(
        &self,
        file: &str,
        mut window: impl FnMut(
            u64,
            usize,
            &mut dyn FnMut(&[u8]) -> Result<(), KtreeFileError>,
        ) -> Result<(), KtreeFileError>,
    ) -> Result<(), KtreeFileError> {
        for (depth, section) in self.sections.iter().enumerate() {
            let samples_len = (section.bytes() - 8 * section.words()) as usize;
            let mut samples = Vec::with_capacity(samples_len / 8);
            let mut copy_samples = |bytes: &[u8]| {
                samples.extend(
                    bytes
                        .chunks_exact(8)
                        .map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes"))),
                );
                Ok(())
            };
            // The samples are ⌈W/64⌉ words: at most 1/64 of the section, read in windows too.
            let mut at = 0;
            while at < samples_len {
                let n = (samples_len - at).min(WINDOW_BYTES);
                window(section.samples_offset() + at as u64, n, &mut copy_samples)?;
                at += n;
            }
            let mut scan = SectionScan::new(file, self.k, depth, *section, samples);
            let words_len = 8 * section.words();
            let mut at = 0u64;
            while at < words_len {
                let n = (words_len - at).min(WINDOW_BYTES as u64) as usize;
                window(section.offset + at, n, &mut |bytes| scan.words(bytes))?;
                at += n as u64;
            }
            scan.finish()?;
        }
        Ok(())
    }
}

/// The running check of one section's words.
struct SectionScan<'a> {
    file: &'a str,
    k: usize,
    depth: usize,
    section: Section,
    samples: Vec<u64>,
    hasher: crc32fast::Hasher,
    word: u64,
    full: u64,
    partial: u64,
}

impl<'a> SectionScan<'a> {
    fn new(file: &'a str, k: usize, depth: usize, section: Section, samples: Vec<u64>) -> Self {
        Self {
            file,
            k,
            depth,
            section,
            samples,
            hasher: crc32fast::Hasher::new(),
            word: 0,
            full: 0,
            partial: 0,
        }
    }

    fn fail(&self, offset: u64, message: String) -> KtreeFileError {
        KtreeFileError::at_byte(
            self.file.to_string(),
            offset,
            KtreeFileErrorKind::Tree(message),
        )
    }

    /// Scans the next words of the section (a multiple of 8 bytes).
    fn words(&mut self, bytes: &[u8]) -> Result<(), KtreeFileError> {
        self.hasher.update(bytes);
        let group_bits = 2u32 << self.k;
        let group_mask = if group_bits == 64 {
            u64::MAX
        } else {
            (1u64 << group_bits) - 1
        };
        let nodes = self.section.nodes;
        for chunk in bytes.chunks_exact(8) {
            let word = u64::from_le_bytes(chunk.try_into().expect("8 bytes"));
            let at = self.section.offset + 8 * self.word;
            let first = self.word * NODES_PER_WORD;
            let here = (nodes - first).min(NODES_PER_WORD);
            if self.word.is_multiple_of(WORDS_PER_SAMPLE) {
                let sample = self.samples[(self.word / WORDS_PER_SAMPLE) as usize];
                if sample != self.partial {
                    return Err(self.fail(
                        self.section.samples_offset() + self.word / WORDS_PER_SAMPLE * 8,
                        format!(
                            "rank sample of level {} is {sample}, the nodes give {}",
                            self.depth, self.partial
                        ),
                    ));
                }
            }
            if (word >> 1) & word & LOW_BITS != 0 {
                return Err(self.fail(
                    at,
                    format!("a node of level {} has the unused code 11", self.depth),
                ));
            }
            if word & !slots_mask(here) != 0 {
                return Err(self.fail(
                    at,
                    format!(
                        "padding bits after the last node of level {} are not 0",
                        self.depth
                    ),
                ));
            }
            if self.depth > 0 {
                // Levels below the root hold whole groups of 2^K siblings, aligned in the word.
                let full_group = LOW_BITS & group_mask;
                for g in 0..(here >> self.k) as u32 {
                    let group = word >> (g * group_bits) & group_mask;
                    if group == 0 || group == full_group {
                        let node = first + u64::from(g << self.k);
                        return Err(self.fail(
                            at,
                            format!(
                                "not reduced: the {} siblings from node {node} of level {} are all {}",
                                1u32 << self.k,
                                self.depth,
                                if group == 0 { "empty" } else { "full" }
                            ),
                        ));
                    }
                }
            }
            self.full += u64::from(full_mask(word).count_ones());
            self.partial += u64::from(partial_mask(word).count_ones());
            self.word += 1;
        }
        Ok(())
    }

    fn finish(mut self) -> Result<(), KtreeFileError> {
        for s in &self.samples {
            self.hasher.update(&s.to_le_bytes());
        }
        let computed = std::mem::take(&mut self.hasher).finalize();
        if computed != self.section.crc {
            return Err(KtreeFileError::at_byte(
                self.file.to_string(),
                self.section.offset,
                KtreeFileErrorKind::SectionChecksum {
                    level: self.depth,
                    stored: self.section.crc,
                    computed,
                },
            ));
        }
        if (self.full, self.partial) != (self.section.full, self.section.partial) {
            return Err(self.fail(
                self.section.offset,
                format!(
                    "level {}: the directory records {} full and {} partial nodes, the section holds {} and {}",
                    self.depth, self.section.full, self.section.partial, self.full, self.partial
                ),
            ));
        }
        Ok(())
    }
}

pub(super) fn check_bytes(layout: &Layout, bytes: &[u8], file: &str) -> Result<(), KtreeFileError> {
    layout.check_sections(file, |offset, len, f| {
        f(&bytes[offset as usize..offset as usize + len])
    })
}

/// Reads a version 2 file's bytes into a tree in memory, with its frame and notes (called by
/// [`read_ktree_framed`](crate::io::read_ktree_framed)).
pub(crate) fn read_v2_framed(
    bytes: &[u8],
    file: &str,
) -> Result<(AnyTree, Option<WorldFrame>, Notes), KtreeFileError> {
    let layout = layout_of_bytes(bytes, file)?;
    check_bytes(&layout, bytes, file)?;
    let levels: Vec<PackedStates> = layout
        .sections
        .iter()
        .map(|s| {
            let start = s.offset as usize;
            let words = bytes[start..start + 8 * s.words() as usize]
                .chunks_exact(8)
                .map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes")))
                .collect();
            PackedStates::from_words(words, s.nodes as usize).expect("sections checked above")
        })
        .collect();
    fn assemble<const K: usize>(level: u32, levels: Vec<PackedStates>) -> KTree<K> {
        KTree::from_levels(Universe::new(level).expect("level checked"), levels)
    }
    let tree = match layout.k {
        1 => AnyTree::K1(assemble::<1>(layout.level, levels)),
        2 => AnyTree::K2(assemble::<2>(layout.level, levels)),
        3 => AnyTree::K3(assemble::<3>(layout.level, levels)),
        _ => AnyTree::K4(assemble::<4>(layout.level, levels)),
    };
    let check = crate::with_dim!(&tree, AnyTree, t => t.check());
    check.map_err(|e| {
        KtreeFileError::at_byte(
            file.to_string(),
            HEADER_BYTES as u64,
            KtreeFileErrorKind::Tree(e.to_string()),
        )
    })?;
    Ok((tree, layout.frame, layout.notes))
}
