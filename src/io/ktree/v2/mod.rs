//! The `.ktree` file, version 2: one word-aligned, checksummed section per tree level, written as a stream
//! ([`KtreeWriter`]) and read by memory-mapping ([`KtreeView`], [`MappedTree`]). The byte layout and the checks
//! are described in the `layout` module's docs (and the README).

mod check;
pub(crate) mod layout;
mod mapped;
mod view;
mod writer;

pub(crate) use check::read_v2_framed;
pub use layout::VERSION;
pub use mapped::{AnyMappedTree, MappedTree};
pub(crate) use view::read_at;
pub use view::KtreeView;
pub(crate) use writer::write_levels;
pub use writer::KtreeWriter;

#[cfg(test)]
mod tests {
    use super::layout::*;
    use super::*;
    use crate::io::KtreeFileErrorKind;
    use crate::rays::ball_rays;
    use crate::stacking::paper::stack;
    use crate::tree::{KTree, NodeState, PackedStates};

    fn sample() -> (KTree<3>, Vec<u8>) {
        let tree = stack(&ball_rays::<3>(4, [10, 12, 14], 9).unwrap());
        let mut bytes = Vec::new();
        write_levels(&mut bytes, &tree, None, &crate::io::Notes::new()).unwrap();
        (tree, bytes)
    }

    #[test]
    fn round_trip_view_and_pieces_agree() {
        let (tree, bytes) = sample();
        assert_eq!(bytes.len() % 8, 0);
        let back = read_v2_framed(&bytes, "s")
            .unwrap()
            .0
            .into_dim::<3>()
            .unwrap();
        assert_eq!(back, tree);
        let view = KtreeView::from_bytes(bytes.clone(), "s").unwrap();
        assert_eq!(view.counts_per_level(), tree.counts_per_level());
        assert_eq!(view.to_tree::<3>().unwrap(), tree);
        for x in (0..16).step_by(3) {
            for y in 0..16 {
                for z in (0..16).step_by(2) {
                    assert_eq!(view.contains([x, y, z]).unwrap(), tree.contains([x, y, z]));
                }
            }
        }
        let mut leaves = Vec::new();
        view.for_each_leaf::<3>(|c, s| leaves.push((c, s))).unwrap();
        assert_eq!(leaves, tree.leaves().collect::<Vec<_>>());
        // Each level in odd-sized pieces: the shifted appends give the same bytes.
        let mut pieces = Vec::new();
        let mut w = KtreeWriter::new(&mut pieces, 3, tree.level()).unwrap();
        for d in 0..tree.depth_count() {
            let level = tree.level_states(d);
            let mut i = 0;
            let mut size = 1;
            while i < level.len() {
                let n = size.min(level.len() - i);
                let mut piece = PackedStates::new();
                (i..i + n).for_each(|j| piece.push(level.get(j)));
                piece.finish();
                w.append_states(&piece).unwrap();
                i += n;
                size = size % 45 + 7;
            }
            w.end_level().unwrap();
        }
        w.finish().unwrap();
        assert_eq!(pieces, bytes);
    }

    fn framed(frame: Option<&crate::space::WorldFrame>, notes: &crate::io::Notes) -> Vec<u8> {
        let (tree, _) = sample();
        let mut bytes = Vec::new();
        write_levels(&mut bytes, &tree, frame, notes).unwrap();
        bytes
    }

    fn frame_and_notes() -> (crate::space::WorldFrame, crate::io::Notes) {
        let frame = crate::space::WorldFrame {
            voxel_size: 0.1,
            origin: [-1.5, 2.0, 0.25],
        };
        let notes = crate::io::Notes::from([
            ("label.3".to_string(), "liver".to_string()),
            ("source".to_string(), "ct.nii".to_string()),
        ]);
        (frame, notes)
    }

    #[test]
    fn frame_and_notes_read_back_from_bytes_and_through_a_map() {
        let (tree, plain) = sample();
        // Without frame or notes: the file of before, flags 0.
        assert_eq!(framed(None, &crate::io::Notes::new()), plain);
        assert_eq!(plain[11], 0);
        let (frame, notes) = frame_and_notes();
        for (f, n, flags) in [
            (Some(&frame), crate::io::Notes::new(), 1),
            (None, notes.clone(), 2),
            (Some(&frame), notes.clone(), 3),
        ] {
            let bytes = framed(f, &n);
            assert_eq!(bytes[11], flags);
            assert_eq!(bytes.len() % 8, 0);
            let (back, kept, kept_notes) = read_v2_framed(&bytes, "s").unwrap();
            assert_eq!(back.into_dim::<3>().unwrap(), tree);
            assert_eq!((kept, &kept_notes), (f.copied(), &n));
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("t.ktree");
            std::fs::write(&path, &bytes).unwrap();
            let view = KtreeView::open(&path).unwrap();
            assert_eq!(view.to_tree::<3>().unwrap(), tree);
            assert_eq!((view.frame(), view.notes()), (f.copied(), &n));
            assert_eq!(
                view.contains([10u32, 12, 14]),
                Ok(tree.contains([10, 12, 14]))
            );
        }
    }

    #[test]
    fn a_damaged_frame_or_notes_block_is_an_error_naming_its_byte() {
        let (frame, notes) = frame_and_notes();
        let bytes = framed(Some(&frame), &notes);
        let error_at = |bytes: &[u8]| {
            let e = read_v2_framed(bytes, "s").unwrap_err();
            let from_view = KtreeView::from_bytes(bytes.to_vec(), "s").unwrap_err();
            assert_eq!(e.offset(), from_view.offset());
            (e.offset(), e.to_string())
        };
        // An unknown flag.
        let mut b = bytes.clone();
        b[11] |= 4;
        assert_eq!(error_at(&b).0, Some(11));
        // A voxel size that is not a number.
        let mut b = bytes.clone();
        b[16..24].copy_from_slice(&f64::NAN.to_le_bytes());
        let (at, message) = error_at(&b);
        assert_eq!(at, Some(16));
        assert!(message.contains("voxel size"), "{message}");
        // An origin changed: the header's checksum.
        let mut b = bytes.clone();
        b[24] ^= 1;
        assert!(matches!(
            read_v2_framed(&b, "s").unwrap_err().kind,
            KtreeFileErrorKind::Checksum { .. }
        ));
        // The notes' length past the end of the file.
        let mut b = bytes.clone();
        let len = b.len() as u64;
        b[48..56].copy_from_slice(&len.to_le_bytes());
        let (at, message) = error_at(&b);
        assert_eq!(at, Some(48));
        assert!(message.contains("runs past"), "{message}");
        // Notes that are not name=text.
        let mut b = bytes.clone();
        let eq = 56 + b[56..].iter().position(|&c| c == b'=').unwrap();
        b[eq] = b'-';
        assert!(error_at(&b).1.contains("not name=text"));
        // Cut inside the frame.
        assert!(read_v2_framed(&bytes[..40], "s").is_err());
    }

    #[test]
    fn bad_section_checksum_names_level_and_offset() {
        let (tree, mut bytes) = sample();
        let view = KtreeView::from_bytes(bytes.clone(), "s").unwrap();
        let last = view.depth_count() - 1;
        let offset = view.layout.sections[last].offset;
        // Swap two different 2-bit codes inside the last section: counts stay equal, the CRC does not.
        let at = offset as usize;
        let word = u64_at(&bytes, at);
        let swapped = (0..32)
            .flat_map(|i| (0..32).map(move |j| (i, j)))
            .find_map(|(i, j)| {
                let (a, b) = (word >> (2 * i) & 3, word >> (2 * j) & 3);
                (a != b).then(|| word ^ (a ^ b) << (2 * i) ^ (a ^ b) << (2 * j))
            })
            .unwrap();
        bytes[at..at + 8].copy_from_slice(&swapped.to_le_bytes());
        let e = read_v2_framed(&bytes, "s").unwrap_err();
        assert_eq!(e.offset(), Some(offset));
        assert!(
            matches!(e.kind, KtreeFileErrorKind::SectionChecksum { level, .. } if level == last),
            "{e}"
        );
        assert!(e.to_string().contains(&format!("level {last}")), "{e}");
        let _ = tree;
    }

    #[test]
    fn a_file_changed_underneath_a_view_gives_errors_not_panics() {
        use std::io::{Seek, SeekFrom, Write as _};
        let (tree, bytes) = sample();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.ktree");
        std::fs::write(&path, &bytes).unwrap();
        let view = KtreeView::open(&path).unwrap();
        assert!(view.is_mapped());
        assert_eq!(view.to_tree::<3>().unwrap(), tree);
        // Overwrite every section in place with code 11: the map shows the new bytes.
        let directory_at = view
            .layout
            .sections
            .last()
            .map(|s| s.offset + s.bytes())
            .unwrap();
        let mut f = std::fs::OpenOptions::new().write(true).open(&path).unwrap();
        f.seek(SeekFrom::Start(HEADER_BYTES as u64)).unwrap();
        f.write_all(&vec![0xFF; directory_at as usize - HEADER_BYTES])
            .unwrap();
        f.sync_all().unwrap();
        assert!(view.contains([10u32, 12, 14]).is_err());
        assert!(view.for_each_leaf::<3>(|_, _| {}).is_err());
        assert!(view.to_tree::<3>().is_err());
        assert!(KtreeView::open(&path).is_err(), "reopening checks again");
    }

    #[test]
    fn writer_rejects_a_broken_shape() {
        let mut w = KtreeWriter::new(Vec::new(), 2, 2).unwrap();
        w.push(NodeState::Partial).unwrap();
        w.end_level().unwrap();
        w.append_words(&[0b10], 3).unwrap();
        assert!(w.end_level().is_err(), "3 children of one partial node");
        let mut w = KtreeWriter::new(Vec::new(), 2, 2).unwrap();
        w.push(NodeState::Partial).unwrap();
        assert!(w.finish().is_err(), "a partial leaf");
        assert!(KtreeWriter::new(Vec::new(), 2, 2)
            .unwrap()
            .append_words(&[0b11], 1)
            .is_err());
    }
}
