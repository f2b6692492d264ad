//! How far apart two meshes are: the distance from points of one to the nearest point of the
//! other, exact per point, found through a uniform grid of the other's triangles. Adaptive
//! mode's `--stats-json` reports its sampled symmetric distance to Steps 1–3 with it, and
//! `skelclimb render --color-by-error` colours triangles by it.

use std::collections::{HashMap, HashSet};

use sc_runtime::geometry::point_triangle_distance_squared;

type P = [f64; 3];

/// A mesh's triangles binned in a uniform grid, for nearest-point queries.
pub struct Nearest {
    tris: Vec<[P; 3]>,
    /// Each triangle's bounding box, lower and upper corner: a query skips, cheaply, the
    /// triangles whose box is farther than the best distance so far, most of those it meets.
    boxes: Vec<[P; 2]>,
    cell: f64,
    bins: HashMap<[i64; 3], Vec<u32>>,
}

impl Nearest {
    /// Bins the triangles `triangles` of `positions`, each coordinate multiplied by `scale`
    /// (distances are then measured in those units).
    pub fn new(positions: &[[f32; 3]], triangles: &[[u32; 3]], scale: P) -> Nearest {
        let tris: Vec<[P; 3]> = triangles
            .iter()
            .map(|t| t.map(|i| scaled(positions[i as usize], scale)))
            .collect();
        let boxes: Vec<[P; 2]> = tris
            .iter()
            .map(|t| {
                [
                    std::array::from_fn(|d| t[0][d].min(t[1][d]).min(t[2][d])),
                    std::array::from_fn(|d| t[0][d].max(t[1][d]).max(t[2][d])),
                ]
            })
            .collect();
        // Cells about two edge lengths wide: a few triangles per cell.
        let edge =
            tris.iter().map(|t| dist2(t[0], t[1]).sqrt()).sum::<f64>() / tris.len().max(1) as f64;
        let cell = (2.0 * edge).max(1e-9);
        let mut bins: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (n, [lo, hi]) in boxes.iter().enumerate() {
            let (lo, hi) = (lo.map(|c| bin(c, cell)), hi.map(|c| bin(c, cell)));
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        bins.entry([x, y, z]).or_default().push(n as u32);
                    }
                }
            }
        }
        Nearest {
            tris,
            boxes,
            cell,
            bins,
        }
    }

    /// The distance from `p` (already scaled) to the nearest point of the mesh; infinite if the
    /// mesh has no triangles.
    pub fn distance(&self, p: P) -> f64 {
        self.nearest(p, &mut None)
    }

    /// [`Nearest::distance`], starting from the triangle `hint` names (the nearest to a point
    /// close to `p`, which prunes most others at once) and leaving the nearest one there.
    fn nearest(&self, p: P, hint: &mut Option<u32>) -> f64 {
        if self.tris.is_empty() {
            return f64::INFINITY;
        }
        let k = p.map(|c| bin(c, self.cell));
        // How far `p` is inside its own cell: a triangle in no cell of shells 0..=r is farther
        // than this plus r cells, so once the best distance is within that reach no further
        // shell can beat it. Points on the other mesh usually stop at their own cell.
        let inside = (0..3)
            .map(|d| {
                let lo = k[d] as f64 * self.cell;
                (p[d] - lo).min(lo + self.cell - p[d])
            })
            .fold(f64::INFINITY, f64::min)
            .max(0.0);
        // Squared.
        let mut best = hint.map_or(f64::INFINITY, |n| {
            point_triangle_distance_squared(p, self.tris[n as usize])
        });
        for r in 0i64..=64 {
            for x in -r..=r {
                for y in -r..=r {
                    for z in -r..=r {
                        if x.abs().max(y.abs()).max(z.abs()) != r {
                            continue;
                        }
                        let Some(bin) = self.bins.get(&[k[0] + x, k[1] + y, k[2] + z]) else {
                            continue;
                        };
                        for &n in bin {
                            let [lo, hi] = self.boxes[n as usize];
                            let gap: f64 = (0..3)
                                .map(|d| (lo[d] - p[d]).max(p[d] - hi[d]).max(0.0).powi(2))
                                .sum();
                            if gap < best {
                                let d = point_triangle_distance_squared(p, self.tris[n as usize]);
                                if d < best {
                                    (best, *hint) = (d, Some(n));
                                }
                            }
                        }
                    }
                }
            }
            if best.sqrt() <= inside + r as f64 * self.cell {
                return best.sqrt();
            }
        }
        // Far from everything (meshes far apart): every triangle.
        self.tris
            .iter()
            .map(|&t| point_triangle_distance_squared(p, t))
            .fold(best, f64::min)
            .sqrt()
    }
}

/// The sampled distance between two meshes, both ways.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Distance {
    /// The mean over each mesh's samples of their distance to the other mesh, averaged over the
    /// two directions.
    pub mean: f64,
    /// The largest distance sampled, either way: at most the true (Hausdorff) distance, and
    /// within `step / √3` of it.
    pub max: f64,
    /// Points sampled, on both meshes.
    pub samples: u64,
}

/// The distance between meshes `a` and `b`, sampled on every triangle of each at the points of
/// the barycentric lattice with `ceil(longest side / step)` divisions per side, coordinates
/// multiplied by `scale` first. Triangles the two meshes share (the same three corners) are at
/// distance zero and are counted without a query.
pub fn symmetric(
    a: (&[[f32; 3]], &[[u32; 3]]),
    b: (&[[f32; 3]], &[[u32; 3]]),
    scale: P,
    step: f64,
) -> Distance {
    let (to_b, back) = (one_way(a, b, scale, step), one_way(b, a, scale, step));
    let mean = |w: (f64, f64, u64)| if w.2 == 0 { 0.0 } else { w.0 / w.2 as f64 };
    Distance {
        mean: (mean(to_b) + mean(back)) / 2.0,
        max: to_b.1.max(back.1),
        samples: to_b.2 + back.2,
    }
}

/// Sum, maximum and count of the distances from `from`'s lattice points to `to`.
fn one_way(
    (fp, ft): (&[[f32; 3]], &[[u32; 3]]),
    (tp, tt): (&[[f32; 3]], &[[u32; 3]]),
    scale: P,
    step: f64,
) -> (f64, f64, u64) {
    let corners = |pos: &[[f32; 3]], t: &[u32; 3]| {
        let mut c = t.map(|i| pos[i as usize].map(f32::to_bits));
        c.sort_unstable();
        c
    };
    let shared: HashSet<[[u32; 3]; 3]> = tt.iter().map(|t| corners(tp, t)).collect();
    let nearest = Nearest::new(tp, tt, scale);
    let (mut sum, mut max, mut count) = (0.0, 0.0f64, 0u64);
    for t in ft {
        let [a, b, c] = t.map(|i| scaled(fp[i as usize], scale));
        let longest = dist2(a, b).max(dist2(b, c)).max(dist2(c, a)).sqrt();
        let n = ((longest / step).ceil() as u64).max(1);
        let points = (n + 1) * (n + 2) / 2;
        count += points;
        if shared.contains(&corners(fp, t)) {
            continue;
        }
        let mut hint = None;
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let w = 1.0 - u - v;
                let p = std::array::from_fn(|d| w * a[d] + u * b[d] + v * c[d]);
                let d = nearest.nearest(p, &mut hint);
                sum += d;
                max = max.max(d);
            }
        }
    }
    (sum, max, count)
}

fn scaled(p: [f32; 3], scale: P) -> P {
    std::array::from_fn(|d| f64::from(p[d]) * scale[d])
}

fn bin(c: f64, cell: f64) -> i64 {
    (c / cell).floor() as i64
}

fn dist2(a: P, b: P) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square in the plane z = `z`, two triangles.
    fn square(z: f32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        (
            vec![[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    #[test]
    fn parallel_squares_are_their_gap_apart_everywhere() {
        let (a, b) = (square(0.0), square(0.25));
        let d = symmetric((&a.0, &a.1), (&b.0, &b.1), [1.0; 3], 0.1);
        assert!(
            (d.mean - 0.25).abs() < 1e-6 && (d.max - 0.25).abs() < 1e-6,
            "{d:?}"
        );
        // 15 divisions on the diagonal (√2 / 0.1 = 14.1): 16 · 17 / 2 points a triangle.
        assert_eq!(d.samples, 4 * 136);
        // Scaled: the gap is measured in the scaled units.
        let d = symmetric((&a.0, &a.1), (&b.0, &b.1), [1.0, 1.0, 4.0], 0.1);
        assert!((d.max - 1.0).abs() < 1e-6, "{d:?}");
    }

    #[test]
    fn a_mesh_is_at_distance_zero_from_itself_without_queries() {
        let a = square(3.0);
        let d = symmetric((&a.0, &a.1), (&a.0, &a.1), [1.0; 3], 0.5);
        assert_eq!((d.mean, d.max), (0.0, 0.0));
        assert_eq!(d.samples, 4 * 10);
    }

    #[test]
    fn queries_far_away_and_beyond_the_bins_are_exact() {
        let a = square(0.0);
        let near = Nearest::new(&a.0, &a.1, [1.0; 3]);
        assert_eq!(near.distance([0.5, 0.5, 2.0]), 2.0);
        // Beyond the 64 shells the index searches: every triangle.
        assert_eq!(near.distance([1000.0, 0.0, 0.0]), 999.0);
        assert_eq!(near.distance([0.0, -3.0, 4.0]), 5.0);
        assert_eq!(
            Nearest::new(&[], &[], [1.0; 3]).distance([0.0; 3]),
            f64::INFINITY
        );
    }

    #[test]
    fn the_maximum_is_where_the_meshes_part() {
        // A square with its corner (1, 1) lifted by 0.5: the farthest point from the flat square
        // is that corner, and from it to the flat square is 0.5.
        let flat = square(0.0);
        let mut lifted = square(0.0);
        lifted.0[2][2] = 0.5;
        let d = symmetric((&lifted.0, &lifted.1), (&flat.0, &flat.1), [1.0; 3], 0.05);
        assert!((d.max - 0.5).abs() < 1e-7, "{d:?}");
        assert!(d.mean > 0.0 && d.mean < 0.25, "{d:?}");
    }
}
