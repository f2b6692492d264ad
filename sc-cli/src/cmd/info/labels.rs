//! `info` on a label volume (a segmentation or an atlas): its labels and their sample counts,
//! named from a label table when there is one, instead of a histogram and iso values.
//!
//! A volume is taken for a label volume when its samples are integers stored without rescaling,
//! none negative, at most [`MAX_LABELS`] distinct values, and either a label table is given
//! (`--label-table`), or a table found beside it names every non-zero value, or it is
//! piecewise constant: at least 3/4 of the pairs of face-neighbouring
//! samples that are both non-zero hold the same value. On the project's real data, scans fail
//! that test by far (2 to 27 % of such pairs are equal in the MRIs, 59 % in a CT stored in 33
//! levels) and label volumes pass it (89 % for ITK's noisy k-means classes, 95 % for AAL, 98 %
//! for JHU's tracts); the limit sits between. Floating-point segmentations are not recognised.

use std::collections::HashMap;
use std::fmt::Write as _;

use sc_io::labels::LabelTable;
use sc_io::volume::{Grid, Samples};

use crate::summary::thousands;

/// The most distinct values a label volume may hold: FreeSurfer's table, the largest in use,
/// names 1,266 labels; sixty-five thousand leaves room for any atlas and bounds the counting.
pub const MAX_LABELS: usize = 65_536;

/// The fraction of equal neighbouring labelled samples from which an untabled volume is taken
/// for labels.
const PIECEWISE_CONSTANT: f64 = 0.75;

/// The samples per label of a label volume, in increasing order of label (the background, 0,
/// included when present), and why it is taken for one.
#[derive(Debug, PartialEq)]
pub struct Census {
    pub counts: Vec<(u64, u64)>,
    pub why: Why,
}

/// Why a volume is taken for a label volume.
#[derive(Debug, PartialEq)]
pub enum Why {
    /// A label table was given.
    Given,
    /// The table found beside it names every non-zero value.
    Named,
    /// Of the face-neighbouring pairs of non-zero samples, this many hold the same value, of
    /// this many.
    PiecewiseConstant(u64, u64),
}

/// The census of `grid` if it is a label volume by the rule of the module's documentation,
/// with `table` given (`given`) or found beside it.
pub fn census(grid: &Grid, table: Option<&LabelTable>, given: bool) -> Option<Census> {
    if !grid.scale.is_identity() {
        return None;
    }
    let dims = grid.dims;
    match &grid.samples {
        Samples::U8(v) => of(v, dims, table, given),
        Samples::I8(v) => of(v, dims, table, given),
        Samples::U16(v) => of(v, dims, table, given),
        Samples::I16(v) => of(v, dims, table, given),
        Samples::U32(v) => of(v, dims, table, given),
        Samples::I32(v) => of(v, dims, table, given),
        Samples::F32(_) | Samples::F64(_) => None,
    }
}

/// Why the volume with these counts is a label volume without looking at its samples again, if
/// the table tells.
fn judge(counts: &[(u64, u64)], table: Option<&LabelTable>, given: bool) -> Option<Why> {
    let table = table?;
    if given {
        return Some(Why::Given);
    }
    let named = |id: u64| table.get(id).is_some_and(|l| !l.name.is_empty());
    counts
        .iter()
        .all(|&(id, _)| id == 0 || named(id))
        .then_some(Why::Named)
}

fn of<T: Copy + Into<i64> + PartialEq>(
    v: &[T],
    dims: [usize; 3],
    table: Option<&LabelTable>,
    given: bool,
) -> Option<Census> {
    let counts = counts(v)?;
    let why = match judge(&counts, table, given) {
        Some(why) => why,
        None => {
            let (equal, pairs) = equal_pairs(v, dims);
            if pairs == 0 || (equal as f64) < PIECEWISE_CONSTANT * pairs as f64 {
                return None;
            }
            Why::PiecewiseConstant(equal, pairs)
        }
    };
    Some(Census { counts, why })
}

/// Samples per value, or `None` for a negative value or more than [`MAX_LABELS`] values. Values
/// below 65,536 are counted in an array, larger ones (rare: u32 and i32 volumes) in a map.
fn counts<T: Copy + Into<i64>>(v: &[T]) -> Option<Vec<(u64, u64)>> {
    let mut small = vec![0u64; 1 << 16];
    let mut large: HashMap<u64, u64> = HashMap::new();
    for &x in v {
        let x: i64 = x.into();
        if x < 0 {
            return None;
        }
        if let Some(c) = small.get_mut(x as usize) {
            *c += 1;
        } else {
            *large.entry(x as u64).or_default() += 1;
            if large.len() > MAX_LABELS {
                return None;
            }
        }
    }
    let mut counts: Vec<(u64, u64)> = (0u64..)
        .zip(small)
        .filter(|&(_, c)| c > 0)
        .chain(large)
        .collect();
    if counts.len() > MAX_LABELS {
        return None;
    }
    counts.sort_unstable();
    Some(counts)
}

/// Of the pairs of samples that are neighbours along x, y or z and both non-zero: how many are
/// equal, and how many there are.
fn equal_pairs<T: Copy + Into<i64> + PartialEq>(v: &[T], [nx, ny, nz]: [usize; 3]) -> (u64, u64) {
    let (mut equal, mut pairs) = (0u64, 0u64);
    let mut pair = |a: T, b: T| {
        if a.into() != 0 && b.into() != 0 {
            pairs += 1;
            equal += u64::from(a == b);
        }
    };
    let slice = nx * ny;
    for z in 0..nz {
        for y in 0..ny {
            let at = z * slice + y * nx;
            let row = &v[at..at + nx];
            for w in row.windows(2) {
                pair(w[0], w[1]);
            }
            if y + 1 < ny {
                for (&a, &b) in row.iter().zip(&v[at + nx..at + 2 * nx]) {
                    pair(a, b);
                }
            }
            if z + 1 < nz {
                for (&a, &b) in row.iter().zip(&v[at + slice..at + slice + nx]) {
                    pair(a, b);
                }
            }
        }
    }
    (equal, pairs)
}

/// The width of the listing, in characters.
const WIDTH: usize = 100;
/// Names longer than this are cut (with `…`) in the listing.
const NAME_WIDTH: usize = 28;

/// The labels part of the report: the count, the table, then every label but the background
/// with its samples (and name), in as many columns as fit, sorted down the columns.
pub fn describe(out: &mut String, census: &Census, table: Option<&LabelTable>, sources: &str) {
    let background = census
        .counts
        .iter()
        .find(|&&(id, _)| id == 0)
        .map_or(0, |c| c.1);
    let labels: Vec<(u64, u64)> = census
        .counts
        .iter()
        .copied()
        .filter(|&(id, _)| id != 0)
        .collect();
    let _ = writeln!(
        out,
        "  labels    {} (and background 0: {} samples)",
        thousands(labels.len() as u64),
        thousands(background)
    );
    let unnamed = labels
        .iter()
        .filter(|&&(id, _)| {
            table
                .and_then(|t| t.get(id))
                .is_none_or(|l| l.name.is_empty())
        })
        .count();
    let table_line = match table {
        Some(_) if unnamed == 0 => sources.to_string(),
        Some(_) => format!(
            "{sources} ({} of the {} labels not named in it)",
            thousands(unnamed as u64),
            thousands(labels.len() as u64)
        ),
        None => "none (give one with --label-table)".into(),
    };
    let _ = writeln!(out, "  table     {table_line}");
    if let Why::PiecewiseConstant(equal, pairs) = census.why {
        let _ = writeln!(
            out,
            "  why       {:.0} % of neighbouring non-zero samples are equal: taken for labels",
            100.0 * equal as f64 / pairs as f64
        );
    }
    if labels.is_empty() {
        return;
    }
    let name = |id: u64| -> String {
        let name = table
            .and_then(|t| t.get(id))
            .map_or("", |l| l.name.as_str());
        if name.chars().count() > NAME_WIDTH {
            let cut: String = name.chars().take(NAME_WIDTH - 1).collect();
            format!("{cut}…")
        } else if name.is_empty() && table.is_some() {
            "?".into()
        } else {
            name.into()
        }
    };
    let cells: Vec<(String, String, String)> = labels
        .iter()
        .map(|&(id, count)| (id.to_string(), name(id), thousands(count)))
        .collect();
    let wid = cells.iter().map(|c| c.0.len()).max().unwrap_or(0);
    let wname = cells.iter().map(|c| c.1.chars().count()).max().unwrap_or(0);
    let wcount = cells.iter().map(|c| c.2.len()).max().unwrap_or(0);
    let cell = wid + wcount + 1 + if wname > 0 { wname + 1 } else { 0 };
    let gap = 4;
    let columns = ((WIDTH - 4 + gap) / (cell + gap)).max(1);
    let rows = cells.len().div_ceil(columns);
    let _ = writeln!(
        out,
        "  samples per label{}",
        if table.is_some() {
            " (id name samples)"
        } else {
            " (id samples)"
        }
    );
    for r in 0..rows {
        let mut line = String::from("    ");
        for c in 0..columns {
            let Some((id, name, count)) = cells.get(c * rows + r) else {
                break;
            };
            if c > 0 {
                line.push_str(&" ".repeat(gap));
            }
            let _ = write!(line, "{id:>wid$} ");
            if wname > 0 {
                let pad = wname - name.chars().count();
                let _ = write!(line, "{name}{} ", " ".repeat(pad));
            }
            let _ = write!(line, "{count:>wcount$}");
        }
        let _ = writeln!(out, "{}", line.trim_end());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(samples: Samples, dims: [usize; 3]) -> Grid {
        Grid::new(samples, dims, "test")
    }

    /// Blocks of constant labels are a label volume; the same values shuffled (a scan's noise)
    /// are not, unless a table says so; floats, negatives and rescaled samples never are.
    #[test]
    fn the_rule() {
        let dims = [8, 8, 8];
        let blocks: Vec<u16> = (0..512)
            .map(|i| {
                let (x, y, z) = (i % 8, i / 8 % 8, i / 64);
                (x / 4 + 2 * (y / 4) + 4 * (z / 4)) as u16
            })
            .collect();
        let c = census(
            &grid(Samples::U16(blocks.clone().into()), dims),
            None,
            false,
        )
        .unwrap();
        assert_eq!(c.counts, (0..8).map(|l| (l, 64)).collect::<Vec<_>>());
        // Labels 1 to 7 fill 7 of 8 blocks: within a block every pair is equal; between blocks
        // none is. Pairs within blocks: 3 axes × 4 × 4 × 3 per block × 7 blocks.
        let Why::PiecewiseConstant(equal, pairs) = c.why else {
            panic!("{:?}", c.why)
        };
        assert_eq!(equal, 3 * 48 * 7);
        assert!(pairs > equal && equal as f64 >= 0.75 * pairs as f64);
        // Shuffled by a fixed permutation: the same counts, no longer piecewise constant; unless
        // a table is given, or one found names every label but 0.
        let shuffled = grid(
            Samples::U16((0..512).map(|i| blocks[(i * 337) % 512]).collect()),
            dims,
        );
        assert!(census(&shuffled, None, false).is_none());
        let named = |ids: std::ops::Range<u64>| -> LabelTable {
            ids.map(|id| {
                (
                    id,
                    sc_io::labels::Label {
                        name: format!("l{id}"),
                        rgb: None,
                    },
                )
            })
            .collect()
        };
        let all = named(1..8);
        let some = named(1..7);
        assert_eq!(
            census(&shuffled, Some(&all), false).unwrap().why,
            Why::Named
        );
        assert!(census(&shuffled, Some(&some), false).is_none());
        assert_eq!(
            census(&shuffled, Some(&some), true).unwrap().why,
            Why::Given
        );
        // A palette names nothing.
        let palette: LabelTable = (0..256)
            .map(|id| {
                (
                    id,
                    sc_io::labels::Label {
                        name: String::new(),
                        rgb: Some([0; 3]),
                    },
                )
            })
            .collect();
        assert!(census(&shuffled, Some(&palette), false).is_none());
        let floats = grid(
            Samples::F32(blocks.iter().map(|&v| f32::from(v)).collect()),
            dims,
        );
        assert!(census(&floats, Some(&all), true).is_none());
        let negative = grid(
            Samples::I16(blocks.iter().map(|&v| v as i16 - 1).collect()),
            dims,
        );
        assert!(census(&negative, Some(&all), true).is_none());
        let mut rescaled = grid(Samples::U16(blocks.into()), dims);
        rescaled.rescale(2.0, 0.0);
        assert!(census(&rescaled, Some(&all), true).is_none());
    }

    /// Large values are counted beside small ones, and one value too many is refused.
    #[test]
    fn counts_of_large_values_and_the_limit() {
        let v: Vec<u32> = vec![7, 70_000, 7, u32::MAX, 70_000, 70_000];
        assert_eq!(
            counts(&v),
            Some(vec![(7, 2), (70_000, 3), (u64::from(u32::MAX), 1)])
        );
        let many: Vec<u32> = (0..=MAX_LABELS as u32).map(|i| i * 3).collect();
        assert_eq!(counts(&many), None);
        assert_eq!(counts(&many[1..]).map(|c| c.len()), Some(MAX_LABELS));
    }

    /// Hundreds of labels fit in columns no wider than the listing, each label once.
    #[test]
    fn listing_is_compact() {
        let counts: Vec<(u64, u64)> = (0..=300).map(|id| (id, 1000 + id)).collect();
        let table: LabelTable = (1..=300)
            .map(|id| {
                (
                    id,
                    sc_io::labels::Label {
                        name: format!("region-number-{id}-with-a-long-name"),
                        rgb: None,
                    },
                )
            })
            .collect();
        let mut out = String::new();
        let census = Census {
            counts,
            why: Why::Named,
        };
        describe(&mut out, &census, Some(&table), "t.txt");
        let lines: Vec<&str> = out.lines().collect();
        assert_eq!(
            lines[0],
            "  labels    300 (and background 0: 1,000 samples)"
        );
        assert!(lines.iter().all(|l| l.chars().count() <= WIDTH), "{out}");
        assert!(lines.len() < 160, "{} lines", lines.len());
        for id in 1..=300 {
            let name: String = format!("region-number-{id}-with-a-long-name")
                .chars()
                .take(27)
                .collect();
            let cell = format!("{id:>3} {name}… {}", thousands(1000 + id));
            assert_eq!(out.matches(&cell).count(), 1, "{cell}\n{out}");
        }
    }
}
