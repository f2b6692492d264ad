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
        }
    }
}

impl core::error::Error for Error {}
