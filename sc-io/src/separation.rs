//! Which samples a mesh leaves on the wrong side: `wrong_side_samples` in `--stats-json`, the
//! separation adaptive mode keeps unless `--allow-wrong-side` waives it (docs/adaptive.md §6),
//! and which embedded mode's merges can give up too.
//!
//! A sample's side by the mesh is the parity of the mesh's crossings along the ray in −x from
//! it; its side by the data is SPEC §1's filled test (`value >= iso`, NaN empty). The rays of a
//! row of samples are one line, so each triangle is rasterised once onto the rows its y–z
//! projection covers, each row's crossings sorted, and the row's samples walked against them:
//! one sweep of the volume, plus work in proportion to the rows the triangles cover.
//!
//! **Exact parity.** Positions are taken back to grid units (`(p − origin) / spacing`) and
//! rounded to multiples of 2⁻²⁰ grid steps, once per vertex, so that every triangle sees the
//! same corners; which rows a triangle covers is then decided exactly, in integers. A row is
//! moved off the lattice symbolically, to `(y + ε, z + ε²)`: it passes through no vertex and
//! along no edge of the projection, so it meets a closed mesh an even number of times and every
//! sample's parity is exact. Most vertices of a Steps 1–3 mesh lie on such rows (a vertex on an
//! x edge has integer y and z), so the rule is needed, not a corner case.
//!
//! **Samples on the surface** are on neither side, and never count. SPEC §1's clamp keeps the
//! extractor's vertices 1/1024 grid step off every sample, and adaptive mode's (P) keeps its
//! triangles 10⁻³ step off them, but a chord of `--allow-wrong-side`, or a merge of embedded
//! mode, can pass exactly through samples. Whether a sample lies on a triangle is decided exactly too, faces parallel to x included;
//! so is where each crossing lies against the samples.

use sc_runtime::{Mesh, Params, Scalar, Volume};

/// The figure's name in every front end's statistics (`--stats-json`, Python's `stats`).
pub const WRONG_SIDE_SAMPLES: &str = "wrong_side_samples";

/// Fraction bits of the fixed-point grid coordinates: 2⁻²⁰ grid steps, as fine as an `f32`
/// position is from 8 grid steps out, while the exact tests stay within `i128` for grids of up
/// to 2³⁰ samples a side and triangles up to 2²⁰ steps across.
const FRAC: u32 = 20;
const ONE: i64 = 1 << FRAC;

/// The samples of `volume` on the wrong side of `mesh`, whose positions were placed with
/// `params.spacing` and `params.origin` (the extractor's own placement) and whose samples are
/// filled at `params.iso`; `None` if a sample on the volume's border is filled.
///
/// The mesh must be closed (every side in an even number of triangles), as the extractor's
/// surface is when every border sample is empty (`--pad` makes it so); where a border sample is
/// filled that surface is open, a sample's side by it is not defined, and nothing is counted.
/// Orientation and self-intersections do not matter: the side is a parity.
pub fn wrong_side_samples<T: Scalar>(
    volume: &Volume<'_, T>,
    params: &Params,
    mesh: &Mesh,
) -> Option<u64> {
    let [nx, ny, nz] = volume.dims();
    if nx * ny * nz == 0 {
        return Some(0);
    }
    let data = volume.data();
    let threshold = T::threshold(params.iso);
    let mut filled = vec![0u8; nx];
    let row = |y: usize, z: usize| &data[(z * ny + y) * nx..][..nx];
    // The border: both end samples of every row, and every sample of the rows on the y and z
    // faces.
    for z in 0..nz {
        for y in 0..ny {
            let r = row(y, z);
            if y == 0 || z == 0 || y + 1 == ny || z + 1 == nz {
                T::classify_row(r, threshold, &mut filled);
                if filled.contains(&1) {
                    return None;
                }
            } else if r[0].filled(threshold) || r[nx - 1].filled(threshold) {
                return None;
            }
        }
    }
    let crossings = Crossings::new(mesh, params, [nx, ny, nz]);
    let count = |flags: &[u8]| flags.iter().map(|&f| u64::from(f)).sum::<u64>();
    let mut on = crossings.on.iter().peekable();
    let mut wrong = 0u64;
    for z in 0..nz {
        for y in 0..ny {
            let r = y + ny * z;
            T::classify_row(row(y, z), threshold, &mut filled);
            let xs = crossings.row(r);
            // The filled samples outside the mesh, and the empty ones inside: sample `x` is
            // inside where an odd number of crossings lie at or behind it, that is from
            // `⌈xs[2k]⌉` up to `⌈xs[2k + 1]⌉`, past it.
            wrong += count(&filled);
            for pair in xs.chunks(2) {
                let at = |i: usize| {
                    pair.get(i)
                        .map_or(nx, |&x| x.ceil().clamp(0.0, nx as f64) as usize)
                };
                let inside = &filled[at(0)..at(1).max(at(0))];
                wrong = wrong + inside.len() as u64 - 2 * count(inside);
            }
            // A sample on the surface is on neither side: take back any counted.
            while let Some(&(_, x)) = on.next_if(|&&(row, _)| row == r) {
                let inside = xs.partition_point(|&c| c <= x as f64) % 2 == 1;
                wrong -= u64::from(inside != (filled[x] == 1));
            }
        }
    }
    Some(wrong)
}

/// The x (in grid steps) of every crossing of the mesh with every row of samples, grouped by
/// row (`y + ny · z`) and sorted within each, and the samples on the surface.
struct Crossings {
    /// Where each row's crossings start in `xs`; one more entry than rows.
    start: Vec<usize>,
    xs: Vec<f64>,
    /// The samples on the surface, `(row, x)`, sorted, once each.
    on: Vec<(usize, usize)>,
}

impl Crossings {
    fn new(mesh: &Mesh, params: &Params, [nx, ny, nz]: [usize; 3]) -> Crossings {
        let grid: Vec<[f64; 3]> = mesh
            .positions
            .iter()
            .map(|p| {
                std::array::from_fn(|d| (f64::from(p[d]) - params.origin[d]) / params.spacing[d])
            })
            .collect();
        let fixed: Vec<[i64; 3]> = grid
            .iter()
            .map(|g| g.map(|c| (c * ONE as f64).round() as i64))
            .collect();
        let mut found: Vec<(usize, f64)> = Vec::new();
        let mut on: Vec<(usize, usize)> = Vec::new();
        for t in &mesh.triangles {
            let p = t.map(|i| fixed[i as usize]);
            let [a, b, c] = p.map(|v| [v[1], v[2]]);
            let area = det(a, b, c);
            // The rows its closed projection covers, within the grid.
            let span = |d: usize, n: usize| {
                let lo = p.iter().map(|v| v[d]).min().unwrap_or(0);
                let hi = p.iter().map(|v| v[d]).max().unwrap_or(-1);
                ceil_steps(lo).max(0)..=floor_steps(hi).min(n as i64 - 1)
            };
            for z in span(2, nz) {
                for y in span(1, ny) {
                    let q = [y * ONE, z * ONE];
                    let row = y as usize + ny * z as usize;
                    if area == 0 {
                        // Parallel to x: no moved row crosses it, but samples can lie on it.
                        if let Some(xs) = along(p, q) {
                            let xs = (*xs.start()).max(0)..=(*xs.end()).min(nx as i64 - 1);
                            on.extend(xs.map(|x| (row, x as usize)));
                        }
                        continue;
                    }
                    // Barycentric weights at the row itself, exactly: of `area`'s sign where
                    // the closed triangle covers the row.
                    let w = [det(b, c, q), det(c, a, q), det(a, b, q)];
                    if w.iter().any(|&w| w != 0 && (w > 0) != (area > 0)) {
                        continue;
                    }
                    let x = (0..3)
                        .map(|k| float(w[k]) * grid[t[k] as usize][0])
                        .sum::<f64>()
                        / float(area);
                    // Where the crossing lies against the nearest sample: exactly where `x`,
                    // good to some 10⁻⁹ steps, cannot tell.
                    let near = x.round();
                    let past = if (x - near).abs() > 1e-6 {
                        if x > near { 1 } else { -1 }
                    } else {
                        (0..3)
                            .map(|k| w[k] * i128::from(p[k][0] - near as i64 * ONE))
                            .sum::<i128>()
                            * area.signum()
                    };
                    if past == 0 && (0.0..nx as f64).contains(&near) {
                        on.push((row, near as usize));
                    }
                    let s = [side(w[0], b, c), side(w[1], c, a), side(w[2], a, b)];
                    if s[0] == s[1] && s[1] == s[2] {
                        let x = match past.signum() {
                            0 => near,
                            1 if x <= near => near + 0.5,
                            -1 if x >= near => near - 0.5,
                            _ => x,
                        };
                        found.push((row, x));
                    }
                }
            }
        }
        // Grouped by row with a counting sort; each row then holds a handful.
        let mut start = vec![0usize; ny * nz + 1];
        for &(r, _) in &found {
            start[r + 1] += 1;
        }
        for r in 0..ny * nz {
            start[r + 1] += start[r];
        }
        let mut next = start.clone();
        let mut xs = vec![0.0; found.len()];
        for (r, x) in found {
            xs[next[r]] = x;
            next[r] += 1;
        }
        for r in 0..ny * nz {
            xs[start[r]..start[r + 1]].sort_unstable_by(f64::total_cmp);
        }
        on.sort_unstable();
        on.dedup();
        Crossings { start, xs, on }
    }

    fn row(&self, r: usize) -> &[f64] {
        &self.xs[self.start[r]..self.start[r + 1]]
    }
}

/// The samples `x` (integers, unbounded) at which the triangle `p`, whose projection has no
/// area, meets the row `q`: where the row lies on the projection of a side, the side meets the
/// row's line at one x (both ends, for a side along x), and the triangle meets it between the
/// least and the greatest of those.
fn along(p: [[i64; 3]; 3], q: [i64; 2]) -> Option<std::ops::RangeInclusive<i64>> {
    let (mut lo, mut hi) = (i64::MAX, i64::MIN);
    let mut meet = |num: i128, den: i128| {
        // `num / den` in fixed point, `den > 0`: the samples from its ceiling to its floor.
        let steps = den * i128::from(ONE);
        lo = lo.min(-((-num).div_euclid(steps)) as i64);
        hi = hi.max(num.div_euclid(steps) as i64);
    };
    for (e, f) in [(p[0], p[1]), (p[1], p[2]), (p[2], p[0])] {
        let (eu, fu) = ([e[1], e[2]], [f[1], f[2]]);
        if det(eu, fu, q) != 0 {
            continue;
        }
        if eu == fu {
            if eu == q {
                meet(e[0].into(), 1);
                meet(f[0].into(), 1);
            }
            continue;
        }
        // Along the coordinate in which the side's projection is longer.
        let d = if (f[1] - e[1]).abs() >= (f[2] - e[2]).abs() {
            1
        } else {
            2
        };
        let (s0, s1, sq) = (e[d], f[d], q[d - 1]);
        if sq < s0.min(s1) || sq > s0.max(s1) {
            continue;
        }
        let num =
            i128::from(e[0]) * i128::from(s1 - s0) + i128::from(f[0] - e[0]) * i128::from(sq - s0);
        let den = i128::from(s1 - s0);
        if den > 0 {
            meet(num, den);
        } else {
            meet(-num, -den);
        }
    }
    (lo <= hi).then_some(lo..=hi)
}

/// `v` as `f64`, through `i64` where it fits (nearly always: a triangle's weights are products
/// of its own sides), which is much cheaper than converting an `i128`.
fn float(v: i128) -> f64 {
    i64::try_from(v).map_or(v as f64, |v| v as f64)
}

/// `⌊v / ONE⌋` for a fixed-point `v`.
fn floor_steps(v: i64) -> i64 {
    v >> FRAC
}

/// `⌈v / ONE⌉` for a fixed-point `v`.
fn ceil_steps(v: i64) -> i64 {
    -((-v) >> FRAC)
}

/// Twice the signed area of `(a, b, q)` in the y–z plane, exactly.
fn det(a: [i64; 2], b: [i64; 2], q: [i64; 2]) -> i128 {
    let m = |u: i64, v: i64| i128::from(u) * i128::from(v);
    m(b[0] - a[0], q[1] - a[1]) - m(b[1] - a[1], q[0] - a[0])
}

/// The sign of `d = det(a, b, q)` with `q` moved to `(q_y + ε, q_z + ε²)`: the terms in ε and
/// ε² decide where `q` lies on the line through `a` and `b`. Zero only if `a` and `b` project
/// to one point.
fn side(d: i128, a: [i64; 2], b: [i64; 2]) -> i8 {
    let sign = |v: i128| v.signum() as i8;
    if d != 0 {
        sign(d)
    } else if b[1] != a[1] {
        // d/dε of (b_y − a_y)(q_z + ε² − a_z) − (b_z − a_z)(q_y + ε − a_y).
        sign(i128::from(a[1] - b[1]))
    } else {
        sign(i128::from(b[0] - a[0]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sc_runtime::{Mode, extract};

    /// A `n³` volume of zeros with the samples `ones` set to 1: filled at iso 1.
    fn volume(dims: [usize; 3], ones: &[[usize; 3]]) -> Vec<u8> {
        let mut v = vec![0u8; dims.iter().product()];
        for &[x, y, z] in ones {
            v[(z * dims[1] + y) * dims[0] + x] = 1;
        }
        v
    }

    fn count(data: &[u8], dims: [usize; 3], params: &Params, mesh: &Mesh) -> Option<u64> {
        wrong_side_samples(&Volume::new(data, dims).unwrap(), params, mesh)
    }

    /// The closed box `[lo, hi]³`, in grid units, as 12 triangles wound outward.
    fn cube(lo: f32, hi: f32) -> Mesh {
        let positions = (0..8)
            .map(|i| [i & 1, (i >> 1) & 1, i >> 2].map(|b| if b == 1 { hi } else { lo }))
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let triangles = quads
            .iter()
            .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
            .collect();
        Mesh {
            positions,
            triangles,
            ..Mesh::default()
        }
    }

    fn block(lo: usize, hi: usize) -> Vec<[usize; 3]> {
        let mut out = Vec::new();
        for z in lo..hi {
            for y in lo..hi {
                out.extend((lo..hi).map(|x| [x, y, z]));
            }
        }
        out
    }

    #[test]
    fn a_cube_around_filled_samples_separates_them() {
        let dims = [6; 3];
        let data = volume(dims, &block(2, 4));
        let params = Params::new(1.0);
        assert_eq!(count(&data, dims, &params, &cube(1.5, 3.5)), Some(0));
        // Around (3, 3, 3) alone: the other seven filled samples are outside.
        assert_eq!(count(&data, dims, &params, &cube(2.5, 3.5)), Some(7));
        // Around all 27 samples of [1, 3]³: 19 empty ones inside.
        assert_eq!(count(&data, dims, &params, &cube(0.5, 3.5)), Some(19));
        // No mesh: every filled sample is outside.
        assert_eq!(count(&data, dims, &params, &Mesh::default()), Some(8));
    }

    /// Faces, sides and corners through samples, every vertex on a row: a sample on the
    /// surface is on neither side, and the others are counted exactly.
    #[test]
    fn samples_on_the_surface_never_count() {
        let dims = [7; 3];
        let params = Params::new(1.0);
        // Filled [2, 4)³ has 26 samples on the box [2, 4]³, (3, 3, 3) inside.
        let data = volume(dims, &block(2, 4));
        assert_eq!(count(&data, dims, &params, &cube(2.0, 4.0)), Some(0));
        // Inside [2, 5]³: {3, 4}³, of which only (3, 3, 3) is filled.
        assert_eq!(count(&data, dims, &params, &cube(2.0, 5.0)), Some(7));
        assert_eq!(count(&data, dims, &params, &cube(1.0, 4.0)), Some(0));
        // Wound inward, the same.
        let mut inward = cube(2.0, 5.0);
        inward.triangles.iter_mut().for_each(|t| t.swap(1, 2));
        assert_eq!(count(&data, dims, &params, &inward), Some(7));
        // (3, 3, 3) at a corner of [3, 4]³, empty or filled.
        for ones in [vec![], vec![[3, 3, 3]]] {
            let data = volume(dims, &ones);
            assert_eq!(count(&data, dims, &params, &cube(3.0, 4.0)), Some(0));
            let inside = count(&data, dims, &params, &cube(2.5, 3.5));
            assert_eq!(inside, Some(u64::from(ones.is_empty())));
        }
    }

    /// A slanted face through samples: the tetrahedron `x, y, z ≥ 1, x + y + z ≤ 7` holds
    /// (2, 2, 2) alone; the samples of its faces, filled or not, never count.
    #[test]
    fn samples_on_a_slanted_face_never_count() {
        let dims = [8; 3];
        let params = Params::new(1.0);
        let tetrahedron = Mesh {
            positions: vec![[1.0; 3], [5.0, 1.0, 1.0], [1.0, 5.0, 1.0], [1.0, 1.0, 5.0]],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            ..Mesh::default()
        };
        let mut face = block(1, 6);
        face.retain(|p| {
            let sum = p.iter().sum::<usize>();
            sum == 7 || sum < 7 && p.contains(&1)
        });
        assert!(face.contains(&[2, 2, 3]) && face.contains(&[1, 4, 1]));
        for (ones, wrong) in [(vec![], 1), (vec![[2, 2, 2]], 0), (face.clone(), 1)] {
            let data = volume(dims, &ones);
            assert_eq!(
                count(&data, dims, &params, &tetrahedron),
                Some(wrong),
                "{ones:?}"
            );
        }
        face.push([2, 2, 2]);
        let data = volume(dims, &face);
        assert_eq!(count(&data, dims, &params, &tetrahedron), Some(0));
    }

    #[test]
    fn a_filled_border_sample_is_not_counted() {
        let dims = [5, 4, 3];
        for p in [
            [0, 1, 1],
            [4, 2, 1],
            [2, 0, 1],
            [2, 3, 1],
            [2, 1, 0],
            [2, 2, 2],
        ] {
            let data = volume(dims, &[p]);
            assert_eq!(
                count(&data, dims, &Params::new(1.0), &Mesh::default()),
                None
            );
        }
        let data = volume(dims, &[[2, 1, 1]]);
        assert_eq!(
            count(&data, dims, &Params::new(1.0), &Mesh::default()),
            Some(1)
        );
    }

    /// A small deterministic generator, so that failures repeat.
    struct Lcg(u64);

    impl Lcg {
        fn next(&mut self) -> u64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            self.0 >> 33
        }
    }

    /// Placement on a skewed lattice, to check that positions are taken back to grid units.
    fn placed(iso: f64, mode: Mode) -> Params {
        Params {
            mode,
            spacing: [0.5, 2.0, 3.0],
            origin: [1.0, -2.0, 5.0],
            normals: false,
            ..Params::new(iso)
        }
    }

    /// Every pattern of a 2×2×2 interior, at iso 1 on 0/1 samples (every vertex at the clamp,
    /// 1/1024 step from a filled sample): the Steps 1–3 mesh separates every sample, and filling
    /// one more sample puts exactly that one on the wrong side.
    #[test]
    fn steps123_separates_every_pattern_of_a_cube_and_one_more_sample_is_one() {
        let dims = [4; 3];
        let params = placed(1.0, Mode::Steps123);
        for case in 0..256usize {
            let ones: Vec<[usize; 3]> = (0..8)
                .filter(|i| case >> i & 1 == 1)
                .map(|i| [1 + (i & 1), 1 + (i >> 1 & 1), 1 + (i >> 2)])
                .collect();
            let data = volume(dims, &ones);
            let mesh = extract(&Volume::new(&data, dims).unwrap(), &params).unwrap();
            assert_eq!(count(&data, dims, &params, &mesh), Some(0), "case {case}");
            for i in (0..8).filter(|i| case >> i & 1 == 0) {
                let mut more = data.clone();
                more[((1 + (i >> 2)) * 4 + 1 + (i >> 1 & 1)) * 4 + 1 + (i & 1)] = 1;
                assert_eq!(
                    count(&more, dims, &params, &mesh),
                    Some(1),
                    "case {case} + {i}"
                );
            }
        }
    }

    /// Random padded volumes of floats (and NaN), in every mode whose surface keeps every
    /// sample's side: Steps 1–3 and adaptive mode by default. Flipping one sample's side adds
    /// one.
    #[test]
    fn random_volumes_are_separated_by_steps123_and_adaptive_meshes() {
        let mut rng = Lcg(49);
        for round in 0..60 {
            let dims = [5 + round % 4, 4 + round % 5, 5 + round % 3];
            let mut data = vec![0f32; dims.iter().product()];
            for z in 1..dims[2] - 1 {
                for y in 1..dims[1] - 1 {
                    for x in 1..dims[0] - 1 {
                        let r = rng.next() % 100;
                        data[(z * dims[1] + y) * dims[0] + x] =
                            if r == 0 { f32::NAN } else { r as f32 / 10.0 };
                    }
                }
            }
            let iso = 3.0 + (round % 5) as f64;
            for mode in [Mode::Steps123, Mode::Adaptive] {
                let params = placed(iso, mode);
                let volume = Volume::new(&data, dims).unwrap();
                let mesh = extract(&volume, &params).unwrap();
                let wrong = wrong_side_samples(&volume, &params, &mesh);
                assert_eq!(wrong, Some(0), "round {round}, {mode}");
                let mut flipped = data.clone();
                let at = (dims[1] + 1) * dims[0] + 1;
                flipped[at] = if flipped[at] >= iso as f32 { 0.0 } else { 10.0 };
                let volume = Volume::new(&flipped, dims).unwrap();
                let wrong = wrong_side_samples(&volume, &params, &mesh);
                assert_eq!(wrong, Some(1), "round {round}, {mode}");
            }
        }
    }
}
