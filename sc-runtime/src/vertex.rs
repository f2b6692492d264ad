//! Step 1's vertex placement and the optional normals (SPEC §1, §7).

use crate::Scalar;

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
    let (a, b) = (a.to_f64(), b.to_f64());
    if a.is_nan() || b.is_nan() {
        0.5
    } else {
        crossing(a, b, iso)
    }
}

/// The square root: `std`'s where it is linked, which compiles to one instruction the optimiser
/// sees through; `libm`'s (the same correctly rounded result) otherwise.
#[inline(always)]
fn sqrt(x: f64) -> f64 {
    #[cfg(feature = "std")]
    return x.sqrt();
    #[cfg(not(feature = "std"))]
    return libm::sqrt(x);
}

/// Reads samples and gradients around grid points of the slices a sweep step can see.
pub(crate) struct Field<'v, T> {
    pub dims: [usize; 3],
    /// [`Field::steps`] of the grid's spacing.
    pub steps: [[f64; 2]; 3],
    /// Slices `z - 1`, `z`, `z + 1` as available, by `z`.
    pub slices: [&'v [T]; 4],
    pub first: usize,
}

impl<'v, T: Scalar> Field<'v, T> {
    #[inline]
    fn slice(&self, z: usize) -> &[T] {
        self.slices[z - self.first]
    }

    /// Central differences inside, one-sided at the border, divided by spacing: for edges with
    /// an end on the grid's border, which [`InteriorRow::pair`] leaves here. Differences are
    /// multiplied by the reciprocal step ([`Field::steps`]): nine divisions per vertex were most
    /// of what normals cost.
    fn gradient(&self, p: [usize; 3]) -> [f64; 3] {
        let [x, y, z] = p;
        let [nx, ny, nz] = self.dims;
        let step = |c: usize, n: usize| (c.saturating_sub(1), (c + 1).min(n - 1));
        let diff = |a: f64, b: f64, lo: usize, hi: usize, d: usize| {
            (b - a) * self.steps[d][usize::from(hi - lo == 2)]
        };
        let here = self.slice(z);
        let row = nx * y;
        let (xl, xh) = step(x, nx);
        let gx = diff(here[row + xl].to_f64(), here[row + xh].to_f64(), xl, xh, 0);
        let (yl, yh) = step(y, ny);
        let gy = diff(
            here[nx * yl + x].to_f64(),
            here[nx * yh + x].to_f64(),
            yl,
            yh,
            1,
        );
        let (zl, zh) = step(z, nz);
        let gz = diff(
            self.slice(zl)[row + x].to_f64(),
            self.slice(zh)[row + x].to_f64(),
            zl,
            zh,
            2,
        );
        [gx, gy, gz]
    }

    /// Per axis, the reciprocals of the one-sided and the central difference's step.
    pub fn steps(spacing: [f64; 3]) -> [[f64; 2]; 3] {
        spacing.map(|s| [1.0 / s, 0.5 / s])
    }

    /// Row `y` of slice `z` for the normals of its edges along `AXIS`, if every such edge with
    /// both ends inside the grid has them inside in y and z too, and the slices hold whole
    /// planes: the tests of [`InteriorRow::pair`] that hold for a whole row, taken once per row
    /// (and not at all without `normals`).
    #[inline(always)]
    pub fn interior_row<const AXIS: usize>(
        &self,
        y: usize,
        z: usize,
        normals: bool,
    ) -> Option<InteriorRow<'_, 'v, T, AXIS>> {
        let [nx, ny, nz] = self.dims;
        let inside =
            |c: usize, n: usize, axis: usize| c >= 1 && c + 1 + usize::from(axis == AXIS) < n;
        // A pass's field starts one slice below the pass's `z` (see `Sweep::field`), so the
        // slices are in place: no per-vertex lookup. Slices past the grid are empty; x- and
        // y-edges do not read the fourth.
        if !(normals && inside(y, ny, 1) && inside(z, nz, 2) && z == self.first + 1) {
            return None;
        }
        let planes = if AXIS == 2 { 4 } else { 3 };
        let plane = nx.checked_mul(ny)?;
        let whole = self.slices[..planes].iter().all(|s| s.len() >= plane);
        whole.then_some(InteriorRow {
            field: self,
            start: nx * y,
        })
    }

    /// The outward unit normal at `t` along the edge from `p` along `AXIS`: the negated,
    /// interpolated gradient, or the edge direction where the gradient vanishes or is NaN.
    /// Inlined into each vertex pass: as a call it spilled the pass's registers, and brainsmall's
    /// normals cost 10 % more time.
    #[inline(always)]
    pub fn normal<const AXIS: usize>(
        &self,
        row: Option<InteriorRow<'_, '_, T, AXIS>>,
        p: [usize; 3],
        t: f64,
        a_filled: bool,
    ) -> [f32; 3] {
        let (ga, gb) = row.and_then(|r| r.pair(p[0])).unwrap_or_else(|| {
            let mut q = p;
            q[AXIS] += 1;
            (self.gradient(p), self.gradient(q))
        });
        // The gradient, not yet negated: the negation goes into the reciprocal length below, one
        // sign instead of three (and the same bits: a sign change is exact).
        let g: [f64; 3] = core::array::from_fn(|d| ga[d] + t * (gb[d] - ga[d]));
        // The test reads the squared length, not its root: a branch on the root would wait for
        // the square root's long latency, and that wait was a quarter of what normals cost.
        let squared = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        // Positive and finite (NaN fails), tested on the bits: positive finite doubles are the
        // bit patterns 1 ..= f64::MAX's, and one unsigned compare finds them. Written as two
        // float compares, the test compiled to a classification of the bits in 18 instructions
        // per vertex.
        if squared.to_bits().wrapping_sub(1) < f64::MAX.to_bits() {
            let inv = -1.0 / sqrt(squared);
            g.map(|c| (c * inv) as f32)
        } else {
            let mut n = [0.0; 3];
            n[AXIS] = if a_filled { 1.0 } else { -1.0 };
            n
        }
    }
}

/// A row of a [`Field`] whose edges along `AXIS` read their gradients' samples unchecked:
/// [`Field::interior_row`] made sure of the row and [`InteriorRow::pair`] makes sure of `x`. The
/// bounds checks of a dozen samples per vertex were a quarter of what normals cost.
#[derive(Clone, Copy)]
pub(crate) struct InteriorRow<'f, 'v, T, const AXIS: usize> {
    /// The field, each of whose slices that the row's edges read holds at least `nx · ny`
    /// samples.
    field: &'f Field<'v, T>,
    /// Where the row starts in a slice: `nx · y`, with `1 <= y` and `y + 2 < ny` (`y + 3` for
    /// y-edges).
    start: usize,
}

impl<T: Scalar, const AXIS: usize> InteriorRow<'_, '_, T, AXIS> {
    /// The gradients at both ends of the edge from `x` along `AXIS`, when both are inside the
    /// grid, as nearly all are. The arithmetic is [`Field::gradient`]'s, so the normals are the
    /// same to the bit.
    #[inline(always)]
    fn pair(&self, x: usize) -> Option<([f64; 3], [f64; 3])> {
        let Field {
            dims,
            steps,
            slices,
            ..
        } = self.field;
        let nx = dims[0];
        if !(x >= 1 && x + 1 + usize::from(AXIS == 0) < nx) {
            return None;
        }
        let i = self.start + x;
        // Called only with the indices below: each is `i` give or take at most `nx + 1` (up to
        // `2 · nx` above for y-edges), which the bounds on `x` above and on `y` in `start` keep
        // in `0..nx · ny`.
        // SAFETY: `0..nx · ny` is within every slice read (`Field::interior_row`).
        let at = |s: &[T], k: usize| unsafe { *s.get_unchecked(k) };
        let d = |s: &[T], lo: usize, t: &[T], hi: usize, axis: usize| {
            T::diff(at(s, lo), at(t, hi)) * steps[axis][1]
        };
        let [b, h, a, top] = *slices;
        let lower = [
            d(h, i - 1, h, i + 1, 0),
            d(h, i - nx, h, i + nx, 1),
            d(b, i, a, i, 2),
        ];
        Some(match AXIS {
            0 => (
                lower,
                [
                    d(h, i, h, i + 2, 0),
                    d(h, i + 1 - nx, h, i + 1 + nx, 1),
                    d(b, i + 1, a, i + 1, 2),
                ],
            ),
            1 => (
                lower,
                [
                    d(h, i + nx - 1, h, i + nx + 1, 0),
                    d(h, i, h, i + 2 * nx, 1),
                    d(b, i + nx, a, i + nx, 2),
                ],
            ),
            _ => (
                lower,
                [
                    d(a, i - 1, a, i + 1, 0),
                    d(a, i - nx, a, i + nx, 1),
                    d(h, i, top, i, 2),
                ],
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::Field;
    use alloc::vec::Vec;

    /// On a small pseudo-random volume with uneven spacing, every edge whose ends are both inside
    /// the grid gets from its row's [`InteriorRow::pair`] exactly, to the bit, the two gradients
    /// the general [`Field::gradient`] gives; every other edge is left to the general path.
    #[test]
    fn row_pairs_match_the_general_gradient() {
        let dims = [6, 5, 7];
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let data: Vec<f32> = (0..dims.iter().product())
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 40) as f32 / 7.0 - 1000.0
            })
            .collect();
        let plane = dims[0] * dims[1];
        let slices: Vec<&[f32]> = data.chunks(plane).collect();
        let mut checked = 0;
        for z in 0..dims[2] {
            // A sweep's view: slices `z - 1` to `z + 2`, as far as the grid goes.
            let first = z.saturating_sub(1);
            let mut window: [&[f32]; 4] = [&[]; 4];
            for (i, s) in slices[first..(z + 3).min(dims[2])].iter().enumerate() {
                window[i] = s;
            }
            let field = Field {
                dims,
                steps: Field::<f32>::steps([0.7, 1.0, 2.5]),
                slices: window,
                first,
            };
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let p = [x, y, z];
                    checked +=
                        check::<0>(&field, p) + check::<1>(&field, p) + check::<2>(&field, p);
                }
            }
        }
        // Edges with both ends inside: 3·3·5 along x, 4·2·5 along y and 4·3·4 along z.
        assert_eq!(checked, 45 + 40 + 48);
    }

    fn check<const AXIS: usize>(field: &Field<'_, f32>, p: [usize; 3]) -> usize {
        let mut q = p;
        q[AXIS] += 1;
        if q[AXIS] >= field.dims[AXIS] {
            return 0;
        }
        let inside = |c: [usize; 3]| (0..3).all(|d| c[d] >= 1 && c[d] + 1 < field.dims[d]);
        let pair = field
            .interior_row::<AXIS>(p[1], p[2], true)
            .and_then(|r| r.pair(p[0]));
        assert_eq!(pair.is_some(), inside(p) && inside(q), "{p:?} along {AXIS}");
        let Some((ga, gb)) = pair else { return 0 };
        let bits = |g: [f64; 3]| g.map(f64::to_bits);
        assert_eq!(bits(ga), bits(field.gradient(p)), "{p:?} along {AXIS}");
        assert_eq!(bits(gb), bits(field.gradient(q)), "{p:?} along {AXIS}");
        1
    }
}
