//! `skelclimb info`.

mod labels;

use std::fmt::Write as _;

use crate::cli::InfoArgs;
use crate::histogram::Histogram;
use crate::progress::Bar;
use crate::summary::thousands;
use sc_io::Result;
use sc_io::labels::LabelTable;
use sc_io::read;
use sc_io::read::dicom::{self, SeriesInfo};
use sc_io::volume::{Dtype, Grid, Range};

/// Bins behind the suggestions: fine enough to separate tissues, coarse enough to smooth noise.
const SUGGESTION_BINS: usize = 128;

/// Prints what is known about the volume and which iso values to try, or, for a label volume,
/// its labels (see [`labels`] for how one is told).
pub fn run(args: &InfoArgs, quiet: bool) -> Result<()> {
    let options = args.read.read_options();
    if args.input.is_dir() && options.dicom.series.is_none() {
        let series = dicom::list_series(&args.input)?;
        if series.len() > 1 {
            print!("{}", list(&args.input.display().to_string(), &series));
            return Ok(());
        }
    }
    let progress = Bar::new(!quiet);
    let mut grid = read::read(&args.input, &options, &progress)?;
    args.placement.apply(&mut grid);
    progress.finish();
    let name = args.input.display().to_string();
    let table = Table::of(args)?;
    let given = args.label_table.is_some();
    let report = match labels::census(&grid, table.labels.as_ref(), given) {
        Some(census) => {
            let mut out = header(&name, &grid);
            labels::describe(&mut out, &census, table.labels.as_ref(), &table.sources);
            for problem in &table.problems {
                let _ = writeln!(out, "  warning   {problem}");
            }
            footer(&mut out, &grid);
            out
        }
        None => {
            let mut out = describe(&name, &grid, usize::from(args.bins));
            if let Some(given) = &args.label_table {
                let _ = writeln!(
                    out,
                    "  warning   --label-table {} unused: not a label volume (labels are whole numbers from 0, stored without rescaling, at most {} of them)",
                    given.display(),
                    thousands(labels::MAX_LABELS as u64)
                );
            }
            out
        }
    };
    print!("{report}");
    Ok(())
}

/// The label table for `info`: the one given, else those beside the volume that read (a table
/// beside it that does not is reported, not fatal: it may be any `.txt`).
struct Table {
    labels: Option<LabelTable>,
    /// Where the names and colours come from, for the report.
    sources: String,
    problems: Vec<String>,
}

impl Table {
    fn of(args: &InfoArgs) -> Result<Table> {
        if let Some(path) = &args.label_table {
            return Ok(Table {
                labels: Some(LabelTable::read(path)?),
                sources: path.display().to_string(),
                problems: Vec::new(),
            });
        }
        let beside = LabelTable::beside(&args.input);
        let names: Vec<_> = beside
            .sources
            .iter()
            .map(|p| p.file_name().unwrap_or_default().to_string_lossy())
            .collect();
        Ok(Table {
            labels: beside.table,
            sources: names.join(", "),
            problems: beside
                .unread
                .iter()
                .map(|e| format!("not read as a label table: {e}"))
                .collect(),
        })
    }
}

/// The series of a DICOM directory that holds several, as text.
pub fn list(name: &str, series: &[SeriesInfo]) -> String {
    let mut out = format!(
        "{name}\n  format    DICOM directory with {} series (choose one with --series N or UID)\n",
        series.len()
    );
    for (i, s) in series.iter().enumerate() {
        let _ = writeln!(
            out,
            "  {:>2}. {} × {} × {} slices  {}  {}",
            i + 1,
            s.size[0],
            s.size[1],
            s.slices,
            s.uid,
            s.description
        );
    }
    out
}

/// The report, as text.
pub fn describe(name: &str, grid: &Grid, bins: usize) -> String {
    let mut out = header(name, grid);
    let range = grid.range();
    let shown = Histogram::of(grid, &range, bins);
    let fine = Histogram::of(grid, &range, SUGGESTION_BINS);
    if range.finite == 0 {
        let _ = writeln!(
            out,
            "  values    none finite ({} NaN)",
            thousands(range.nan as u64)
        );
    } else {
        let _ = writeln!(
            out,
            "  values    {} to {}, mean {}",
            short(range.min),
            short(range.max),
            short(shown.mean)
        );
        if range.nan > 0 {
            let _ = writeln!(
                out,
                "  NaN       {} samples (outside every surface)",
                thousands(range.nan as u64)
            );
        }
        let _ = writeln!(out, "  histogram (bar length ∝ log count)");
        let widest = shown.counts.iter().map(|&c| ln1p(c)).fold(0.0, f64::max);
        for (i, &c) in shown.counts.iter().enumerate() {
            let bar = if widest > 0.0 {
                (40.0 * ln1p(c) / widest).round() as usize
            } else {
                0
            };
            let _ = writeln!(
                out,
                "    {:>10} … {:<10} {:<40} {}",
                short(shown.edge(i)),
                short(shown.edge(i + 1)),
                "█".repeat(bar),
                thousands(c)
            );
        }
        // Integer samples never equal a value halfway between integers, which keeps vertices off
        // grid points (SPEC §1).
        let integer =
            grid.scale.is_identity() && !matches!(grid.samples.dtype(), Dtype::F32 | Dtype::F64);
        let snap = |x: f64| if integer { x.floor() + 0.5 } else { x };
        let _ = writeln!(
            out,
            "  suggested iso values{}",
            if integer {
                " (halfway between integers)"
            } else {
                ""
            }
        );
        if let Some(t) = fine.otsu() {
            let _ = writeln!(
                out,
                "    {:<10} Otsu threshold: best split into two classes of values",
                short(snap(t))
            );
        }
        for (v, l, r) in fine.valleys(3) {
            let _ = writeln!(
                out,
                "    {:<10} histogram valley between peaks near {} and {}",
                short(snap(v)),
                short(l),
                short(r)
            );
        }
        if is_hounsfield(&range) {
            for (level, what) in CT_LEVELS {
                let _ = writeln!(out, "    {:<10} {what}", short(snap(level)));
            }
        }
    }
    footer(&mut out, grid);
    out
}

/// The first lines of every report: the file, its format, size, sample type and placement.
fn header(name: &str, grid: &Grid) -> String {
    let mut out = String::new();
    let [nx, ny, nz] = grid.dims;
    let [sx, sy, sz] = grid.spacing;
    let [ox, oy, oz] = grid.origin;
    // `fmt::Write` for `String` cannot fail.
    let _ = writeln!(out, "{name}");
    let _ = writeln!(out, "  format    {}", grid.format);
    let _ = writeln!(
        out,
        "  dims      {nx} × {ny} × {nz} ({} samples)",
        thousands(grid.len() as u64)
    );
    let _ = writeln!(out, "  dtype     {}", grid.samples.dtype().name());
    if !grid.scale.is_identity() {
        let _ = writeln!(
            out,
            "  rescale   value = {} × stored + {}",
            grid.scale.slope, grid.scale.inter
        );
    }
    let _ = writeln!(
        out,
        "  spacing   {} × {} × {}",
        short(sx),
        short(sy),
        short(sz)
    );
    let _ = writeln!(
        out,
        "  origin    {}, {}, {}",
        short(ox),
        short(oy),
        short(oz)
    );
    if let Some(frame) = grid.frame {
        let d = frame.direction;
        let axis = |a: usize| {
            format!(
                "({}, {}, {})",
                short(d[0][a]),
                short(d[1][a]),
                short(d[2][a])
            )
        };
        let _ = writeln!(
            out,
            "  axes      x → {}, y → {}, z → {} ({} world)",
            axis(0),
            axis(1),
            axis(2),
            frame.space.name()
        );
    }
    out
}

/// The last lines of every report: what the reader noted and warned of.
fn footer(out: &mut String, grid: &Grid) {
    for note in &grid.notes {
        let _ = writeln!(out, "  note      {note}");
    }
    for warning in &grid.warnings {
        let _ = writeln!(out, "  warning   {warning}");
    }
}

/// The usual CT surface levels, in Hounsfield units.
const CT_LEVELS: [(f64, &str); 2] = [
    (
        -500.0,
        "skin: air against soft tissue (CT, Hounsfield units)",
    ),
    (350.0, "bone: usual level 300 to 400 (CT, Hounsfield units)"),
];

/// Whether the values look like CT in Hounsfield units: air near −1000 (or the −1024 to −3024
/// padding scanners write outside the field of view) and values up to bone. No other modality
/// stores large negative values, so the range alone tells.
fn is_hounsfield(range: &Range) -> bool {
    range.min <= -900.0 && range.min >= -3100.0 && range.max >= 300.0
}

/// A value for reading: at most four decimals, no trailing zeros, no negative zero.
fn short(x: f64) -> String {
    if x.is_finite() && x.abs() >= 1e15 {
        return format!("{x:.4e}");
    }
    let text = format!("{:.4}", x + 0.0);
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        &text
    };
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

fn ln1p(c: u64) -> f64 {
    (c as f64).ln_1p()
}

#[cfg(test)]
mod tests {
    use sc_io::volume::Samples;

    use super::*;

    fn report(values: Vec<i16>) -> String {
        let n = values.len();
        describe(
            "t",
            &Grid::new(Samples::I16(values.into()), [n, 1, 1], "test"),
            16,
        )
    }

    #[test]
    fn ct_in_hounsfield_units_gets_the_tissue_levels() {
        let mut ct = vec![-1000i16; 3000];
        ct.extend(vec![40i16; 3000]);
        ct.extend(vec![900i16; 500]);
        let text = report(ct);
        let line = |start: &str| text.lines().any(|l| l.trim_start().starts_with(start));
        assert!(line("-499.5     skin"), "{text}");
        assert!(line("350.5      bone"), "{text}");
        // An MRI-like range (no large negative values) gets no CT levels.
        let text = report((0..600).map(|i| i % 300).collect());
        assert!(!text.contains("Hounsfield"), "{text}");
    }
}
