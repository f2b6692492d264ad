use wide::i32x4;

/// A sample type the extractor reads.
///
/// Classification (`filled`) is done in the sample's own type where that is exact, so integer
/// volumes never round through floating point on the hot path.
pub trait Scalar: Copy + Send + Sync + 'static {
    /// The iso value prepared for comparisons against this type.
    type Threshold: Copy + Send + Sync;
    /// Prepares `iso` so that `filled(v, t)` is exactly `v >= iso` (false for NaN).
    fn threshold(iso: f64) -> Self::Threshold;
    /// Whether the sample is filled (●).
    fn filled(self, t: Self::Threshold) -> bool;
    /// The sample as `f64`, for interpolation and gradients.
    fn to_f64(self) -> f64;
    /// `b − a` as `f64`, exactly `b.to_f64() − a.to_f64()`. Integer types subtract before they
    /// convert (exact either way), which halves the conversions a gradient makes.
    #[inline]
    fn diff(a: Self, b: Self) -> f64 {
        b.to_f64() - a.to_f64()
    }
    /// [`Scalar::diff`] rounded to `f32`, for normals. Integer types of up to 16 bits subtract
    /// and convert exactly.
    #[inline]
    fn diff32(a: Self, b: Self) -> f32 {
        Self::diff(a, b) as f32
    }
    /// Three [`Scalar::diff32`]s, `b[d] − a[d]`, and a zero: a gradient's lanes. Integer types
    /// of up to 16 bits subtract in `i32` and convert the three at once.
    #[inline]
    fn diffs32(a: [Self; 3], b: [Self; 3]) -> [f32; 4] {
        lane_by_lane(a, b)
    }
    /// Step 1 over a row: `out[i]` is 1 where `row[i]` is filled, else 0. A type may override
    /// it to take per-row decisions out of the loop, so that the loop vectorises.
    #[inline]
    fn classify_row(row: &[Self], t: Self::Threshold, out: &mut [u8]) {
        for (o, v) in out.iter_mut().zip(row) {
            *o = u8::from(v.filled(t));
        }
    }
}

/// [`Scalar::diffs32`] one [`Scalar::diff32`] at a time.
#[inline(always)]
fn lane_by_lane<T: Scalar>(a: [T; 3], b: [T; 3]) -> [f32; 4] {
    let [x, y, z] = core::array::from_fn(|d| T::diff32(a[d], b[d]));
    [x, y, z, 0.0]
}

macro_rules! int_scalar {
    ($($t:ty => $wide:ty),*) => {$(
        impl Scalar for $t {
            /// The smallest filled value, or `None` when no value of the type reaches `iso`.
            /// Comparing in the sample's own width lets the classification loop vectorise.
            type Threshold = Option<$t>;
            #[inline]
            fn threshold(iso: f64) -> Option<$t> {
                // `v >= iso` is `v >= ceil(iso)` for integers; NaN fills nothing.
                let c = if iso.is_nan() { i64::MAX } else { ceil_saturating(iso) };
                if c > <$t>::MAX as i64 { None } else { Some(c.max(<$t>::MIN as i64) as $t) }
            }
            #[inline]
            fn filled(self, t: Option<$t>) -> bool {
                t.is_some_and(|t| self >= t)
            }
            #[inline]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline]
            fn diff(a: $t, b: $t) -> f64 {
                (<$wide>::from(b) - <$wide>::from(a)) as f64
            }
            #[inline]
            fn diff32(a: $t, b: $t) -> f32 {
                (<$wide>::from(b) - <$wide>::from(a)) as f32
            }
            /// One vector conversion for the three lanes where `i32` holds the samples (the
            /// test is on the type, decided when compiling): the three scalar conversions per
            /// gradient and the shuffles that packed their results cost a vertex's normal about
            /// 8 instructions more than this (`bench/profile.sh … --normals`).
            #[inline]
            fn diffs32(a: [$t; 3], b: [$t; 3]) -> [f32; 4] {
                if size_of::<$t>() <= 2 {
                    // Exact: samples of up to 16 bits are `i32`s, their differences too, and
                    // those are `f32`s (below 2^24).
                    let d = |k: usize| b[k] as i32 - a[k] as i32;
                    i32x4::new([d(0), d(1), d(2), 0]).round_float().to_array()
                } else {
                    lane_by_lane(a, b)
                }
            }
            #[inline]
            fn classify_row(row: &[$t], t: Option<$t>, out: &mut [u8]) {
                match t {
                    Some(t) => {
                        for (o, &v) in out.iter_mut().zip(row) {
                            *o = u8::from(v >= t);
                        }
                    }
                    None => out.fill(0),
                }
            }
        }
    )*};
}
int_scalar!(u8 => i32, i8 => i32, u16 => i32, i16 => i32, u32 => i64, i32 => i64);

impl Scalar for f32 {
    /// The smallest `f32` at or above `iso`, so `v >= t` in `f32` is exactly `v as f64 >= iso`.
    type Threshold = f32;
    /// In blocks of sixteen: LLVM does not vectorise the plain loop, whose compare results are
    /// four times the width of its output bytes; this form it does.
    #[inline]
    fn classify_row(row: &[f32], t: f32, out: &mut [u8]) {
        let mut blocks = out.chunks_exact_mut(16);
        let mut rows = row.chunks_exact(16);
        for (o, v) in (&mut blocks).zip(&mut rows) {
            for (o, &v) in o.iter_mut().zip(v) {
                *o = u8::from(v >= t);
            }
        }
        for (o, &v) in blocks.into_remainder().iter_mut().zip(rows.remainder()) {
            *o = u8::from(v >= t);
        }
    }
    #[inline]
    fn threshold(iso: f64) -> f32 {
        let t = iso as f32;
        if (t as f64) < iso { t.next_up() } else { t }
    }
    #[inline]
    fn filled(self, t: f32) -> bool {
        self >= t
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self as f64
    }
}

impl Scalar for f64 {
    type Threshold = f64;
    #[inline]
    fn threshold(iso: f64) -> f64 {
        iso
    }
    #[inline]
    fn filled(self, t: f64) -> bool {
        self >= t
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
}

/// `ceil` saturated to `i64`, without `std`: the `as` cast truncates toward zero and saturates.
fn ceil_saturating(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) < x {
        t.saturating_add(1)
    } else {
        t
    }
}
