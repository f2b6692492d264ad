//! Built-in volumes: the paper's knotted torus (SPEC §8) and simple solids, needing no files.
//!
//! Every volume is filled inside its solid and empty on its border, so the surface is closed.

use std::vec::Vec;

/// A generated volume with the iso value and world placement it is meant for.
#[derive(Clone, Debug, PartialEq)]
pub struct DemoVolume {
    /// Samples, x fastest.
    pub data: Vec<f64>,
    /// `[nx, ny, nz]`.
    pub dims: [usize; 3],
    /// The surface level.
    pub iso: f64,
    /// World distance between samples.
    pub spacing: [f64; 3],
    /// World position of sample `(0, 0, 0)`.
    pub origin: [f64; 3],
}

impl DemoVolume {
    fn sample(n: usize, lo: f64, hi: f64, iso: f64, f: impl Fn(f64, f64, f64) -> f64) -> Self {
        let step = (hi - lo) / n as f64;
        let coord = |i: usize| lo + step * (i as f64 + 0.5);
        let mut data = Vec::with_capacity(n * n * n);
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    data.push(f(coord(x), coord(y), coord(z)));
                }
            }
        }
        DemoVolume {
            data,
            dims: [n; 3],
            iso,
            spacing: [step; 3],
            origin: [coord(0); 3],
        }
    }
}

/// The paper's knotted torus `sin(π·(k1² + k2²)^(1/6)) = 0.9`, sampled cell-centred on `n³`
/// points over `[-3.4, 3.4]³`. At `n = 64` this is exactly the volume of the paper's Table 1.
pub fn knot(n: usize) -> DemoVolume {
    DemoVolume::sample(n, -3.4, 3.4, 0.9, knot_field)
}

/// The knot's scalar field at a world point (SPEC §8).
pub fn knot_field(x: f64, y: f64, z: f64) -> f64 {
    let rho2 = x * x + y * y + z * z;
    let d = rho2 + 1.0;
    let (p, q, r, s) = (2.0 * x / d, 2.0 * y / d, 2.0 * z / d, (rho2 - 1.0) / d);
    let k1 = p * p - q * q + r * r * r - 3.0 * r * s * s;
    let k2 = 2.0 * p * q - 3.0 * r * r * s + s * s * s;
    (core::f64::consts::PI * (k1 * k1 + k2 * k2).powf(1.0 / 6.0)).sin()
}

/// A ball of radius 0.8 in `[-1, 1]³`, as signed distance (positive inside).
pub fn sphere(n: usize) -> DemoVolume {
    DemoVolume::sample(n, -1.0, 1.0, 0.0, |x, y, z| {
        0.8 - (x * x + y * y + z * z).sqrt()
    })
}

/// A ring torus (radii 0.6 and 0.25) around the z axis in `[-1, 1]³` (positive inside).
pub fn torus(n: usize) -> DemoVolume {
    DemoVolume::sample(n, -1.0, 1.0, 0.0, |x, y, z| {
        let ring = (x * x + y * y).sqrt() - 0.6;
        0.25 - (ring * ring + z * z).sqrt()
    })
}

/// The ball with deterministic per-sample noise of amplitude 0.05: a rough surface with many small
/// features, the kind real scans have. The border stays empty.
pub fn sphere_noise(n: usize) -> DemoVolume {
    let mut v = sphere(n);
    let [nx, ny, nz] = v.dims;
    for (i, f) in v.data.iter_mut().enumerate() {
        let (x, y, z) = (i % nx, (i / nx) % ny, i / (nx * ny));
        let border = x == 0 || y == 0 || z == 0 || x == nx - 1 || y == ny - 1 || z == nz - 1;
        *f = if border {
            -1.0
        } else {
            *f + 0.05 * unit_noise(i as u64)
        };
    }
    v
}

/// Deterministic noise in `[-1, 1)` (splitmix64), so demos need no random-number crate.
fn unit_noise(i: u64) -> f64 {
    let mut z = i.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}
