//! A volume as read from a file: samples kept in their stored type, so that a 512³ `u16` scan
//! costs 256 MiB and not 1 GiB, and the extractor compares integers exactly.

use bytemuck::Pod;

pub use crate::buffer::Buffer;
use sc_runtime::Scalar;

use crate::space::Frame;

/// The sample types the extractor supports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Dtype {
    /// Unsigned 8-bit.
    U8,
    /// Signed 8-bit.
    I8,
    /// Unsigned 16-bit.
    U16,
    /// Signed 16-bit.
    I16,
    /// Unsigned 32-bit.
    U32,
    /// Signed 32-bit.
    I32,
    /// IEEE single.
    F32,
    /// IEEE double.
    F64,
}

impl Dtype {
    /// Bytes per sample.
    pub fn size(self) -> usize {
        match self {
            Dtype::U8 | Dtype::I8 => 1,
            Dtype::U16 | Dtype::I16 => 2,
            Dtype::U32 | Dtype::I32 | Dtype::F32 => 4,
            Dtype::F64 => 8,
        }
    }

    /// The name used on the command line and in summaries.
    pub fn name(self) -> &'static str {
        match self {
            Dtype::U8 => "u8",
            Dtype::I8 => "i8",
            Dtype::U16 => "u16",
            Dtype::I16 => "i16",
            Dtype::U32 => "u32",
            Dtype::I32 => "i32",
            Dtype::F32 => "f32",
            Dtype::F64 => "f64",
        }
    }

    /// The type named `name`, as this crate spells it (`u8`, `f32`) or as NumPy does (`uint8`,
    /// `float32`).
    pub fn from_name(name: &str) -> Option<Dtype> {
        Some(match name {
            "u8" | "uint8" => Dtype::U8,
            "i8" | "int8" => Dtype::I8,
            "u16" | "uint16" => Dtype::U16,
            "i16" | "int16" => Dtype::I16,
            "u32" | "uint32" => Dtype::U32,
            "i32" | "int32" => Dtype::I32,
            "f32" | "float32" => Dtype::F32,
            "f64" | "float64" => Dtype::F64,
            _ => return None,
        })
    }

    /// The type for `(kind, bytes)` as most formats describe it: `'u'`, `'i'` or `'f'`.
    pub fn from_kind(kind: char, bytes: usize) -> Option<Dtype> {
        Some(match (kind, bytes) {
            ('u', 1) => Dtype::U8,
            ('i', 1) => Dtype::I8,
            ('u', 2) => Dtype::U16,
            ('i', 2) => Dtype::I16,
            ('u', 4) => Dtype::U32,
            ('i', 4) => Dtype::I32,
            ('f', 4) => Dtype::F32,
            ('f', 8) => Dtype::F64,
            _ => return None,
        })
    }
}

/// Byte order of stored samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Endian {
    /// Least significant byte first (x86, ARM, and most files).
    #[default]
    Little,
    /// Most significant byte first.
    Big,
}

impl Endian {
    /// This machine's byte order.
    pub fn native() -> Endian {
        if cfg!(target_endian = "big") {
            Endian::Big
        } else {
            Endian::Little
        }
    }
}

/// Samples in their stored type, x fastest, in memory or mapped from their file.
#[derive(Clone, Debug, PartialEq)]
pub enum Samples {
    /// `u8` samples.
    U8(Buffer<u8>),
    /// `i8` samples.
    I8(Buffer<i8>),
    /// `u16` samples.
    U16(Buffer<u16>),
    /// `i16` samples.
    I16(Buffer<i16>),
    /// `u32` samples.
    U32(Buffer<u32>),
    /// `i32` samples.
    I32(Buffer<i32>),
    /// `f32` samples.
    F32(Buffer<f32>),
    /// `f64` samples.
    F64(Buffer<f64>),
}

/// Runs `$body` with `$v` bound to the typed [`Buffer`] inside a [`Samples`], so that generic code is
/// written once and monomorphised per type.
#[macro_export]
macro_rules! with_samples {
    ($samples:expr, $v:ident => $body:expr) => {
        match $samples {
            $crate::volume::Samples::U8($v) => $body,
            $crate::volume::Samples::I8($v) => $body,
            $crate::volume::Samples::U16($v) => $body,
            $crate::volume::Samples::I16($v) => $body,
            $crate::volume::Samples::U32($v) => $body,
            $crate::volume::Samples::I32($v) => $body,
            $crate::volume::Samples::F32($v) => $body,
            $crate::volume::Samples::F64($v) => $body,
        }
    };
}

/// Runs `$body` with the type alias `$t` set to the Rust type of a [`Dtype`].
macro_rules! with_dtype {
    ($dtype:expr, $t:ident => $body:expr) => {
        match $dtype {
            $crate::volume::Dtype::U8 => {
                type $t = u8;
                $body
            }
            $crate::volume::Dtype::I8 => {
                type $t = i8;
                $body
            }
            $crate::volume::Dtype::U16 => {
                type $t = u16;
                $body
            }
            $crate::volume::Dtype::I16 => {
                type $t = i16;
                $body
            }
            $crate::volume::Dtype::U32 => {
                type $t = u32;
                $body
            }
            $crate::volume::Dtype::I32 => {
                type $t = i32;
                $body
            }
            $crate::volume::Dtype::F32 => {
                type $t = f32;
                $body
            }
            $crate::volume::Dtype::F64 => {
                type $t = f64;
                $body
            }
        }
    };
}

pub(crate) use with_dtype;

impl Samples {
    /// The stored type.
    pub fn dtype(&self) -> Dtype {
        with_samples!(self, v => dtype_of(v))
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        with_samples!(self, v => v.len())
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// No samples, of type `dtype`: a grid whose samples are read later, or slice by slice.
    pub fn empty(dtype: Dtype) -> Samples {
        crate::with_dtype!(dtype, T => T::wrap(Vec::new().into()))
    }
}

fn dtype_of<T: Sample>(_: &[T]) -> Dtype {
    T::DTYPE
}

/// What the readers and the padding need of a sample type beyond what the extractor needs.
pub trait Sample: Scalar + Pod + PartialOrd {
    /// The matching [`Dtype`].
    const DTYPE: Dtype;
    /// Wraps typed samples.
    fn wrap(v: Buffer<Self>) -> Samples;
    /// The largest value of this type that is empty at `iso` (`< iso`), if the type has one.
    fn largest_below(iso: f64) -> Option<Self>;
}

macro_rules! int_sample {
    ($($t:ty => $d:ident),*) => {$(
        impl Sample for $t {
            const DTYPE: Dtype = Dtype::$d;
            fn wrap(v: Buffer<Self>) -> Samples {
                Samples::$d(v)
            }
            fn largest_below(iso: f64) -> Option<Self> {
                // Integers below `iso` are those below `ceil(iso)`.
                let below = iso.ceil() - 1.0;
                (below >= <$t>::MIN as f64).then(|| below.min(<$t>::MAX as f64) as $t)
            }
        }
    )*};
}
int_sample!(u8 => U8, i8 => I8, u16 => U16, i16 => I16, u32 => U32, i32 => I32);

impl Sample for f32 {
    const DTYPE: Dtype = Dtype::F32;
    fn wrap(v: Buffer<Self>) -> Samples {
        Samples::F32(v)
    }
    fn largest_below(iso: f64) -> Option<Self> {
        let v = iso as f32;
        let v = if f64::from(v) < iso { v } else { v.next_down() };
        v.is_finite().then_some(v)
    }
}

impl Sample for f64 {
    const DTYPE: Dtype = Dtype::F64;
    fn wrap(v: Buffer<Self>) -> Samples {
        Samples::F64(v)
    }
    fn largest_below(iso: f64) -> Option<Self> {
        let v = iso.next_down();
        v.is_finite().then_some(v)
    }
}

/// A linear map from stored values to real ones (DICOM RescaleSlope/Intercept, NIfTI
/// scl_slope/scl_inter). It is kept beside the samples rather than applied to them, so that no
/// second copy of the volume is made: with a positive slope `slope·v + inter >= iso` is
/// `v >= (iso - inter) / slope`, and interpolation and normals are unchanged.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linear {
    /// Multiplier; always positive (readers convert the samples when it is not).
    pub slope: f64,
    /// Offset.
    pub inter: f64,
}

impl Default for Linear {
    fn default() -> Self {
        Linear {
            slope: 1.0,
            inter: 0.0,
        }
    }
}

impl Linear {
    /// Whether this map changes nothing.
    pub fn is_identity(&self) -> bool {
        *self == Linear::default()
    }

    /// A stored value in real units.
    pub fn apply(&self, v: f64) -> f64 {
        v * self.slope + self.inter
    }

    /// The stored value that corresponds to the real value `iso`.
    pub fn invert(&self, iso: f64) -> f64 {
        (iso - self.inter) / self.slope
    }
}

/// A volume ready for extraction, with what the file says about its placement.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// The samples, x fastest.
    pub samples: Samples,
    /// `[nx, ny, nz]`.
    pub dims: [usize; 3],
    /// World distance between samples.
    pub spacing: [f64; 3],
    /// World position of sample `(0, 0, 0)`.
    pub origin: [f64; 3],
    /// The directions of the array's axes in the scanner's world, when the file states them:
    /// sample `i` is at `origin + direction · (i ⊙ spacing)`.
    pub frame: Option<Frame>,
    /// Stored-to-real value map.
    pub scale: Linear,
    /// The file format, for summaries.
    pub format: &'static str,
    /// Facts the file states that the mesh does not use (e.g. a rotation), for `info`.
    pub notes: Vec<String>,
    /// What the user must be told about the samples read (e.g. Zarr chunks that had no file and
    /// read as the fill value): every front end shows them as warnings.
    pub warnings: Vec<String>,
}

impl Grid {
    /// A grid with unit spacing, zero origin and no scaling.
    pub fn new(samples: Samples, dims: [usize; 3], format: &'static str) -> Self {
        Grid {
            samples,
            dims,
            spacing: [1.0; 3],
            origin: [0.0; 3],
            frame: None,
            scale: Linear::default(),
            format,
            notes: Vec::new(),
            warnings: Vec::new(),
        }
    }

    /// Records that real values are `slope · stored + inter`. A positive slope is kept beside the
    /// samples (see [`Linear`]); a negative one would turn `>= iso` into `<= iso`, so the samples
    /// are converted to floating point instead, `f32` where that is exact for the stored type.
    pub fn rescale(&mut self, slope: f64, inter: f64) {
        let map = Linear { slope, inter };
        if slope > 0.0 && inter.is_finite() && slope.is_finite() {
            self.scale = map;
        } else if slope < 0.0 && inter.is_finite() && slope.is_finite() {
            self.samples = with_samples!(&self.samples, v => to_real(v, map));
        }
    }

    /// Sample count.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Whether the grid has no samples.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// Minimum and maximum finite values in real units, and the NaN count, in one pass.
    pub fn range(&self) -> Range {
        let r = with_samples!(&self.samples, v => stored_range(v));
        let (a, b) = (self.scale.apply(r.min), self.scale.apply(r.max));
        Range {
            min: a.min(b),
            max: a.max(b),
            ..r
        }
    }

    /// Surrounds the volume with one layer of samples that are empty at `iso` (real units), so
    /// that every surface closes. The pad is the smallest finite sample if that is empty, so caps
    /// sit where the data would put them; otherwise the largest stored value below `iso`.
    pub fn pad(&mut self, iso: f64) -> Result<(), String> {
        let stored_iso = self.scale.invert(iso);
        let dims = self.dims;
        let dtype = self.samples.dtype();
        self.samples = with_samples!(&self.samples, v => {
            let fill = pad_value(v, stored_iso)
                .ok_or_else(|| format!("--pad: no {} value is below iso {iso}", dtype.name()))?;
            Sample::wrap(padded(v, dims, fill).into())
        });
        self.dims = dims.map(|d| d + 2);
        // One sample back along each axis, in world space.
        let step = self.spacing;
        let direction = self
            .frame
            .map_or([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], |f| {
                f.direction
            });
        self.origin = [0, 1, 2]
            .map(|r| self.origin[r] - (0..3).map(|a| direction[r][a] * step[a]).sum::<f64>());
        Ok(())
    }
}

/// What one pass over the samples finds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// Smallest finite value (`+inf` if none).
    pub min: f64,
    /// Largest finite value (`-inf` if none).
    pub max: f64,
    /// Finite samples.
    pub finite: usize,
    /// NaN samples.
    pub nan: usize,
}

fn stored_range<T: Sample>(v: &[T]) -> Range {
    let mut r = Range {
        min: f64::INFINITY,
        max: f64::NEG_INFINITY,
        finite: 0,
        nan: 0,
    };
    for x in v.iter().map(|x| x.to_f64()) {
        if x.is_nan() {
            r.nan += 1;
        } else if x.is_finite() {
            r.finite += 1;
            r.min = r.min.min(x);
            r.max = r.max.max(x);
        }
    }
    r
}

fn to_real<T: Sample>(v: &[T], map: Linear) -> Samples {
    if T::DTYPE.size() <= 2 || T::DTYPE == Dtype::F32 {
        Samples::F32(v.iter().map(|x| map.apply(x.to_f64()) as f32).collect())
    } else {
        Samples::F64(v.iter().map(|x| map.apply(x.to_f64())).collect())
    }
}

fn pad_value<T: Sample>(v: &[T], stored_iso: f64) -> Option<T> {
    let min = v
        .iter()
        .copied()
        .filter(|x| x.to_f64().is_finite())
        .min_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    min.filter(|m| m.to_f64() < stored_iso)
        .or_else(|| T::largest_below(stored_iso))
}

/// The samples of the box `at` (per axis) of a volume of `dims` samples stored x fastest, as a
/// volume of their own: a block's samples, copied out for meshing it alone.
pub(crate) fn cut<T: Copy>(
    v: &[T],
    [nx, ny, _]: [usize; 3],
    at: &[std::ops::Range<usize>; 3],
) -> Vec<T> {
    let mut out = Vec::with_capacity(at.iter().map(|r| r.len()).product());
    for z in at[2].clone() {
        for y in at[1].clone() {
            let row = (z * ny + y) * nx;
            out.extend_from_slice(&v[row + at[0].start..row + at[0].end]);
        }
    }
    out
}

fn padded<T: Sample>(v: &[T], [nx, ny, nz]: [usize; 3], fill: T) -> Vec<T> {
    let (px, py) = (nx + 2, ny + 2);
    let mut out = vec![fill; px * py * (nz + 2)];
    for z in 0..nz {
        for y in 0..ny {
            let src = nx * (y + ny * z);
            let dst = 1 + px * (y + 1 + py * (z + 1));
            out[dst..dst + nx].copy_from_slice(&v[src..src + nx]);
        }
    }
    out
}
