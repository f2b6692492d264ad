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
}

macro_rules! int_scalar {
    ($($t:ty),*) => {$(
        impl Scalar for $t {
            type Threshold = i64;
            #[inline]
            fn threshold(iso: f64) -> i64 {
                // `v >= iso` is `v >= ceil(iso)` for integers; NaN fills nothing.
                if iso.is_nan() { i64::MAX } else { libm_ceil(iso) }
            }
            #[inline]
            fn filled(self, t: i64) -> bool {
                self as i64 >= t
            }
            #[inline]
            fn to_f64(self) -> f64 {
                self as f64
            }
        }
    )*};
}
int_scalar!(u8, i8, u16, i16, u32, i32);

macro_rules! float_scalar {
    ($($t:ty),*) => {$(
        impl Scalar for $t {
            type Threshold = f64;
            #[inline]
            fn threshold(iso: f64) -> f64 {
                iso
            }
            #[inline]
            fn filled(self, t: f64) -> bool {
                self as f64 >= t
            }
            #[inline]
            fn to_f64(self) -> f64 {
                self as f64
            }
        }
    )*};
}
float_scalar!(f32, f64);

/// `ceil` saturated to `i64`, without `std`: the `as` cast truncates toward zero and saturates.
fn libm_ceil(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) < x {
        t.saturating_add(1)
    } else {
        t
    }
}
