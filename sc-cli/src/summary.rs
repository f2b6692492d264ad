//! The report printed after `extract`, as text and as JSON (`--stats-json`).

use std::fmt;
use std::time::Duration;

use sc_io::surface::Measures;
use sc_io::{report, separation};
use sc_runtime::{ErrorBound, ErrorUnits, Mode, Stats};
use serde_json::{Value, json};

use crate::check::EdgeReport;

/// The paper's Table 1 figures for the knotted torus: Marching Cubes, Steps 1–3, Steps 1–4.
pub const PAPER_KNOT: [u64; 3] = [13_968, 13_968, 10_464];

/// Everything the summary reports.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// The input as the user named it.
    pub input: String,
    /// Its format.
    pub format: &'static str,
    /// `[nx, ny, nz]` of the input.
    pub dims: [usize; 3],
    /// Whether `--pad` added a layer of empty samples on every side before meshing.
    pub padded: bool,
    /// The mesh's coordinate system, in words.
    pub coordinates: String,
    /// Sample type name.
    pub dtype: &'static str,
    /// Surface value.
    pub iso: f64,
    /// Which steps ran.
    pub mode: Mode,
    /// `--max-error`, if given.
    pub max_error: Option<ErrorBound>,
    /// Counts from the extractor.
    pub stats: Stats,
    /// Time spent reading (or generating) the volume.
    pub read: Duration,
    /// Time spent extracting.
    pub extract: Duration,
    /// Time spent writing the mesh.
    pub write: Duration,
    /// For the paper's knot: our triangle count in paper mode, printed beside Table 1's figures.
    pub paper_knot: Option<u64>,
    /// With `--check`: how the mesh's edges are shared.
    pub edges: Option<EdgeReport>,
    /// With `--stats-json`: the samples on the wrong side, and in adaptive mode the sampled
    /// distance between its surface and Steps 1–3's, in the bound's units.
    pub measured: Option<Measures>,
}

/// A mode's name in reports.
pub fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Embedded => "Steps 1–4, embedded",
        Mode::Paper => "Steps 1–4, paper",
        Mode::Steps123 => "Steps 1–3",
        Mode::Adaptive => "Adaptive",
    }
}

/// `n` with thousands separators, as the paper prints counts.
pub fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Adds the mode, the bound and the counts to the JSON object `j`, under the names `extract
/// --stats-json` uses (see [`sc_io::report::counts`]), so that `merge --stats-json` reports
/// them the same way.
pub fn add_counts(j: &mut Value, mode: Mode, max_error: Option<ErrorBound>, s: &Stats) {
    if let Value::Object(j) = j {
        j.extend(report::counts(mode, max_error, s));
    }
}

impl Summary {
    /// The units distances are reported in: the bound's, world units when no bound was given
    /// (adaptive mode's default bound is in world units).
    fn bound_units(&self) -> ErrorUnits {
        self.max_error.map_or(ErrorUnits::World, ErrorBound::units)
    }

    /// The JSON form: same numbers, seconds as floats.
    pub fn to_json(&self) -> Value {
        let mut j = json!({
            "input": self.input,
            "format": self.format,
            "dims": self.dims,
            "padded": self.padded,
            "coordinates": self.coordinates,
            "dtype": self.dtype,
            "iso": self.iso,
            "seconds": {
                "read": self.read.as_secs_f64(),
                "extract": self.extract.as_secs_f64(),
                "write": self.write.as_secs_f64(),
            },
        });
        if let Some(m) = self.measured {
            j["seconds"]["measure"] = m.time.as_secs_f64().into();
        }
        add_counts(&mut j, self.mode, self.max_error, &self.stats);
        if let Some(e) = self.edges {
            j["edges"] = e.to_json();
        }
        let measured = self.measured.as_ref();
        if let Some(d) = measured.and_then(|m| m.distance) {
            j["distance_to_steps123"] = json!({
                "mean": d.mean,
                "max": d.max,
                "samples": d.samples,
                "units": self.bound_units().name(),
            });
        }
        if let Some(n) = measured.and_then(|m| m.wrong_side_samples) {
            j[separation::WRONG_SIDE_SAMPLES] = n.into();
        }
        j
    }
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = &self.stats;
        let [nx, ny, nz] = self.dims;
        writeln!(f, "{} ({})", self.input, self.format)?;
        writeln!(
            f,
            "  dims {nx} × {ny} × {nz}, {}, iso {}",
            self.dtype, self.iso
        )?;
        writeln!(f, "  coordinates: {}", self.coordinates)?;
        if self.padded {
            writeln!(
                f,
                "  --pad: meshed as {} × {} × {}, one layer of empty samples added on every side",
                nx + 2,
                ny + 2,
                nz + 2
            )?;
        }
        writeln!(f, "  {:<22}{:>12}{:>12}", "", "vertices", "triangles")?;
        writeln!(
            f,
            "  {:<22}{:>12}{:>12}",
            "Steps 1–3",
            thousands(s.v13),
            thousands(s.t13)
        )?;
        if self.mode == Mode::Adaptive {
            writeln!(
                f,
                "  {:<22}{:>12}{:>12}   {:.1} % fewer triangles",
                mode_name(self.mode),
                thousands(s.vertices),
                thousands(s.triangles),
                s.reduction_percent(),
            )?;
        } else if self.mode != Mode::Steps123 {
            writeln!(
                f,
                "  {:<22}{:>12}{:>12}   {:.1} % fewer triangles ({} grey edges merged)",
                mode_name(self.mode),
                thousands(s.vertices),
                thousands(s.triangles),
                s.reduction_percent(),
                thousands(s.merged)
            )?;
        }
        if let Some(bound) = self.max_error {
            let (d, units) = match bound {
                ErrorBound::World(d) => (d, "world units"),
                ErrorBound::Voxels(d) => (d, "voxels"),
            };
            if self.mode == Mode::Adaptive {
                writeln!(
                    f,
                    "  --max-error {d} {units}: the surface stays within it of Steps 1–3's"
                )?;
            } else {
                writeln!(
                    f,
                    "  --max-error {d} {units}: {} more grey edges kept to stay within it",
                    thousands(s.bounded)
                )?;
            }
        }
        let measured = self.measured.as_ref();
        if let Some(n) = measured.and_then(|m| m.wrong_side_samples) {
            writeln!(
                f,
                "  samples on the wrong side of the surface: {}",
                thousands(n)
            )?;
        }
        if let Some(d) = measured.and_then(|m| m.distance) {
            let units = match self.bound_units() {
                ErrorUnits::World => "world units",
                ErrorUnits::Voxels => "voxels",
            };
            writeln!(
                f,
                "  distance to Steps 1–3: mean {:.4}, max {:.4} {units} ({} points sampled)",
                d.mean,
                d.max,
                thousands(d.samples)
            )?;
        }
        if let Some(ours) = self.paper_knot {
            let [mc, t13, t14] = PAPER_KNOT.map(thousands);
            writeln!(
                f,
                "  paper, Table 1 (knot): Marching Cubes {mc}, Steps 1–3 {t13}, Steps 1–4 {t14} triangles"
            )?;
            writeln!(
                f,
                "  ours:                  Steps 1–3 {}, Steps 1–4 (paper mode) {} triangles",
                thousands(s.t13),
                thousands(ours)
            )?;
        }
        if let Some(e) = self.edges {
            writeln!(
                f,
                "  edges: {} in 2 triangles, {} in 1 (border), {} in 3 or more, {} misoriented",
                thousands(e.manifold),
                thousands(e.border),
                thousands(e.non_manifold),
                thousands(e.misoriented)
            )?;
        }
        write!(
            f,
            "  time: read {:.3} s, extract {:.3} s, write {:.3} s",
            self.read.as_secs_f64(),
            self.extract.as_secs_f64(),
            self.write.as_secs_f64()
        )?;
        if let Some(m) = self.measured {
            write!(f, ", measure {:.3} s", m.time.as_secs_f64())?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sc_io::distance::Distance;

    #[test]
    fn thousands_groups_digits() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(13_968), "13,968");
        assert_eq!(thousands(1_234_567), "1,234,567");
    }

    #[test]
    fn text_and_json_agree() {
        let stats = Stats {
            v13: 10,
            t13: 16,
            merged: 2,
            blocked: 0,
            bounded: 0,
            vertices: 8,
            triangles: 12,
        };
        let s = Summary {
            input: "v.nii".into(),
            format: "NIfTI-1",
            dims: [4, 5, 6],
            padded: true,
            coordinates: "RAS world coordinates (scanner space)".into(),
            dtype: "u8",
            iso: 20.0,
            mode: Mode::Embedded,
            max_error: None,
            stats,
            read: Duration::from_millis(5),
            extract: Duration::from_millis(7),
            write: Duration::from_millis(1),
            paper_knot: None,
            edges: None,
            measured: None,
        };
        let text = s.to_string();
        assert!(
            text.contains("4 × 5 × 6") && text.contains("25.0 % fewer"),
            "{text}"
        );
        assert!(text.contains("--pad: meshed as 6 × 7 × 8"), "{text}");
        let j = s.to_json();
        assert_eq!(j["result"]["triangles"], 12);
        assert_eq!(j["mode"], "embedded");
        assert_eq!(j["padded"], true);
        assert_eq!(j["coordinates"], "RAS world coordinates (scanner space)");
        assert!(text.contains("coordinates: RAS world"), "{text}");
        assert_eq!(j["dims"], serde_json::json!([4, 5, 6]));
        assert_eq!(j["reduction_percent"], 25.0);
        assert!(j.get("distance_to_steps123").is_none() && !text.contains("distance"));
        assert!(j.get("wrong_side_samples").is_none() && !text.contains("wrong side"));

        // Any mode reports the samples on the wrong side when measured.
        let embedded = Summary {
            measured: Some(Measures {
                distance: None,
                wrong_side_samples: Some(1234),
                time: Duration::from_millis(3),
            }),
            ..s.clone()
        };
        let text = embedded.to_string();
        assert!(
            text.contains("samples on the wrong side of the surface: 1,234"),
            "{text}"
        );
        let j = embedded.to_json();
        assert_eq!(j["wrong_side_samples"], 1234);
        assert!(j.get("distance_to_steps123").is_none() && !text.contains("distance"));

        // Adaptive mode reports its distance to Steps 1–3 in the bound's units.
        let adaptive = Summary {
            mode: Mode::Adaptive,
            max_error: Some(ErrorBound::Voxels(0.5)),
            measured: Some(Measures {
                distance: Some(Distance {
                    mean: 0.0625,
                    max: 0.375,
                    samples: 1234,
                }),
                wrong_side_samples: Some(0),
                time: Duration::from_millis(3),
            }),
            ..s
        };
        let text = adaptive.to_string();
        assert!(
            text.contains("distance to Steps 1–3: mean 0.0625, max 0.3750 voxels (1,234 points"),
            "{text}"
        );
        assert!(text.contains("measure 0.003 s"), "{text}");
        let j = adaptive.to_json();
        let d = &j["distance_to_steps123"];
        assert_eq!(
            (d["mean"].as_f64(), d["max"].as_f64()),
            (Some(0.0625), Some(0.375))
        );
        assert_eq!(
            (d["samples"].as_u64(), d["units"].as_str()),
            (Some(1234), Some("voxels"))
        );
        assert_eq!(j["seconds"]["measure"], 0.003);
        assert_eq!(j["wrong_side_samples"], 0);
    }
}
