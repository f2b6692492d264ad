//! Test volumes: analytic solids, noise, single cube cases, hand-built configurations for each
//! embedded-mode rule, and small crops of real scans (committed under `tests/data/`, embedded
//! with `include_bytes!` so no test reads outside the crate).

use std::ops::Range;

use sc_runtime::demo::DemoVolume;
use sc_runtime::{Mesh, Mode, Params, Scalar, Volume};

use crate::reference::Field;

/// A scalar type the runtime reads, converted exactly to `f64` for the reference.
pub trait Sample: Scalar + PartialOrd + std::fmt::Debug {
    /// The value as `f64` (exact for every supported type).
    fn as_f64(self) -> f64;
    /// The smallest value: below any iso the tests use, so it pads with empty samples.
    const LOWEST: Self;
}

macro_rules! sample {
    ($($t:ty),*) => {$(
        impl Sample for $t {
            fn as_f64(self) -> f64 { self as f64 }
            const LOWEST: Self = <$t>::MIN;
        }
    )*};
}
sample!(u8, i8, u16, i16, u32, i32, f32, f64);

/// A volume with everything an extraction needs.
#[derive(Clone, Debug)]
pub struct Vol<T> {
    /// Samples, x fastest.
    pub data: Vec<T>,
    /// `[nx, ny, nz]`.
    pub dims: [usize; 3],
    /// Surface level.
    pub iso: f64,
    /// World distance between samples.
    pub spacing: [f64; 3],
    /// World position of sample 0.
    pub origin: [f64; 3],
}

impl<T: Sample> Vol<T> {
    /// Unit spacing, zero origin.
    pub fn new(data: Vec<T>, dims: [usize; 3], iso: f64) -> Self {
        assert_eq!(data.len(), dims.iter().product::<usize>());
        Vol {
            data,
            dims,
            iso,
            spacing: [1.0; 3],
            origin: [0.0; 3],
        }
    }

    /// The same volume as the reference sees it.
    pub fn field(&self) -> Field {
        Field {
            values: self.data.iter().map(|&v| v.as_f64()).collect(),
            dims: self.dims,
            iso: self.iso,
            spacing: self.spacing,
            origin: self.origin,
        }
    }

    /// Runtime parameters for `mode`, normals on.
    pub fn params(&self, mode: Mode) -> Params {
        Params {
            mode,
            spacing: self.spacing,
            origin: self.origin,
            ..Params::new(self.iso)
        }
    }

    /// The runtime's mesh on one thread.
    pub fn extract(&self, mode: Mode) -> Mesh {
        let vol = Volume::new(&self.data, self.dims).expect("consistent test volume");
        sc_runtime::extract(&vol, &self.params(mode)).expect("extraction succeeds")
    }

    /// The volume surrounded by a one-sample border of `empty` (which must be below iso), so the
    /// surface is closed. The origin moves so the original samples keep their world positions.
    pub fn padded(&self, empty: T) -> Vol<T> {
        let empty_below = empty.as_f64().partial_cmp(&self.iso)
            != Some(std::cmp::Ordering::Greater)
            && empty.as_f64() != self.iso;
        assert!(empty_below, "padding must be empty");
        let [nx, ny, nz] = self.dims;
        let d = [nx + 2, ny + 2, nz + 2];
        let mut data = vec![empty; d[0] * d[1] * d[2]];
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    data[(x + 1) + d[0] * ((y + 1) + d[1] * (z + 1))] =
                        self.data[x + nx * (y + ny * z)];
                }
            }
        }
        Vol {
            data,
            dims: d,
            iso: self.iso,
            spacing: self.spacing,
            origin: [0, 1, 2].map(|i| self.origin[i] - self.spacing[i]),
        }
    }

    /// The sample at a grid point.
    pub fn at(&self, p: [usize; 3]) -> T {
        self.data[p[0] + self.dims[0] * (p[1] + self.dims[1] * p[2])]
    }

    /// Sets the sample at a grid point.
    pub fn set(&mut self, p: [usize; 3], v: T) {
        let i = p[0] + self.dims[0] * (p[1] + self.dims[1] * p[2]);
        self.data[i] = v;
    }

    /// All grid points, x fastest.
    pub fn points(&self) -> impl Iterator<Item = [usize; 3]> + use<T> {
        let [nx, ny, nz] = self.dims;
        (0..nz).flat_map(move |z| (0..ny).flat_map(move |y| (0..nx).map(move |x| [x, y, z])))
    }

    /// World position of a grid point.
    pub fn world(&self, p: [usize; 3]) -> [f64; 3] {
        [0, 1, 2].map(|d| self.origin[d] + p[d] as f64 * self.spacing[d])
    }

    /// Whether a sample is filled (SPEC §1).
    pub fn filled(&self, p: [usize; 3]) -> bool {
        self.at(p).as_f64() >= self.iso
    }
}

/// A demo volume from `sc_runtime::demo` (their borders are empty).
pub fn demo(v: DemoVolume) -> Vol<f64> {
    Vol {
        data: v.data,
        dims: v.dims,
        iso: v.iso,
        spacing: v.spacing,
        origin: v.origin,
    }
}

/// A field sampled at integer grid points of an `n³` grid.
pub fn sampled(dims: [usize; 3], iso: f64, f: impl Fn(f64, f64, f64) -> f64) -> Vol<f64> {
    let mut data = Vec::with_capacity(dims.iter().product());
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                data.push(f(x as f64, y as f64, z as f64));
            }
        }
    }
    Vol::new(data, dims, iso)
}

/// Two balls of radius `r` whose centres are `2r` apart along x: they touch at one point, the
/// hardest case for a surface that must stay a manifold. Signed distance to the union, positive
/// inside, on an `n³` grid with unit spacing.
pub fn touching_spheres(n: usize, r: f64) -> Vol<f64> {
    let c = (n as f64 - 1.0) / 2.0;
    let (c1, c2) = ([c - r, c, c], [c + r, c, c]);
    sampled([n; 3], 0.0, |x, y, z| {
        let d = |q: [f64; 3]| ((x - q[0]).powi(2) + (y - q[1]).powi(2) + (z - q[2]).powi(2)).sqrt();
        (r - d(c1)).max(r - d(c2))
    })
}

/// splitmix64: deterministic noise without a random-number crate.
pub fn splitmix(i: u64) -> u64 {
    let mut z = i.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Independent labels in `0..labels` per sample: the most junctions a label volume can have.
pub fn label_noise(dims: [usize; 3], labels: u64, seed: u64) -> Vec<u16> {
    let n = dims.iter().product::<usize>();
    (0..n)
        .map(|i| (splitmix(seed * 1_000_003 + i as u64) % labels) as u16)
        .collect()
}

/// The Voronoi cells of `count` random seeds as labels, every fourth cell the background 0:
/// regions large enough for Step 4 to merge, with junction curves between them.
pub fn voronoi_labels(dims: [usize; 3], count: u64, seed: u64) -> Vec<u16> {
    let seeds: Vec<[f64; 3]> = (0..count)
        .map(|s| {
            [0, 1, 2].map(|a| {
                (splitmix(seed * 7919 + s * 3 + a as u64) % 10_000) as f64 / 10_000.0
                    * dims[a] as f64
            })
        })
        .collect();
    let mut data = vec![];
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let p = [x as f64, y as f64, z as f64];
                let d = |s: &[f64; 3]| (0..3).map(|a| (s[a] - p[a]).powi(2)).sum::<f64>();
                let best = (0..seeds.len())
                    .min_by(|&a, &b| d(&seeds[a]).total_cmp(&d(&seeds[b])))
                    .unwrap();
                data.push(if best % 4 == 3 { 0 } else { 1 + best as u16 });
            }
        }
    }
    data
}

/// The samples of the box `r` (per axis) of a volume of `dims`, copied out, x fastest.
pub fn sub_box<T: Copy>(data: &[T], dims: [usize; 3], r: &[Range<usize>; 3]) -> Vec<T> {
    let [nx, ny, _] = dims;
    let mut out = Vec::with_capacity(r.iter().map(|r| r.len()).product());
    for z in r[2].clone() {
        for y in r[1].clone() {
            out.extend_from_slice(&data[nx * (y + ny * z)..][r[0].clone()]);
        }
    }
    out
}

/// The blocks of a grid of `cubes` cubes per axis between consecutive cuts (cube indices; those
/// outside `1 .. cubes` are ignored), x fastest.
pub fn blocks_between(cubes: [usize; 3], cuts: &[Vec<usize>; 3]) -> Vec<[Range<usize>; 3]> {
    let ranges: Vec<Vec<Range<usize>>> = (0..3)
        .map(|d| {
            let mut ends = vec![0];
            ends.extend(cuts[d].iter().copied().filter(|&c| c > 0 && c < cubes[d]));
            ends.push(cubes[d]);
            ends.windows(2).map(|w| w[0]..w[1]).collect()
        })
        .collect();
    let mut out = Vec::new();
    for z in &ranges[2] {
        for y in &ranges[1] {
            for x in &ranges[0] {
                out.push([x.clone(), y.clone(), z.clone()]);
            }
        }
    }
    out
}

/// Integer noise in `0..levels` at an integer iso in the middle: many samples equal iso exactly,
/// the SPEC §1 tie case (every third sample or so when `levels` is 3).
pub fn integer_noise(dims: [usize; 3], levels: u8, seed: u64) -> Vol<u8> {
    let data = (0..dims.iter().product::<usize>())
        .map(|i| (splitmix(seed ^ (i as u64) << 8) % u64::from(levels)) as u8)
        .collect();
    Vol::new(data, dims, f64::from(levels / 2))
}

/// A 5³ grid of zeros with one cube of the given case at the offset that gives it parity class
/// `class`: the cube's corners are the only possibly filled samples, so the border is empty.
pub fn single_case(case: u8, class: u8) -> Vol<u8> {
    let mut v = Vol::new(vec![0u8; 125], [5; 3], 1.0);
    // Offset 2 is even, offset 1 odd.
    let off = [0, 1, 2].map(|d| if class >> d & 1 == 1 { 1 } else { 2 });
    for c in 0..8u8 {
        if case >> c & 1 == 1 {
            let p = [0, 1, 2].map(|d| off[d] + usize::from(c >> d & 1));
            v.set(p, 1);
        }
    }
    v
}

/// A bare 2×2×2 grid holding one case (class 0, the cube touches the grid border).
pub fn bare_case(case: u8) -> Vol<u8> {
    Vol::new(
        (0..8).map(|c| u8::from(case >> c & 1 == 1)).collect(),
        [2; 3],
        1.0,
    )
}

/// A `dims` grid of zeros with the listed points set to one, at iso 1.
pub fn points(dims: [usize; 3], filled: &[[usize; 3]]) -> Vol<u8> {
    let mut v = Vol::new(vec![0u8; dims.iter().product()], dims, 1.0);
    for &p in filled {
        v.set(p, 1);
    }
    v
}

fn le_u16(b: &[u8]) -> Vec<i16> {
    b.chunks_exact(2)
        .map(|c| i16::from_le_bytes([c[0], c[1]]))
        .collect()
}

/// brainsmall-mri, 40×40×30 crop (u8), at iso 20: 592 samples equal the iso exactly.
pub fn brainsmall_crop() -> Vol<u8> {
    let b = include_bytes!("../data/brainsmall-crop-40x40x30.u8.raw");
    Vol::new(b.to_vec(), [40, 40, 30], 20.0)
}

/// stent-ct, 40×40×30 crop (i16), at the given iso (281 suggested; 250 is a quantisation level
/// 1,991 samples equal).
pub fn stent_crop(iso: f64) -> Vol<i16> {
    let b = include_bytes!("../data/stent-crop-40x40x30.i16.raw");
    Vol::new(le_u16(b), [40, 40, 30], iso)
}

/// itk-t1-mri, 40×40×30 crop (i16) with its anisotropic spacing 2, 2, 3, at iso 20.
pub fn itk_t1_crop() -> Vol<i16> {
    let b = include_bytes!("../data/itk-t1-crop-40x40x30.i16.raw");
    let mut v = Vol::new(le_u16(b), [40, 40, 30], 20.0);
    v.spacing = [2.0, 2.0, 3.0];
    v
}
