//! Notes a version 3 `.ktree` file may keep beside its tree: named texts (a history's number of steps,
//! say), kept in a block after the header and the world frame, covered by the header's checksum. A file
//! with no notes has no block (flag bit 1 clear), so it is byte for byte what a writer without notes
//! writes.
//!
//! The block: the text's length in bytes `N` (`u64`), then `N` bytes of UTF-8, one note a line
//! (`name=text\n`, in the order of the names), zero-padded to a multiple of 8 bytes.
//!
//! ```
//! use ktree::io::ktree::v3::{read_valued_ktree_noted, write_valued_ktree_noted};
//! use ktree::io::ktree::Notes;
//! use ktree::KTree;
//! let tree = KTree::<2, u8>::from_dense_values(1, &[Some(1), None, Some(2), Some(1)]).unwrap();
//! let notes = Notes::from([("steps".to_string(), "24".to_string())]);
//! let mut bytes = Vec::new();
//! write_valued_ktree_noted(&mut bytes, &tree, None, &notes).unwrap();
//! assert_eq!(read_valued_ktree_noted::<2, u8>(&bytes, "mem").unwrap(), (tree, None, notes));
//! ```

use std::collections::BTreeMap;

/// A file's notes: texts by name. A name is not empty and holds no `=` and no line break; a text holds no
/// line break.
pub type Notes = BTreeMap<String, String>;

/// The name of the note that names a value (a label's name: `label.3` = `liver`), the value as
/// [`Value::text`](crate::value::Value::text) writes it. `ktree voxelize --labels` writes them for meshes'
/// groups; `ktree stats` prints them.
///
/// ```
/// assert_eq!(ktree::io::ktree::notes::label_note("3"), "label.3");
/// ```
pub fn label_note(value: &str) -> String {
    format!("label.{value}")
}

/// Why a note cannot be kept, if it cannot.
fn check_note(name: &str, text: &str) -> Result<(), String> {
    if name.is_empty() || name.contains(['=', '\n', '\r']) {
        return Err(format!(
            "note name {name:?}: a name is not empty and holds no '=' and no line break"
        ));
    }
    if text.contains(['\n', '\r']) {
        return Err(format!("note {name:?}: a text holds no line break"));
    }
    Ok(())
}

/// The block of `notes` (length, text, padding); empty for no notes.
///
/// # Errors
/// A message naming a note that cannot be kept.
pub(crate) fn encode(notes: &Notes) -> Result<Vec<u8>, String> {
    if notes.is_empty() {
        return Ok(Vec::new());
    }
    let mut text = String::new();
    for (name, value) in notes {
        check_note(name, value)?;
        text.push_str(name);
        text.push('=');
        text.push_str(value);
        text.push('\n');
    }
    let mut block = Vec::with_capacity(8 + text.len() + 7);
    block.extend_from_slice(&(text.len() as u64).to_le_bytes());
    block.extend_from_slice(text.as_bytes());
    block.resize(block.len().div_ceil(8) * 8, 0);
    Ok(block)
}

/// The bytes of a block starting at `bytes[0]`, read from its length (`None` if the length does not fit
/// in `room` bytes).
pub(crate) fn block_bytes(bytes: &[u8], room: usize) -> Option<usize> {
    let length = u64::from_le_bytes(bytes.get(..8)?.try_into().ok()?);
    let padded = length.checked_add(8 + 7)? / 8 * 8;
    usize::try_from(padded).ok().filter(|&b| b <= room)
}

/// The notes of a block (its bytes as [`block_bytes`] measured them).
///
/// # Errors
/// The offset in the block and a message: text that is not UTF-8, a line that is not `name=text`, a
/// name given twice, padding that is not zero.
pub(crate) fn decode(block: &[u8]) -> Result<Notes, (usize, String)> {
    let length = u64::from_le_bytes(block[..8].try_into().expect("8 bytes")) as usize;
    let (text, padding) = block[8..].split_at(length);
    if let Some(i) = padding.iter().position(|&b| b != 0) {
        return Err((8 + length + i, "the notes' padding is not zero".into()));
    }
    let text = std::str::from_utf8(text)
        .map_err(|e| (8 + e.valid_up_to(), "the notes are not UTF-8 text".into()))?;
    let mut notes = Notes::new();
    let mut at = 8;
    for line in text.split_inclusive('\n') {
        let bad = |why: String| (at, why);
        let Some(line_text) = line.strip_suffix('\n') else {
            return Err(bad("the notes' last line has no line break".into()));
        };
        let Some((name, value)) = line_text.split_once('=') else {
            return Err(bad(format!("note {line_text:?} is not name=text")));
        };
        check_note(name, value).map_err(bad)?;
        if notes.insert(name.to_string(), value.to_string()).is_some() {
            return Err(bad(format!("note {name:?} is given twice")));
        }
        at += line.len();
    }
    Ok(notes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn notes_read_back_and_bad_blocks_say_where() {
        let notes = Notes::from([
            ("a".to_string(), "x = 1".to_string()),
            ("steps".to_string(), String::new()),
            ("ünï".to_string(), "cödé".to_string()),
        ]);
        let block = encode(&notes).unwrap();
        assert_eq!(block.len() % 8, 0);
        assert_eq!(block_bytes(&block, block.len()), Some(block.len()));
        assert_eq!(block_bytes(&block, block.len() - 1), None);
        assert_eq!(decode(&block).unwrap(), notes);
        assert!(encode(&Notes::new()).unwrap().is_empty());
        for (name, text) in [("", "x"), ("a=b", "x"), ("a\nb", "x"), ("a", "x\ny")] {
            let bad = Notes::from([(name.to_string(), text.to_string())]);
            assert!(encode(&bad).is_err(), "{name:?} {text:?}");
        }
        // A line without '=' (its offset named), text that is not UTF-8, a repeated name, a padding byte.
        let raw = |text: &[u8]| {
            let mut b = (text.len() as u64).to_le_bytes().to_vec();
            b.extend_from_slice(text);
            b.resize(b.len().div_ceil(8) * 8, 0);
            b
        };
        assert_eq!(decode(&raw(b"a=1\nbad\n")).unwrap_err().0, 12);
        assert!(decode(&raw(b"a=\xff\n")).unwrap_err().1.contains("UTF-8"));
        assert!(decode(&raw(b"a=1\na=2\n")).unwrap_err().1.contains("twice"));
        assert!(decode(&raw(b"a=1")).unwrap_err().1.contains("line break"));
        let mut padded = raw(b"a=1\n");
        *padded.last_mut().unwrap() = 1;
        assert!(decode(&padded).unwrap_err().1.contains("padding"));
    }
}
