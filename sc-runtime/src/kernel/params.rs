use crate::Error;

/// `Display` and `FromStr` for a type with a table of names, `NAMES`, in the order of `ALL`:
/// each value is written as its name, and parsed from exactly that name.
macro_rules! named {
    ($t:ident) => {
        impl core::fmt::Display for $t {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl core::str::FromStr for $t {
            type Err = UnknownName;

            fn from_str(name: &str) -> Result<$t, UnknownName> {
                $t::NAMES
                    .iter()
                    .position(|n| *n == name)
                    .map(|i| $t::ALL[i])
                    .ok_or(UnknownName {
                        expected: &$t::NAMES,
                    })
            }
        }
    };
}

/// Which steps of Skeleton Climbing run (SPEC §5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Mode {
    /// Steps 1–4, merging only grey edges that keep the surface a closed 2-manifold.
    #[default]
    Embedded,
    /// Steps 1–4 as the paper does: every occupied interior grey edge is merged.
    Paper,
    /// Steps 1–3 only: the Marching-Cubes-sized surface, no merging.
    Steps123,
    /// Steps 1–3, with boxes of 2×2×2 cubes meshed as one where the surface through them is
    /// simple, stays within [`Params::max_error`] of the Steps 1–3 surface and keeps every
    /// sample on its side (docs/adaptive.md). One thread, the volume in memory.
    Adaptive,
}

impl Mode {
    /// Every mode, in declaration order.
    pub const ALL: [Mode; 4] = [Mode::Embedded, Mode::Paper, Mode::Steps123, Mode::Adaptive];

    /// The modes' names, in the order of [`Mode::ALL`]: the one spelling that the command
    /// line, Python, shard manifests and reports share.
    pub const NAMES: [&'static str; 4] = ["embedded", "paper", "steps123", "adaptive"];

    /// This mode's name (see [`Mode::NAMES`]).
    pub const fn name(self) -> &'static str {
        Mode::NAMES[self as usize]
    }
}

named!(Mode);

/// A name missing from a table of names ([`Mode::NAMES`], [`ErrorUnits::NAMES`]); its message
/// lists the names that are valid, for a front end to put beside the name it was given.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnknownName {
    expected: &'static [&'static str],
}

impl UnknownName {
    /// The valid names.
    pub fn expected(&self) -> &'static [&'static str] {
        self.expected
    }
}

/// "expected 'a', 'b' or 'c'".
impl core::fmt::Display for UnknownName {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("expected ")?;
        let last = self.expected.len().saturating_sub(1);
        for (i, name) in self.expected.iter().enumerate() {
            let sep = match i {
                0 => "",
                _ if i == last => " or ",
                _ => ", ",
            };
            write!(f, "{sep}'{name}'")?;
        }
        Ok(())
    }
}

impl core::error::Error for UnknownName {}

/// The order of the coordinates of each position and normal a sweep emits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Axes {
    /// `(x, y, z)`, x the fastest axis of the samples in memory.
    #[default]
    Xyz,
    /// `(z, y, x)`: the axis order of a C-ordered NumPy array, whose first index is z. Emitted
    /// so by the sweep, the coordinates need no pass that reverses them afterwards: without
    /// that pass the Python package's `marching_cubes` takes 0.91–0.97× the time.
    Zyx,
}

/// How far Step 4 may move the surface: a grey edge merges only if its vertex lies closer than
/// this to the two triangles that replace its four, and the new diagonal (its quarter points and
/// middle) closer than this to the four old triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ErrorBound {
    /// In world units (positions are `index × spacing + origin`).
    World(f64),
    /// In grid steps: distances measured on sample indices, whatever the spacing.
    Voxels(f64),
}

impl ErrorBound {
    /// A bound of `value` in `units`.
    pub fn new(value: f64, units: ErrorUnits) -> ErrorBound {
        match units {
            ErrorUnits::World => ErrorBound::World(value),
            ErrorUnits::Voxels => ErrorBound::Voxels(value),
        }
    }

    /// The bound's number, in its units.
    pub fn value(self) -> f64 {
        match self {
            ErrorBound::World(d) | ErrorBound::Voxels(d) => d,
        }
    }

    /// The units the bound is in.
    pub fn units(self) -> ErrorUnits {
        match self {
            ErrorBound::World(_) => ErrorUnits::World,
            ErrorBound::Voxels(_) => ErrorUnits::Voxels,
        }
    }
}

/// The units of an [`ErrorBound`], without its number: what a front end parses from a name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ErrorUnits {
    /// World units (see [`ErrorBound::World`]).
    #[default]
    World,
    /// Grid steps (see [`ErrorBound::Voxels`]).
    Voxels,
}

impl ErrorUnits {
    /// Both units, in declaration order.
    pub const ALL: [ErrorUnits; 2] = [ErrorUnits::World, ErrorUnits::Voxels];

    /// The units' names, in the order of [`ErrorUnits::ALL`], as the command line, Python,
    /// shard manifests and reports spell them.
    pub const NAMES: [&'static str; 2] = ["world", "voxels"];

    /// These units' name (see [`ErrorUnits::NAMES`]).
    pub const fn name(self) -> &'static str {
        ErrorUnits::NAMES[self as usize]
    }
}

named!(ErrorUnits);

/// Everything about an extraction besides the samples.
#[derive(Clone, Copy, Debug)]
pub struct Params {
    /// Samples `>= iso` are filled; NaN is empty.
    pub iso: f64,
    /// Which steps run.
    pub mode: Mode,
    /// Emit per-vertex normals (negated, normalised central-difference gradients).
    pub normals: bool,
    /// Emit per vertex the larger of the two samples at the ends of its grid edge, as `f32` (a
    /// NaN end gives NaN), through [`Sink::vertex_value`](crate::Sink::vertex_value): what
    /// scikit-image's `marching_cubes` returns as `values`. The sweep has both samples at hand
    /// when it places the vertex; looked up afterwards from the positions, they would have left
    /// the cache. Off by default; block extraction
    /// (`extract_block`) does not carry values.
    pub values: bool,
    /// World distance between samples along x, y, z.
    pub spacing: [f64; 3],
    /// World position of sample `(0, 0, 0)`.
    pub origin: [f64; 3],
    /// The order of the emitted positions' and normals' coordinates; `spacing` and `origin` are
    /// in `(x, y, z)` order either way.
    pub axes: Axes,
    /// The bound on Step 4's displacement of the surface; `None` (the default) merges whatever
    /// the mode allows, and a bound of zero merges nothing.
    pub max_error: Option<ErrorBound>,
    /// Adaptive mode's largest box, in cubes along each side: a power of two from 1 up to the
    /// largest this version makes (2) and the volume's longest cube count; `None` (the default)
    /// is that largest. 1 keeps every unit cube, the Steps 1–3 mesh. Other modes refuse it.
    pub max_box: Option<u32>,
    /// Adaptive mode: let boxes leave samples on the wrong side of the surface, as the 1998
    /// paper does, for fewer triangles; off by default, every sample keeps its side. Other modes
    /// refuse it.
    pub allow_wrong_side: bool,
    /// The case tables; [`crate::tables::DEFAULT`] unless a crate brings its own.
    pub tables: &'static crate::tables::CaseTables,
}

impl Params {
    /// Embedded mode, with normals, without values, unit spacing, the origin at zero, and
    /// coordinates in `(x, y, z)` order.
    pub fn new(iso: f64) -> Self {
        Params {
            iso,
            mode: Mode::Embedded,
            normals: true,
            values: false,
            spacing: [1.0; 3],
            origin: [0.0; 3],
            axes: Axes::Xyz,
            max_error: None,
            max_box: None,
            allow_wrong_side: false,
            tables: &crate::tables::DEFAULT,
        }
    }
}

/// A borrowed grid of samples, x fastest: `data[x + nx * (y + ny * z)]`.
#[derive(Clone, Copy, Debug)]
pub struct Volume<'a, T> {
    data: &'a [T],
    dims: [usize; 3],
}

impl<'a, T> Volume<'a, T> {
    /// Checks that `data` holds exactly `nx · ny · nz` samples.
    pub fn new(data: &'a [T], dims: [usize; 3]) -> Result<Self, Error> {
        let expected = dims
            .iter()
            .try_fold(1usize, |acc, &d| acc.checked_mul(d))
            .ok_or(Error::DimsOverflow(dims))?;
        if data.len() != expected {
            return Err(Error::DataLength {
                expected,
                actual: data.len(),
            });
        }
        Ok(Volume { data, dims })
    }

    /// The samples, x fastest.
    pub fn data(&self) -> &'a [T] {
        self.data
    }

    /// `[nx, ny, nz]`.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::string::ToString;

    #[test]
    fn names_round_trip_and_unknown_names_list_the_valid_ones() {
        for (i, mode) in Mode::ALL.into_iter().enumerate() {
            assert_eq!(mode.name(), Mode::NAMES[i]);
            assert_eq!(mode.to_string(), Mode::NAMES[i]);
            assert_eq!(mode.name().parse(), Ok(mode));
        }
        for (i, units) in ErrorUnits::ALL.into_iter().enumerate() {
            assert_eq!(units.name(), ErrorUnits::NAMES[i]);
            assert_eq!(units.name().parse(), Ok(units));
            let bound = ErrorBound::new(0.5, units);
            assert_eq!((bound.value(), bound.units()), (0.5, units));
        }
        let e = "Paper".parse::<Mode>().unwrap_err();
        assert_eq!(e.expected(), &Mode::NAMES[..]);
        assert_eq!(
            e.to_string(),
            "expected 'embedded', 'paper', 'steps123' or 'adaptive'"
        );
        let e = "mm".parse::<ErrorUnits>().unwrap_err();
        assert_eq!(e.to_string(), "expected 'world' or 'voxels'");
    }
}
