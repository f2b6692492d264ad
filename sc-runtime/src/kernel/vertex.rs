//! Step 1's vertex placement and the optional normals (SPEC §1, §7).

use crate::Scalar;
use wide::f32x4;

/// The SPEC §1 clamp: keeps vertices off grid points, so no triangle collapses when a sample
/// equals the iso value exactly.
const T_MIN: f64 = 1.0 / 1024.0;

/// Where along an edge from sample `a` to sample `b` the surface crosses.
#[inline]
pub(crate) fn crossing(a: f64, b: f64, iso: f64) -> f64 {
    let t = (iso - a) / (b - a);
    if t.is_finite() {
        t.clamp(T_MIN, 1.0 - T_MIN)
    } else {
        0.5
    }
}

/// Where along the edge from `p` along `axis` the surface crosses; the middle at a NaN end.
#[inline(always)]
pub(crate) fn edge_crossing<T: Scalar>(
    field: &Field<'_, T>,
    p: [usize; 3],
    axis: usize,
    iso: f64,
) -> f64 {
    let mut q = p;
    q[axis] += 1;
    let s = |p: [usize; 3]| field.slice(p[2])[p[0] + field.dims[0] * p[1]];
    sample_crossing(s(p), s(q), iso)
}

/// Where the surface crosses between the samples `a` and `b` of an edge; the middle at a NaN end.
#[inline(always)]
pub(crate) fn sample_crossing<T: Scalar>(a: T, b: T, iso: f64) -> f64 {
    wide_crossing(a.to_f64(), b.to_f64(), iso)
}

/// [`sample_crossing`] of samples already in `f64`.
#[inline(always)]
pub(crate) fn wide_crossing(a: f64, b: f64, iso: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        0.5
    } else {
        crossing(a, b, iso)
    }
}

/// The interpolation weights `(1 − t, t)` of an edge's two gradients for its crossing, times
/// `|b − a|`: a normal is a direction, and weights made of the samples alone keep the crossing's
/// division off the normal's chain of long-latency steps (about 0.96 times the extraction's time
/// with normals in the plain output's copy of the sweep; the values-and-`(z, y, x)` copy the
/// Python package uses did not gain). Not clamped as [`crossing`] clamps the vertex:
/// scikit-image's normals are not either, the clamp moves a normal by at most 1/1024 of its
/// gradients' difference, and it cost nine instructions per vertex.
#[inline(always)]
fn weights(a: f64, b: f64, iso: f64) -> [f64; 2] {
    [(b - iso).abs(), (a - iso).abs()]
}

/// Square roots: `std`'s where it is linked, which compile to one instruction the optimiser sees
/// through; `libm`'s (the same correctly rounded results) otherwise.
#[cfg(feature = "std")]
pub(crate) mod root {
    #[inline(always)]
    pub fn sqrt(x: f64) -> f64 {
        x.sqrt()
    }

    #[inline(always)]
    pub fn sqrtf(x: f32) -> f32 {
        x.sqrt()
    }
}
#[cfg(not(feature = "std"))]
pub(crate) mod root {
    pub use libm::{sqrt, sqrtf};
}
use root::{sqrt, sqrtf};

/// A vertex's normal as the sweep hands it to its sink.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Normal {
    /// An outward direction whose squared length is a normal `f32` ([`scalable`]): the unit
    /// normal is [`unit`] of it, which the sink computes, at once or later with others.
    Toward([f32; 3]),
    /// The unit normal itself, computed in `f64` where `f32` fell short.
    Unit([f32; 3]),
}

impl Normal {
    /// The unit normal.
    #[cfg(test)]
    pub fn unit(self) -> [f32; 3] {
        match self {
            Normal::Toward(d) => unit(d),
            Normal::Unit(n) => n,
        }
    }

    /// The coordinates in `(z, y, x)` order (see [`Axes::Zyx`](crate::Axes::Zyx)).
    #[inline(always)]
    pub fn reversed(self) -> Normal {
        let r = |[x, y, z]: [f32; 3]| [z, y, x];
        match self {
            Normal::Toward(d) => Normal::Toward(r(d)),
            Normal::Unit(n) => Normal::Unit(r(n)),
        }
    }
}

/// The squared length of `d`, summed as `(x² + z²) + y²`: [`unit`] and [`units`] give the same
/// bits, and so does a direction in `(z, y, x)` order ([`Normal::reversed`]), which a sink
/// scales after the sweep reversed it.
#[inline(always)]
fn squared([x, y, z]: [f32; 3]) -> f32 {
    (x * x + z * z) + y * y
}

/// Whether a squared length is a normal, finite `f32` (NaN is not), tested on the bits: positive
/// normal floats are the bit patterns `MIN_POSITIVE ..= MAX`'s, and one unsigned compare finds
/// them. Only then does `f32` give a direction's unit vector accurately.
#[inline(always)]
fn scalable(squared: f32) -> bool {
    let low = f32::MIN_POSITIVE.to_bits();
    squared.to_bits().wrapping_sub(low) <= f32::MAX.to_bits() - low
}

/// The unit vector along `d`, a [`Normal::Toward`]'s direction: `d` times `1 / √(d · d)`.
#[inline]
pub(crate) fn unit(d: [f32; 3]) -> [f32; 3] {
    debug_assert!(scalable(squared(d)));
    let r = 1.0 / sqrtf(squared(d));
    d.map(|c| c * r)
}

/// [`unit`] of every direction in `ds`, in place, four at a time: a square root and a division
/// per vertex, each waiting on the last, stalled the vertex passes, and four lanes at once do
/// not wait (see [`Sink::edge_vertex_toward`](crate::Sink::edge_vertex_toward)). The bits are
/// [`unit`]'s: the same correctly rounded operations, lane by lane.
#[cfg(feature = "alloc")]
pub(crate) fn units(ds: &mut [[f32; 3]]) {
    let (fours, rest) = ds.as_chunks_mut::<4>();
    for four in fours {
        units4(four.as_flattened_mut().try_into().expect("four directions"));
    }
    for d in rest {
        *d = unit(*d);
    }
}

/// Four directions' [`unit`]s, on SSE registers: the twelve coordinates loaded as three
/// registers and shuffled into each sum's terms: about half the instructions of a scalar
/// gather of the four squared lengths and twelve scalar products.
#[cfg(all(feature = "alloc", target_arch = "x86_64"))]
#[inline(always)]
fn units4(d: &mut [f32; 12]) {
    use core::arch::x86_64::{
        __m128, _mm_add_ps, _mm_div_ps, _mm_loadu_ps, _mm_mul_ps, _mm_set1_ps, _mm_shuffle_ps,
        _mm_sqrt_ps, _mm_storeu_ps,
    };
    /// `_mm_shuffle_ps`'s lanes: `[p[i], p[j], q[k], q[l]]`.
    macro_rules! pick {
        ($p:expr, $q:expr, $i:literal, $j:literal, $k:literal, $l:literal) => {
            _mm_shuffle_ps::<{ $i | $j << 2 | $k << 4 | $l << 6 }>($p, $q)
        };
    }
    let p = d.as_mut_ptr();
    // SAFETY: SSE is part of x86-64's baseline, and `d` is twelve floats: the loads and stores
    // are of floats 0–3, 4–7 and 8–11.
    unsafe {
        // a = [x0 y0 z0 x1], b = [y1 z1 x2 y2], c = [z2 x3 y3 z3]; the squared lengths summed as
        // `squared` sums them, ((x² + z²) + y²).
        let [a, b, c]: [__m128; 3] = [0, 4, 8].map(|o| _mm_loadu_ps(p.add(o)));
        let (aa, bb, cc) = (_mm_mul_ps(a, a), _mm_mul_ps(b, b), _mm_mul_ps(c, c));
        let x = pick!(aa, pick!(bb, cc, 2, 3, 0, 1), 0, 3, 0, 3);
        let z = pick!(pick!(aa, bb, 2, 2, 1, 1), cc, 0, 2, 0, 3);
        let y = pick!(
            pick!(aa, bb, 1, 1, 0, 0),
            pick!(bb, cc, 3, 3, 2, 2),
            0,
            2,
            0,
            2
        );
        let r = _mm_div_ps(
            _mm_set1_ps(1.0),
            _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(x, z), y)),
        );
        _mm_storeu_ps(p, _mm_mul_ps(a, pick!(r, r, 0, 0, 0, 1)));
        _mm_storeu_ps(p.add(4), _mm_mul_ps(b, pick!(r, r, 1, 1, 2, 2)));
        _mm_storeu_ps(p.add(8), _mm_mul_ps(c, pick!(r, r, 2, 3, 3, 3)));
    }
}

/// Four directions' [`unit`]s, lane by lane (`wide`'s root without `std` is not `sqrtf`'s, so
/// the roots are taken one by one).
#[cfg(all(feature = "alloc", not(target_arch = "x86_64")))]
#[inline(always)]
fn units4(d: &mut [f32; 12]) {
    let four = d.as_chunks_mut::<3>().0;
    let roots = core::array::from_fn(|i| sqrtf(squared(four[i])));
    let r = f32x4::ONE / f32x4::new(roots);
    for (d, r) in four.iter_mut().zip(r.to_array()) {
        *d = d.map(|c| c * r);
    }
}

/// The gradient's reciprocal steps, per axis, for one-sided and central differences, relative to
/// the smallest spacing: a normal is a direction, so one scale for all three axes does not change
/// it, and steps of at most one keep `f32` gradients of integer samples far from overflow.
#[derive(Clone, Copy)]
pub(crate) struct Steps {
    wide: [[f64; 2]; 3],
    /// The central steps in `f32`, as the lanes an interior gradient is multiplied by.
    central: f32x4,
}

impl Steps {
    pub fn new(spacing: [f64; 3]) -> Steps {
        let least = spacing.iter().copied().fold(f64::INFINITY, f64::min);
        let wide = spacing.map(|s| [least / s, 0.5 * least / s]);
        let central = |d: usize| wide[d][1] as f32;
        Steps {
            wide,
            central: f32x4::new([central(0), central(1), central(2), 0.0]),
        }
    }
}

/// Reads samples and gradients around grid points of the slices a sweep step can see.
pub(crate) struct Field<'v, T> {
    pub dims: [usize; 3],
    pub steps: Steps,
    /// Slices `z - 1`, `z`, `z + 1` as available, by `z`.
    pub slices: [&'v [T]; 4],
    pub first: usize,
}

impl<'v, T: Scalar> Field<'v, T> {
    #[inline]
    fn slice(&self, z: usize) -> &[T] {
        self.slices[z - self.first]
    }

    /// Central differences inside, one-sided at the border, each made by `diff` from its two
    /// samples and its reciprocal step: for edges with an end on the grid's border, which
    /// [`InteriorRow::pair`] leaves here, in `f32` as the pair does, or in `f64` where `f32`
    /// over- or underflows.
    #[inline(always)]
    fn gradient<F>(&self, p: [usize; 3], diff: impl Fn(T, T, f64) -> F) -> [F; 3] {
        let [x, y, z] = p;
        let [nx, ny, nz] = self.dims;
        let step = |c: usize, n: usize| (c.saturating_sub(1), (c + 1).min(n - 1));
        let scaled = |a: T, b: T, lo: usize, hi: usize, d: usize| {
            diff(a, b, self.steps.wide[d][usize::from(hi - lo == 2)])
        };
        let here = self.slice(z);
        let row = nx * y;
        let (xl, xh) = step(x, nx);
        let gx = scaled(here[row + xl], here[row + xh], xl, xh, 0);
        let (yl, yh) = step(y, ny);
        let gy = scaled(here[nx * yl + x], here[nx * yh + x], yl, yh, 1);
        let (zl, zh) = step(z, nz);
        let gz = scaled(self.slice(zl)[row + x], self.slice(zh)[row + x], zl, zh, 2);
        [gx, gy, gz]
    }

    /// [`Field::gradient`] in `f32`, the fourth lane zero: exactly what [`InteriorRow::pair`]
    /// computes for an interior point.
    fn gradient32(&self, p: [usize; 3]) -> f32x4 {
        let [gx, gy, gz] = self.gradient(p, |a, b, s| T::diff32(a, b) * s as f32);
        f32x4::new([gx, gy, gz, 0.0])
    }

    /// Slice `z`'s rows for the normals of its edges along `AXIS`, if the field holds whole
    /// planes. The planes on the grid's first and last slices are taken too, their one-sided
    /// z-differences made by the row's own slice standing in for the missing one and the z-step
    /// doubled: a thin scan has a large share of its edges there, and each would otherwise take
    /// two bounds-checked general gradients. Once per plane, not per row: per row, this costs
    /// more than the border's vertices save.
    pub fn interior_plane<const AXIS: usize>(
        &self,
        z: usize,
        normals: bool,
    ) -> Option<InteriorPlane<'v, T, AXIS>> {
        let [nx, ny, nz] = self.dims;
        if !normals {
            return None;
        }
        // Slices `z - 1`, `z`, `z + 1` and `z + 2` clamped to the grid, as `Field::gradient`
        // clamps them, and the z-steps of the gradients at `z` and (for z-edges) `z + 1`. A
        // field that does not hold one of them is left to the general path.
        let last = nz.checked_sub(1)?;
        let slice = |c: usize| {
            self.slices
                .get(c.min(last).checked_sub(self.first)?)
                .copied()
        };
        let z_top = if AXIS == 2 { z + 2 } else { z + 1 };
        let slices = [
            slice(z.saturating_sub(1))?,
            slice(z)?,
            slice(z + 1)?,
            slice(z_top)?,
        ];
        let plane = nx.checked_mul(ny)?;
        if slices.iter().any(|s| s.len() < plane) {
            return None;
        }
        let step = |lo: usize, hi: usize| {
            let central = usize::from(hi.min(last) - lo == 2);
            let mut steps = self.steps.central.to_array();
            steps[2] = self.steps.wide[2][central] as f32;
            f32x4::new(steps)
        };
        let lower = step(z.saturating_sub(1), z + 1);
        Some(InteriorPlane {
            dims: [nx, ny],
            slices,
            steps: [lower, if AXIS == 2 { step(z, z + 2) } else { lower }],
        })
    }

    /// The outward normal where level `iso` crosses the edge from `p` along `AXIS`, whose
    /// samples are `(a, b)`: the negated gradient interpolated there ([`weights`]), or the edge
    /// direction where it vanishes or is NaN.
    /// Computed in `f32`, a vertex's gradient in one vector, since the result is `f32` anyway
    /// (fewer instructions than in `f64`). Where the squared length leaves `f32`'s normal range,
    /// in `f64`. Otherwise it is left to the sink to scale ([`Normal::Toward`]).
    /// Inlined into each vertex pass: as a call it spills the pass's registers.
    #[inline(always)]
    pub fn normal<const AXIS: usize>(
        &self,
        row: Option<InteriorRow<'_, '_, T, AXIS>>,
        p: [usize; 3],
        (a, b): (f64, f64),
        iso: f64,
    ) -> Normal {
        let (ga, gb) = row.and_then(|r| r.pair(p[0])).unwrap_or_else(|| {
            let mut q = p;
            q[AXIS] += 1;
            (self.gradient32(p), self.gradient32(q))
        });
        let [wa, wb] = weights(a, b, iso).map(|w| f32x4::splat(w as f32));
        // The gradient, not yet negated: the negation goes into the reciprocal length below, one
        // sign instead of three (and the same bits: a sign change is exact).
        let g = ga * wa + gb * wb;
        let [x, y, z, _] = (-g).to_array();
        // The test reads the squared length, not its root: a branch on the root would wait for
        // the square root's long latency, and that wait was a quarter of what normals cost.
        if scalable(squared([x, y, z])) {
            Normal::Toward([x, y, z])
        } else {
            Normal::Unit(self.wide_normal::<AXIS>(p, (a, b), iso))
        }
    }

    /// [`Field::normal`] in `f64`, for gradients too large or too small for `f32` (and for
    /// vanishing or NaN ones, which take the edge's direction).
    #[cold]
    #[inline(never)]
    fn wide_normal<const AXIS: usize>(
        &self,
        p: [usize; 3],
        (a, b): (f64, f64),
        iso: f64,
    ) -> [f32; 3] {
        let mut q = p;
        q[AXIS] += 1;
        let wide = |p| self.gradient(p, |a, b, s| T::diff(a, b) * s);
        let (ga, gb) = (wide(p), wide(q));
        // The weights' `t`, which keeps the gradient's scale: the weights themselves may be
        // what took `f32` out of range.
        let [wa, wb] = weights(a, b, iso);
        let t = wb / (wa + wb);
        let g: [f64; 3] = core::array::from_fn(|d| ga[d] + t * (gb[d] - ga[d]));
        let squared = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        // Positive and finite, on the bits as above.
        if squared.to_bits().wrapping_sub(1) < f64::MAX.to_bits() {
            let inv = -1.0 / sqrt(squared);
            g.map(|c| (c * inv) as f32)
        } else {
            let mut n = [0.0; 3];
            n[AXIS] = if a >= iso { 1.0 } else { -1.0 };
            n
        }
    }
}

/// The slices and steps that the rows of one plane's edges along `AXIS` read their gradients
/// from (see [`Field::interior_plane`]).
pub(crate) struct InteriorPlane<'v, T, const AXIS: usize> {
    /// The grid's `nx` and `ny`.
    dims: [usize; 2],
    /// Slices `z - 1`, `z`, `z + 1` and, for z-edges, `z + 2`, clamped to the grid: each at
    /// least `nx · ny` long.
    slices: [&'v [T]; 4],
    /// The reciprocal steps of the gradients at `z` and at the edges' other end: central, but in
    /// z one-sided where a slice was clamped.
    steps: [f32x4; 2],
}

impl<'v, T, const AXIS: usize> InteriorPlane<'v, T, AXIS> {
    /// Row `y`, if every one of its edges with both ends inside the grid in x has them inside
    /// in y too.
    #[inline(always)]
    pub fn row(&self, y: usize) -> Option<InteriorRow<'_, 'v, T, AXIS>> {
        let [nx, ny] = self.dims;
        (y >= 1 && y + 1 + usize::from(AXIS == 1) < ny).then_some(InteriorRow {
            plane: self,
            start: nx * y,
        })
    }
}

/// A row of an [`InteriorPlane`] whose edges along `AXIS` read their gradients' samples
/// unchecked: [`InteriorPlane::row`] made sure of the row and [`InteriorRow::pair`] makes sure
/// of `x`. The bounds checks of a dozen samples per vertex were a quarter of what normals cost.
#[derive(Clone, Copy)]
pub(crate) struct InteriorRow<'p, 'v, T, const AXIS: usize> {
    plane: &'p InteriorPlane<'v, T, AXIS>,
    /// Where the row starts in a slice: `nx · y`, with `1 <= y` and `y + 2 < ny` (`y + 3` for
    /// y-edges).
    start: usize,
}

impl<T: Scalar, const AXIS: usize> InteriorRow<'_, '_, T, AXIS> {
    /// The gradients at both ends of the edge from `x` along `AXIS`, when both are inside the
    /// grid in x, as nearly all are. The arithmetic is [`Field::gradient32`]'s, so the normals
    /// are the same to the bit.
    #[inline(always)]
    fn pair(&self, x: usize) -> Option<(f32x4, f32x4)> {
        let InteriorPlane {
            dims: [nx, _],
            slices,
            steps,
        } = self.plane;
        let nx = *nx;
        if !(x >= 1 && x + 1 + usize::from(AXIS == 0) < nx) {
            return None;
        }
        let i = self.start + x;
        // Called only with the indices below: each is `i` give or take at most `nx + 1` (up to
        // `2 · nx` above for y-edges), which the bounds on `x` above and on `y` in `start` keep
        // in `0..nx · ny`.
        // SAFETY: `0..nx · ny` is within every slice read (`Field::interior_plane`).
        let at = |s: &[T], k: usize| unsafe { *s.get_unchecked(k) };
        // A gradient from the samples its three differences subtract and are subtracted from.
        let gradient = |[lo, hi]: [[T; 3]; 2], steps: f32x4| f32x4::new(T::diffs32(lo, hi)) * steps;
        let [b, h, a, top] = *slices;
        let lower = gradient(
            [
                [at(h, i - 1), at(h, i - nx), at(b, i)],
                [at(h, i + 1), at(h, i + nx), at(a, i)],
            ],
            steps[0],
        );
        let upper = match AXIS {
            0 => [
                [at(h, i), at(h, i + 1 - nx), at(b, i + 1)],
                [at(h, i + 2), at(h, i + 1 + nx), at(a, i + 1)],
            ],
            1 => [
                [at(h, i + nx - 1), at(h, i), at(b, i + nx)],
                [at(h, i + nx + 1), at(h, i + 2 * nx), at(a, i + nx)],
            ],
            _ => [
                [at(a, i - 1), at(a, i - nx), at(h, i)],
                [at(a, i + 1), at(a, i + nx), at(top, i)],
            ],
        };
        Some((lower, gradient(upper, steps[1])))
    }
}

#[cfg(test)]
mod tests {
    use super::{Field, Steps, scalable, squared, unit, units};
    use alloc::vec::Vec;
    use wide::f32x4;

    /// A small pseudo-random volume, `scale` times values from -1000 to about 2.4 million.
    fn noise(dims: [usize; 3], scale: f64) -> Vec<f64> {
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        (0..dims.iter().product())
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                ((state >> 40) as f64 / 7.0 - 1000.0) * scale
            })
            .collect()
    }

    /// Calls `visit` with every grid point and the field a sweep sees there: slices `z - 1` to
    /// `z + 2`, as far as the grid goes.
    fn sweep<T: crate::Scalar>(
        data: &[T],
        dims: [usize; 3],
        mut visit: impl FnMut(&Field<'_, T>, [usize; 3]),
    ) {
        let slices: Vec<&[T]> = data.chunks(dims[0] * dims[1]).collect();
        for z in 0..dims[2] {
            let first = z.saturating_sub(1);
            let mut window: [&[T]; 4] = [&[]; 4];
            for (i, s) in slices[first..(z + 3).min(dims[2])].iter().enumerate() {
                window[i] = s;
            }
            let field = Field {
                dims,
                steps: Steps::new([0.7, 1.0, 2.5]),
                slices: window,
                first,
            };
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    visit(&field, [x, y, z]);
                }
            }
        }
    }

    /// On a small pseudo-random volume with uneven spacing, every edge whose ends are both inside
    /// the grid in x and y gets from its row's [`InteriorRow::pair`] exactly, to the bit, the two
    /// gradients the general [`Field::gradient32`] gives, one-sided in z on the first and last
    /// slices; every other edge is left to the general path.
    /// In `f32`, and in `i16` and `u8` over nearly their whole ranges, whose differences the
    /// pair converts in one vector.
    #[test]
    fn row_pairs_match_the_general_gradient() {
        // Seven slices, and two: there every row is on the first or the last.
        for dims in [[6, 5, 7], [6, 5, 2]] {
            let noise = noise(dims, 1.0);
            row_pairs_match::<f32>(dims, noise.iter().map(|&v| v as f32).collect());
            // The noise mapped onto `lo..=hi`.
            let spread = |lo: f64, hi: f64| {
                let (min, max) = noise
                    .iter()
                    .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
                noise
                    .iter()
                    .map(move |&v| lo + (v - min) / (max - min) * (hi - lo))
            };
            row_pairs_match::<i16>(dims, spread(-32768.0, 32767.0).map(|v| v as i16).collect());
            row_pairs_match::<u8>(dims, spread(0.0, 255.0).map(|v| v as u8).collect());
        }
    }

    fn row_pairs_match<T: crate::Scalar>(dims: [usize; 3], data: Vec<T>) {
        let mut checked = 0;
        sweep(&data, dims, |field, p| {
            checked += check::<T, 0>(field, p) + check::<T, 1>(field, p) + check::<T, 2>(field, p);
        });
        // Edges with both ends inside in x and y, along each axis: in x and y, starts from 1 to
        // `n - 3` (`n - 4` along the edge), and in z all starts (but the last along the edge).
        let [nx, ny, nz] = dims;
        let along = |axis: usize| {
            let e = |d: usize| usize::from(d == axis);
            (nx - 2 - e(0)) * (ny - 2 - e(1)) * (nz - e(2))
        };
        assert_eq!(checked, along(0) + along(1) + along(2));
    }

    /// A normal is the negated gradient interpolated at the crossing, `(1 − t) · g_a + t · g_b`
    /// normalised, whatever weights make it: on a pseudo-random volume with uneven spacing, every
    /// edge at two levels (a third and four fifths of the way along, which a swap of the weights
    /// would tell apart), against the interpolation done in `f64` from `t`, within `f32`
    /// rounding. Edges whose interpolated gradient nearly cancels are left out: there a last-bit
    /// difference in the weights turns the direction.
    #[test]
    fn normals_interpolate_the_gradients_at_the_crossing() {
        let dims = [6, 5, 7];
        let data = noise(dims, 1.0);
        let mut checked = 0;
        sweep(&data, dims, |field, p| {
            checked += crossing_normals::<0>(field, p)
                + crossing_normals::<1>(field, p)
                + crossing_normals::<2>(field, p);
        });
        assert!(checked > 1000, "{checked} of 1,046 edge levels checked");
    }

    fn crossing_normals<const AXIS: usize>(field: &Field<'_, f64>, p: [usize; 3]) -> usize {
        let mut q = p;
        q[AXIS] += 1;
        if q[AXIS] >= field.dims[AXIS] {
            return 0;
        }
        let sample = |p: [usize; 3]| field.slice(p[2])[p[0] + field.dims[0] * p[1]];
        let (a, b) = (sample(p), sample(q));
        if a == b {
            return 0;
        }
        let wide = |p| field.gradient(p, |a, b, s| (b - a) * s);
        let (ga, gb) = (wide(p), wide(q));
        let plane = field.interior_plane::<AXIS>(p[2], true);
        let row = plane.as_ref().and_then(|plane| plane.row(p[1]));
        let mut checked = 0;
        for t in [1.0 / 3.0, 0.8] {
            let g: [f64; 3] = core::array::from_fn(|d| ga[d] + t * (gb[d] - ga[d]));
            let length = g.iter().map(|c| c * c).sum::<f64>().sqrt();
            let scale = ga.iter().chain(&gb).map(|c| c.abs()).sum::<f64>();
            if length < 0.05 * scale {
                continue;
            }
            let n = field.normal::<AXIS>(row, p, (a, b), a + t * (b - a)).unit();
            for d in 0..3 {
                let want = -g[d] / length;
                assert!(
                    (f64::from(n[d]) - want).abs() < 1e-5,
                    "{p:?} along {AXIS} at t = {t}: {n:?}, want {g:?} normalised and negated"
                );
            }
            checked += 1;
        }
        checked
    }

    /// Scaling a volume by 1e30 or 1e-30 takes its gradients out of `f32`'s range (their squared
    /// lengths over- or underflow), and the normals, then computed in `f64`, are still those of
    /// the unscaled volume, computed in `f32`, within `f32` rounding; every one has unit length.
    #[test]
    fn normals_do_not_depend_on_the_data_scale() {
        let dims = [6, 5, 7];
        let normals = |scale: f64| {
            let data = noise(dims, scale);
            let mut out = Vec::new();
            sweep(&data, dims, |field, p| {
                out.extend(normal::<0>(field, p));
                out.extend(normal::<1>(field, p));
                out.extend(normal::<2>(field, p));
            });
            out
        };
        let unscaled = normals(1.0);
        assert_eq!(unscaled.len(), 5 * 5 * 7 + 6 * 4 * 7 + 6 * 5 * 6);
        for scale in [1e30, 1e-30] {
            for (n, m) in normals(scale).iter().zip(&unscaled) {
                let length = n.iter().map(|c| c * c).sum::<f32>().sqrt();
                assert!((length - 1.0).abs() < 1e-6, "{n:?} at scale {scale}");
                for d in 0..3 {
                    assert!((n[d] - m[d]).abs() < 1e-6, "{n:?} against {m:?} at {scale}");
                }
            }
        }
    }

    /// Scaled four at a time or one at a time, and in `(z, y, x)` order, directions give the same
    /// bits, whatever their number (whole fours and a remainder) and lengths (from tiny to huge,
    /// as long as the squared length is a normal `f32`).
    #[test]
    fn units_are_unit_bit_for_bit() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 - 0.5
        };
        for len in 0..=9 {
            for scale in [1e-15, 1e-3, 1.0, 7.0, 1e15] {
                let ds: Vec<[f32; 3]> = (0..len)
                    .map(|_| [next(), next(), next()].map(|c| c * scale))
                    .collect();
                let mut batch = ds.clone();
                units(&mut batch);
                for (d, n) in ds.iter().zip(&batch) {
                    assert!(scalable(squared(*d)), "{d:?}");
                    assert_eq!(unit(*d).map(f32::to_bits), n.map(f32::to_bits), "{d:?}");
                    let [x, y, z] = *d;
                    let [nx, ny, nz] = unit([z, y, x]);
                    assert_eq!([nz, ny, nx].map(f32::to_bits), n.map(f32::to_bits), "{d:?}");
                    let length = squared(*n).sqrt();
                    assert!((length - 1.0).abs() < 1e-6, "{n:?} from {d:?}");
                }
            }
        }
    }

    /// The normal a vertex pass gives the edge from `p` along `AXIS`, a third of the way along
    /// (samples 1 and −2, level 0).
    fn normal<const AXIS: usize>(field: &Field<'_, f64>, p: [usize; 3]) -> Option<[f32; 3]> {
        (p[AXIS] + 1 < field.dims[AXIS]).then(|| {
            let plane = field.interior_plane::<AXIS>(p[2], true);
            let row = plane.as_ref().and_then(|plane| plane.row(p[1]));
            field.normal::<AXIS>(row, p, (1.0, -2.0), 0.0).unit()
        })
    }

    fn check<T: crate::Scalar, const AXIS: usize>(field: &Field<'_, T>, p: [usize; 3]) -> usize {
        let mut q = p;
        q[AXIS] += 1;
        if q[AXIS] >= field.dims[AXIS] {
            return 0;
        }
        let inside = |c: [usize; 3]| (0..2).all(|d| c[d] >= 1 && c[d] + 1 < field.dims[d]);
        let plane = field.interior_plane::<AXIS>(p[2], true);
        let pair = plane
            .as_ref()
            .and_then(|plane| plane.row(p[1]))
            .and_then(|r| r.pair(p[0]));
        assert_eq!(pair.is_some(), inside(p) && inside(q), "{p:?} along {AXIS}");
        let Some((ga, gb)) = pair else { return 0 };
        let bits = |g: f32x4| g.to_array().map(f32::to_bits);
        assert_eq!(bits(ga), bits(field.gradient32(p)), "{p:?} along {AXIS}");
        assert_eq!(bits(gb), bits(field.gradient32(q)), "{p:?} along {AXIS}");
        1
    }
}
