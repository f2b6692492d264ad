use crate::{Error, Scalar};

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
}

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
    /// when it places the vertex; looked up afterwards from the positions, they had left the
    /// cache, and the pass took a tenth of the Python call. Off by default; block extraction
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

impl<'a, T: Scalar> Volume<'a, T> {
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
