use core::fmt;

/// Why an extraction could not run. Every failure is reported, never a panic or a wrap.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Error {
    /// `nx · ny · nz` does not fit in `usize`.
    DimsOverflow([usize; 3]),
    /// The sample slice does not hold `nx · ny · nz` values.
    DataLength {
        /// `nx · ny · nz`.
        expected: usize,
        /// The slice's length.
        actual: usize,
    },
    /// The mesh would need more than `u32::MAX` vertices or triangles.
    TooManyVertices,
    /// A scratch buffer is smaller than [`crate::Scratch::len`] requires.
    ScratchTooSmall,
    /// The worker threads could not be started.
    ThreadPool,
    /// More than `nz` slices were pushed into a streamer.
    TooManySlices {
        /// `nz`, the number of slices the streamer was made for.
        nz: usize,
    },
    /// A streamed slice does not hold `nx · ny` values.
    SliceLength {
        /// `nx · ny`.
        expected: usize,
        /// The slice's length.
        actual: usize,
    },
    /// A block's cube range leaves the grid (cubes run from 0 to one less than the samples).
    BlockOutsideGrid {
        /// 0, 1, 2 for x, y, z.
        axis: usize,
        /// The cubes asked for along that axis.
        cubes: core::ops::Range<usize>,
        /// Samples of the grid along that axis.
        grid: usize,
    },
    /// A block's samples do not cover the halo its decisions read (`block_samples`).
    HaloTooSmall {
        /// 0, 1, 2 for x, y, z.
        axis: usize,
        /// The samples given along that axis.
        have: core::ops::Range<usize>,
        /// The samples needed along that axis.
        need: core::ops::Range<usize>,
    },
    /// Block meshes of different grids or settings (normals, positions of a shared vertex).
    BlocksDiffer,
    /// Two block meshes own the same cube.
    BlocksOverlap {
        /// The cube's key.
        cube: u64,
    },
    /// A block mesh's parts do not fit together (read from a damaged file, say): `what` says how.
    BlockMalformed {
        /// The broken rule, in words.
        what: &'static str,
    },
    /// An atlas's arrays do not fit together: `what` says how.
    AtlasMalformed {
        /// The broken rule, in words.
        what: &'static str,
    },
    /// A label extraction's smoothing width is negative, not finite, or wider than
    /// [`MAX_SMOOTHING`](crate::labels::MAX_SMOOTHING) voxels.
    Smoothing,
    /// `max_error` is negative, NaN or infinite.
    MaxError,
    /// `max_box` is not a power of two from 1 to `largest`.
    MaxBox {
        /// The box asked for, in cubes.
        given: u32,
        /// The largest box allowed on this volume, in cubes.
        largest: u32,
    },
    /// `max_box` or `allow_wrong_side` given to a mode that makes no boxes, or adaptive mode
    /// asked of an entry point that does not run it: `what` names it.
    NotAdaptive {
        /// The option or entry point.
        what: &'static str,
    },
    /// The joined blocks do not cover the grid.
    BlocksMissing {
        /// Cubes the blocks own.
        covered: u64,
        /// Cubes of the grid.
        cubes: u64,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::DimsOverflow(d) => {
                write!(
                    f,
                    "dimensions {}x{}x{} overflow the address space",
                    d[0], d[1], d[2]
                )
            }
            Error::DataLength { expected, actual } => {
                write!(f, "expected {expected} samples, got {actual}")
            }
            Error::TooManyVertices => {
                f.write_str("the mesh would exceed u32::MAX vertices or triangles")
            }
            Error::ScratchTooSmall => {
                f.write_str("scratch buffers are too small for these dimensions")
            }
            Error::ThreadPool => f.write_str("could not start the worker threads"),
            Error::TooManySlices { nz } => write!(f, "more than the {nz} slices the volume has"),
            Error::SliceLength { expected, actual } => {
                write!(f, "expected a slice of {expected} samples, got {actual}")
            }
            Error::BlockOutsideGrid { axis, cubes, grid } => write!(
                f,
                "cubes {}..{} along {} leave a grid of {grid} samples (cubes 0..{})",
                cubes.start,
                cubes.end,
                AXES[*axis],
                grid.saturating_sub(1)
            ),
            Error::HaloTooSmall { axis, have, need } => write!(
                f,
                "the block's samples {}..{} along {} do not cover the {}..{} its cubes read",
                have.start, have.end, AXES[*axis], need.start, need.end
            ),
            Error::BlocksDiffer => f.write_str(
                "the block meshes come from different grids or settings and cannot be joined",
            ),
            Error::BlocksOverlap { cube } => {
                write!(f, "two block meshes both own cube {cube}")
            }
            Error::BlockMalformed { what } => write!(f, "the block mesh is malformed: {what}"),
            Error::AtlasMalformed { what } => write!(f, "the atlas is malformed: {what}"),
            Error::Smoothing => write!(
                f,
                "the smoothing width is in voxels, from 0 (none) to {}",
                crate::kernel::labels::MAX_SMOOTHING
            ),
            Error::MaxError => f.write_str("max_error must be a finite number ≥ 0"),
            Error::MaxBox { given, largest } => write!(
                f,
                "max_box must be a power of two from 1 to {largest} (1, 2, 4, …), got {given}"
            ),
            Error::NotAdaptive { what } => f.write_str(what),
            Error::BlocksMissing { covered, cubes } => write!(
                f,
                "the joined blocks cover {covered} of the grid's {cubes} cubes"
            ),
        }
    }
}

const AXES: [&str; 3] = ["x", "y", "z"];

impl core::error::Error for Error {}
