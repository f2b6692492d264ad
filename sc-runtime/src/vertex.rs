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

/// Reads samples and gradients around grid points of the slices a sweep step can see.
pub(crate) struct Field<'v, T> {
    pub dims: [usize; 3],
    /// [`Field::steps`] of the grid's spacing.
    pub steps: [[f64; 2]; 3],
    /// Slices `z - 1`, `z`, `z + 1` as available, by `z`.
    pub slices: [&'v [T]; 4],
    pub first: usize,
}

impl<T: Scalar> Field<'_, T> {
    #[inline]
    fn slice(&self, z: usize) -> &[T] {
        self.slices[z - self.first]
    }

    /// Central differences inside, one-sided at the border, divided by spacing. Each axis
    /// reads its two samples straight from their slices: the normals pass calls this twice per
    /// vertex, and a general "sample at point" lookup cost as much as the rest of the sweep.
    /// Differences are multiplied by the reciprocal step ([`Field::steps`]): nine divisions per
    /// vertex were most of what normals cost.
    #[inline(always)]
    pub fn gradient(&self, p: [usize; 3]) -> [f64; 3] {
        let [x, y, z] = p;
        let [nx, ny, nz] = self.dims;
        if (1..nx - 1).contains(&x) && (1..ny - 1).contains(&y) && (1..nz - 1).contains(&z) {
            // Inside, as nearly every vertex's ends are: the general case below, unrolled.
            let i = nx * y + x;
            let (here, below, above) = (self.slice(z), self.slice(z - 1), self.slice(z + 1));
            let d = |a: T, b: T, axis: usize| (b.to_f64() - a.to_f64()) * self.steps[axis][1];
            return [
                d(here[i - 1], here[i + 1], 0),
                d(here[i - nx], here[i + nx], 1),
                d(below[i], above[i], 2),
            ];
        }
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

    /// The outward unit normal at `t` along the edge from `p` along `axis`: the negated,
    /// interpolated gradient, or the edge direction where the gradient vanishes or is NaN.
    pub fn normal(&self, p: [usize; 3], axis: usize, t: f64, a_filled: bool) -> [f32; 3] {
        let mut q = p;
        q[axis] += 1;
        let (ga, gb) = (self.gradient(p), self.gradient(q));
        let g: [f64; 3] = core::array::from_fn(|d| -(ga[d] + t * (gb[d] - ga[d])));
        let len = libm::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        if len > 0.0 && len.is_finite() {
            let inv = 1.0 / len;
            g.map(|c| (c * inv) as f32)
        } else {
            let mut n = [0.0; 3];
            n[axis] = if a_filled { 1.0 } else { -1.0 };
            n
        }
    }
}
