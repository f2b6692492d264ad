//! Label tables: the names and colours of the regions of a label volume (a segmentation or an
//! atlas), read from the files the usual tools write beside it.
//!
//! [`LabelTable::read`] tells the format from the file itself:
//!
//! - ITK-SNAP label descriptions: `IDX R G B A VIS MSH "LABEL"` lines;
//! - FreeSurfer colour tables (`FreeSurferColorLUT.txt`): `id name R G B A` lines;
//! - MRIcron's names beside its atlases (`aal.nii.txt`): `id name` lines, tab- or
//!   space-separated, further fields ignored (AAL's carry a region code);
//! - MRIcron's palettes (`aal.nii.lut`): 768 bytes, 256 reds, then 256 greens, then 256 blues,
//!   indexed by label id. A palette names no label: its labels have empty names.
//!
//! MRIcron ships names and palette as two files; [`LabelTable::beside`] finds and
//! [`LabelTable::merge`]s them. [`file_stem`] names a label's mesh file, [`default_rgb`] colours
//! a label no table colours.

mod mesh;
mod parse;
mod shard;
mod stream;

pub use mesh::{LabelMeshes, LabelRequest, Selection, extract};
pub use shard::{LabelSettings, Stored, extract_shards, join_shards, merge_shards, write_block};
pub use stream::extract_stream;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// One region of a label volume.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Label {
    /// The region's name as the table gives it; empty where the table names none (a palette).
    pub name: String,
    /// Its colour (sRGB, 0 to 255), if the table gives one.
    pub rgb: Option<[u8; 3]>,
}

/// Labels by id.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LabelTable {
    labels: BTreeMap<u64, Label>,
}

/// The largest file read as a label table: FreeSurfer's full table, the largest in use, is
/// about 100 KB; anything far larger is not a table, and is refused before it is read whole.
const MAX_TABLE_BYTES: u64 = 16 << 20;

impl LabelTable {
    /// Reads a label table in any of the formats of the [module](self) documentation. An error
    /// names the file and, for text, the line.
    pub fn read(path: &Path) -> Result<LabelTable> {
        use std::io::Read;

        let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
        let mut bytes = Vec::new();
        file.take(MAX_TABLE_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(|e| Error::io(path, e))?;
        if bytes.len() as u64 > MAX_TABLE_BYTES {
            return Err(Error::file(
                path,
                format!(
                    "larger than {} MiB: not a label table",
                    MAX_TABLE_BYTES >> 20
                ),
            ));
        }
        parse::table(&bytes, is_palette_name(path))
            .map(|labels| LabelTable { labels })
            .map_err(|message| Error::file(path, message))
    }

    /// The tables found beside `volume` (see [`tables_beside`]), read and merged: the first
    /// read gives the names, later ones fill in colours. A table that cannot be read is kept
    /// in [`Beside::unread`] rather than failing: a file named like a table beside a volume may
    /// be anything, and the front end decides whether that matters.
    pub fn beside(volume: &Path) -> Beside {
        let mut found = Beside::default();
        for path in tables_beside(volume) {
            match LabelTable::read(&path) {
                Ok(table) => {
                    found.table = Some(match found.table.take() {
                        Some(names) => names.merge(table),
                        None => table,
                    });
                    found.sources.push(path);
                }
                Err(e) => found.unread.push(e),
            }
        }
        found
    }

    /// The label `id`, if the table has it.
    pub fn get(&self, id: u64) -> Option<&Label> {
        self.labels.get(&id)
    }

    /// The labels in increasing order of id.
    pub fn iter(&self) -> impl Iterator<Item = (u64, &Label)> {
        self.labels.iter().map(|(&id, label)| (id, label))
    }

    /// The number of labels.
    pub fn len(&self) -> usize {
        self.labels.len()
    }

    /// Whether the table has no label (never so for a table read from a file).
    pub fn is_empty(&self) -> bool {
        self.labels.is_empty()
    }

    /// This table completed by `other`: a label keeps its name and colour here, and takes
    /// `other`'s where it has none; labels only in `other` are added. MRIcron's names
    /// (`.nii.txt`) merged with its palette (`.nii.lut`) give named, coloured labels.
    #[must_use]
    pub fn merge(mut self, other: LabelTable) -> LabelTable {
        for (id, theirs) in other.labels {
            let ours = self.labels.entry(id).or_default();
            if ours.name.is_empty() {
                ours.name = theirs.name;
            }
            ours.rgb = ours.rgb.or(theirs.rgb);
        }
        self
    }
}

impl FromIterator<(u64, Label)> for LabelTable {
    fn from_iter<I: IntoIterator<Item = (u64, Label)>>(iter: I) -> Self {
        LabelTable {
            labels: iter.into_iter().collect(),
        }
    }
}

/// The label tables beside a volume, as [`LabelTable::beside`] finds them.
#[derive(Debug, Default)]
pub struct Beside {
    /// The tables read, merged; `None` if none was.
    pub table: Option<LabelTable>,
    /// The files read, in the order merged.
    pub sources: Vec<PathBuf>,
    /// Why each file that looked like a table could not be read.
    pub unread: Vec<Error>,
}

/// Whether `path` names a binary MRIcron palette.
fn is_palette_name(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("lut"))
}

/// The label tables that exist beside `volume`, names before palettes: for `aal.nii.gz`,
/// `aal.nii.txt` and `aal.nii.lut` (MRIcron's names), then `aal.txt` and `aal.lut`. For a
/// volume whose user gives no table.
pub fn tables_beside(volume: &Path) -> Vec<PathBuf> {
    let Some(name) = volume.file_name().and_then(|n| n.to_str()) else {
        return Vec::new();
    };
    // `aal.nii.gz` → `aal.nii` (MRIcron's stem) and `aal`.
    let uncompressed = name
        .strip_suffix(".gz")
        .or_else(|| name.strip_suffix(".GZ"))
        .unwrap_or(name);
    let bare = match uncompressed.rfind('.') {
        Some(dot) if dot > 0 => &uncompressed[..dot],
        _ => uncompressed,
    };
    let mut found = Vec::new();
    for stem in [uncompressed, bare] {
        for ext in ["txt", "lut"] {
            let path = volume.with_file_name(format!("{stem}.{ext}"));
            if path != volume && !found.contains(&path) && path.is_file() {
                found.push(path);
            }
        }
    }
    found
}

/// The colour of label `id` when no table gives one: hues a golden angle apart (distinct for
/// neighbouring ids, which are often neighbouring regions), saturated and light enough to tell
/// apart on a dark or a light background. A function of the id alone, so a label keeps its
/// colour from one file to the next whatever else is meshed.
pub fn default_rgb(id: u64) -> [u8; 3] {
    // The fraction of a turn: id × (golden ratio − 1), modulo 1, exact for any u64 id.
    const STEP: u64 = 0x9E37_79B9_7F4A_7C15; // 2^64 / golden ratio
    let hue = id.wrapping_mul(STEP) as f64 / 2f64.powi(64) * 6.0;
    let (s, v) = (0.6, 0.9);
    let f = hue.fract();
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    let (r, g, b) = match hue as u32 {
        0 => (v, t, p),
        1 => (q, v, p),
        2 => (p, v, t),
        3 => (p, q, v),
        4 => (t, p, v),
        _ => (v, p, q),
    };
    [r, g, b].map(|c| (c * 255.0).round() as u8)
}

/// The longest part of a file name taken from a label's name, in bytes: with the id, the
/// extension and the temporary name's additions, far below the usual 255-byte limit.
const MAX_NAME_BYTES: usize = 80;

/// A file name stem for label `id` named `name`: `<id>-<name>` with every character that is
/// not a letter, a digit, or one of `-_.+()` replaced by `_` (runs of them by one, none at the
/// ends), cut to 80 bytes; `label-<id>` when nothing of the name is left. No path separator,
/// control character or leading dot can appear, and since the id leads, the stems of distinct
/// labels differ, even on a file system that ignores case.
pub fn file_stem(id: u64, name: &str) -> String {
    let keep = |c: char| c.is_alphanumeric() || "-_.+()".contains(c);
    let mut clean = String::new();
    for c in name.chars() {
        let c = if keep(c) { c } else { '_' };
        if !(c == '_' && clean.ends_with('_')) {
            clean.push(c);
        }
    }
    let mut clean = clean.trim_matches(['_', '.']);
    if clean.len() > MAX_NAME_BYTES {
        let cut = (0..=MAX_NAME_BYTES)
            .rev()
            .find(|&i| clean.is_char_boundary(i))
            .unwrap_or(0);
        clean = clean[..cut].trim_end_matches(['_', '.']);
    }
    if clean.is_empty() {
        format!("label-{id}")
    } else {
        format!("{id}-{clean}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_stems_are_safe_and_distinct() {
        assert_eq!(file_stem(3, "Left-Thalamus"), "3-Left-Thalamus");
        assert_eq!(file_stem(7, "label one (l1)"), "7-label_one_(l1)");
        assert_eq!(file_stem(9, "../../etc/passwd"), "9-etc_passwd");
        assert_eq!(file_stem(9, "a\\b:c\u{7}d\ne"), "9-a_b_c_d_e");
        assert_eq!(file_stem(12, ""), "label-12");
        assert_eq!(file_stem(12, " / . "), "label-12");
        assert_eq!(file_stem(5, "Thalamus_gauche_é"), "5-Thalamus_gauche_é");
        let long = "é".repeat(100);
        let stem = file_stem(1, &long);
        assert_eq!(stem, format!("1-{}", "é".repeat(40)));
        // Distinct ids give distinct stems, whatever the names, even ignoring case: every pair of
        // ids below 200 with names chosen to collide once cleaned.
        let names = ["A", "a", "", "_", "1-a", "a/", "a b", "a_b"];
        let mut seen = std::collections::HashSet::new();
        for id in 0..200u64 {
            let stem = file_stem(id, names[id as usize % names.len()]).to_lowercase();
            assert!(
                stem.chars()
                    .all(|c| !c.is_control() && c != '/' && c != '\\')
            );
            assert!(seen.insert(stem));
        }
    }

    /// Default colours: the same for the same id; ids up to 4 apart differ by more than 50 in
    /// some channel; the first 256 are all different.
    #[test]
    fn default_colours_are_stable_and_distinct() {
        assert_eq!(default_rgb(17), default_rgb(17));
        let colours: Vec<[u8; 3]> = (0..1000).map(default_rgb).collect();
        for (i, a) in colours.iter().enumerate() {
            for b in &colours[i.saturating_sub(4)..i] {
                assert!(
                    a.iter().zip(b).any(|(x, y)| x.abs_diff(*y) > 50),
                    "{a:?} {b:?}"
                );
            }
        }
        let first: std::collections::HashSet<_> = colours[..256].iter().collect();
        assert_eq!(first.len(), 256);
        // Every component within the HSV bounds chosen: value 0.9, saturation 0.6.
        assert!(colours.iter().flatten().all(|&c| (91..=230).contains(&c)));
    }

    #[test]
    fn merge_keeps_names_and_fills_colours() {
        let names: LabelTable = [
            (
                1,
                Label {
                    name: "one".into(),
                    rgb: None,
                },
            ),
            (
                2,
                Label {
                    name: "two".into(),
                    rgb: Some([1, 2, 3]),
                },
            ),
        ]
        .into_iter()
        .collect();
        let palette: LabelTable = (0..4)
            .map(|id| {
                (
                    id,
                    Label {
                        name: String::new(),
                        rgb: Some([id as u8; 3]),
                    },
                )
            })
            .collect();
        let merged = names.merge(palette);
        assert_eq!(merged.len(), 4);
        assert_eq!(
            merged.get(1),
            Some(&Label {
                name: "one".into(),
                rgb: Some([1; 3])
            })
        );
        assert_eq!(
            merged.get(2),
            Some(&Label {
                name: "two".into(),
                rgb: Some([1, 2, 3])
            })
        );
        assert_eq!(
            merged.get(3),
            Some(&Label {
                name: String::new(),
                rgb: Some([3; 3])
            })
        );
        assert_eq!(merged.get(4), None);
    }

    #[test]
    fn tables_beside_a_volume() {
        let dir = tempfile::tempdir().unwrap();
        let volume = dir.path().join("aal.nii.gz");
        std::fs::write(&volume, b"").unwrap();
        assert!(tables_beside(&volume).is_empty());
        for name in ["aal.nii.lut", "aal.nii.txt", "aal.txt", "other.txt"] {
            std::fs::write(dir.path().join(name), b"").unwrap();
        }
        let found: Vec<_> = tables_beside(&volume)
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(found, ["aal.nii.txt", "aal.nii.lut", "aal.txt"]);
        // A volume whose own name ends in .txt is not its own table.
        let raw = dir.path().join("seg.txt");
        std::fs::write(&raw, b"").unwrap();
        assert!(tables_beside(&raw).is_empty());
    }
}
