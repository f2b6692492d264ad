//! Whole-mesh self-intersection check.
//!
//! The narrow phase is the exact predicate
//! [`sc_tablegen::intersect::triangles_conflict`]; this module only has to
//! make sure every pair that could possibly touch reaches it exactly once,
//! without testing all pairs (meshes of millions of triangles are checked).
//!
//! Broad phase: a uniform grid over the triangles' bounding boxes. Boxes are
//! compared in their original `f32` coordinates, closed, so touching boxes
//! stay candidates and no rounding can drop a pair. A pair whose boxes
//! overlap in several cells is tested only in the bucket of the cell holding
//! the low corner of the boxes' intersection, which dedupes without a pair
//! set.
//!
//! The grid is hashed rather than dense so that memory and time follow the
//! occupied cells, not the bounding volume: a mesh plus one stray far-away
//! triangle must not blow up the cell count or force huge cells. The cell
//! size comes from the *median* triangle extent so a few large triangles do
//! not coarsen it; triangles covering many cells are instead checked against
//! every box directly, which is cheap as long as they are few.

use sc_tablegen::intersect::{Point, is_degenerate, triangles_conflict};

/// Pairs (i, j), i < j, of triangles of an indexed mesh that conflict per sc_tablegen::intersect::triangles_conflict
/// (positions converted exactly f32 → f64). Also report degenerate triangles as (i, i).
///
/// Triangles with a non-finite coordinate count as degenerate (per
/// [`is_degenerate`]): no geometric answer about them would mean anything.
/// Degenerate triangles are not tested against others, since the
/// predicate's notion of "allowed contact" needs a well-defined plane. The
/// result is sorted. Coordinates that started as `f32` can neither overflow
/// nor underflow in the predicates' expansions, so every answer is exact.
///
/// # Panics
/// If a triangle refers to a vertex index outside `positions`.
pub fn self_intersections(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<(usize, usize)> {
    let n_vertices = positions.len();
    for t in triangles {
        if let Some(&i) = t.iter().find(|&&i| i as usize >= n_vertices) {
            panic!("vertex index {i} out of range ({n_vertices} positions)");
        }
    }
    assert!(
        u32::try_from(triangles.len()).is_ok(),
        "more than u32::MAX triangles"
    );
    let pts: Vec<Point> = positions.iter().map(|p| p.map(f64::from)).collect();
    let corners = |t: u32| triangles[t as usize].map(|i| pts[i as usize]);

    let mut out = Vec::new();
    let mut live: Vec<u32> = Vec::with_capacity(triangles.len());
    for t in 0..triangles.len() as u32 {
        let c = corners(t);
        if !is_degenerate(&c) {
            live.push(t);
        } else {
            out.push((t as usize, t as usize));
        }
    }
    let boxes: Vec<Aabb> = triangles
        .iter()
        .map(|t| Aabb::of(t.map(|i| positions[i as usize])))
        .collect();

    let mut report = |i: u32, j: u32| {
        if triangles_conflict(&corners(i), &corners(j)) {
            out.push((i.min(j) as usize, i.max(j) as usize));
        }
    };

    let grid = Grid::build(&live, &boxes);
    for bucket in 0..grid.bucket_count() {
        let members = grid.members(bucket);
        for (k, &i) in members.iter().enumerate() {
            let bi = &boxes[i as usize];
            for &j in &members[k + 1..] {
                let bj = &boxes[j as usize];
                if bi.overlaps(bj) && grid.bucket_of(bi.low_corner_with(bj)) == bucket {
                    report(i, j);
                }
            }
        }
    }

    // Oversized triangles against every box: each big-small pair once from
    // the big side, each big-big pair once from its lower index.
    for &b in &grid.oversized {
        let bb = &boxes[b as usize];
        for &t in &live {
            if t != b
                && bb.overlaps(&boxes[t as usize])
                && !(t < b && grid.is_oversized[t as usize])
            {
                report(b, t);
            }
        }
    }

    out.sort_unstable();
    out
}

/// Closed axis-aligned box, kept in `f32` so comparisons are exact.
#[derive(Clone, Copy, Debug)]
struct Aabb {
    lo: [f32; 3],
    hi: [f32; 3],
}

impl Aabb {
    fn of(p: [[f32; 3]; 3]) -> Aabb {
        let lo = [0, 1, 2].map(|k| p[0][k].min(p[1][k]).min(p[2][k]));
        let hi = [0, 1, 2].map(|k| p[0][k].max(p[1][k]).max(p[2][k]));
        Aabb { lo, hi }
    }

    fn overlaps(&self, o: &Aabb) -> bool {
        (0..3).all(|k| self.lo[k] <= o.hi[k] && o.lo[k] <= self.hi[k])
    }

    /// Low corner of the intersection of two overlapping boxes: a point in
    /// both, hence in a cell both were inserted into.
    fn low_corner_with(&self, o: &Aabb) -> [f32; 3] {
        [0, 1, 2].map(|k| self.lo[k].max(o.lo[k]))
    }

    fn max_extent(&self) -> f64 {
        (0..3)
            .map(|k| f64::from(self.hi[k]) - f64::from(self.lo[k]))
            .fold(0.0, f64::max)
    }
}

/// Cell edge as a multiple of the median triangle extent: a typical
/// triangle touches a few cells and a cell holds a few triangles.
const CELL_PER_MEDIAN_EXTENT: f64 = 2.0;
/// Triangles covering more cells than this go to the direct-scan list, so a
/// few huge triangles cannot multiply the grid's size.
const MAX_CELLS_PER_TRIANGLE: u64 = 64;

/// Hashed uniform grid in CSR form: `entries[start[b]..start[b + 1]]` are
/// the triangles touching some cell that hashes to bucket `b`, each listed
/// once, in increasing order. Unrelated cells sharing a bucket only add
/// candidates, which the box test removes.
struct Grid {
    origin: [f64; 3],
    inv_cell: f64,
    /// log2 of the bucket count.
    bits: u32,
    start: Vec<u32>,
    entries: Vec<u32>,
    oversized: Vec<u32>,
    is_oversized: Vec<bool>,
}

impl Grid {
    fn build(live: &[u32], boxes: &[Aabb]) -> Grid {
        let mut grid = Grid {
            origin: [0.0; 3],
            inv_cell: 0.0,
            bits: 0,
            start: vec![0, 0],
            entries: Vec::new(),
            oversized: Vec::new(),
            is_oversized: vec![false; boxes.len()],
        };
        if live.is_empty() {
            return grid;
        }
        let mut extents: Vec<f64> = live
            .iter()
            .map(|&t| boxes[t as usize].max_extent())
            .collect();
        let mid = extents.len() / 2;
        // Non-degenerate triangles have positive extent, so the cell is > 0.
        let median = *extents.select_nth_unstable_by(mid, f64::total_cmp).1;
        grid.inv_cell = 1.0 / (CELL_PER_MEDIAN_EXTENT * median);
        for k in 0..3 {
            grid.origin[k] = live
                .iter()
                .map(|&t| f64::from(boxes[t as usize].lo[k]))
                .fold(f64::INFINITY, f64::min);
        }

        let mut inserted = 0u64;
        let mut in_grid = Vec::with_capacity(live.len());
        for &t in live {
            let n = grid.cells_covered(&boxes[t as usize]);
            if n > MAX_CELLS_PER_TRIANGLE {
                grid.oversized.push(t);
                grid.is_oversized[t as usize] = true;
            } else {
                in_grid.push(t);
                inserted += n;
            }
        }
        grid.bits = inserted.max(1).next_power_of_two().trailing_zeros();
        let buckets = 1usize << grid.bits;

        // Counting sort over buckets: count, prefix-sum, fill from the back
        // (so each bucket ends up in increasing triangle order).
        let mut scratch = Vec::new();
        let mut counts = vec![0u32; buckets];
        for &t in &in_grid {
            for &b in grid.buckets_of(&boxes[t as usize], &mut scratch) {
                counts[b] += 1;
            }
        }
        let mut start = Vec::with_capacity(buckets + 1);
        let mut acc = 0u32;
        for &c in &counts {
            acc = acc.checked_add(c).expect("grid too large");
            start.push(acc);
        }
        start.push(acc);
        drop(counts);
        let mut entries = vec![0u32; acc as usize];
        for &t in in_grid.iter().rev() {
            for &b in grid.buckets_of(&boxes[t as usize], &mut scratch) {
                start[b] -= 1;
                entries[start[b] as usize] = t;
            }
        }
        grid.start = start;
        grid.entries = entries;
        grid
    }

    fn bucket_count(&self) -> usize {
        self.start.len() - 1
    }

    fn members(&self, b: usize) -> &[u32] {
        &self.entries[self.start[b] as usize..self.start[b + 1] as usize]
    }

    /// Monotone in `x` (subtraction, multiplication and the saturating
    /// float → int cast all round monotonically), which is what makes a box
    /// cover exactly the cells between those of its corners and keeps the
    /// low-corner dedupe consistent with insertion.
    fn axis_cell(&self, x: f32, k: usize) -> u64 {
        ((f64::from(x) - self.origin[k]) * self.inv_cell) as u64
    }

    fn cell_range(&self, b: &Aabb) -> [(u64, u64); 3] {
        [0, 1, 2].map(|k| (self.axis_cell(b.lo[k], k), self.axis_cell(b.hi[k], k)))
    }

    fn cells_covered(&self, b: &Aabb) -> u64 {
        self.cell_range(b)
            .iter()
            .map(|&(lo, hi)| (hi - lo).saturating_add(1))
            .fold(1, u64::saturating_mul)
    }

    /// Scrambles (y, z) but keeps runs along x adjacent, so neighbouring
    /// cells — which share most of their triangles — are visited one after
    /// another with their data still in cache.
    fn hash(&self, c: [u64; 3]) -> usize {
        let h = c[1].wrapping_mul(0xC2B2_AE3D_27D4_EB4F) ^ c[2].wrapping_mul(0x1656_67B1_9E37_79F9);
        let h = (h ^ (h >> 29)).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 32;
        (h.wrapping_add(c[0]) & ((1u64 << self.bits) - 1)) as usize
    }

    fn bucket_of(&self, p: [f32; 3]) -> usize {
        self.hash([0, 1, 2].map(|k| self.axis_cell(p[k], k)))
    }

    /// The distinct buckets of the cells a box covers.
    fn buckets_of<'s>(&self, b: &Aabb, scratch: &'s mut Vec<usize>) -> &'s [usize] {
        scratch.clear();
        let [x, y, z] = self.cell_range(b);
        for cz in z.0..=z.1 {
            for cy in y.0..=y.1 {
                for cx in x.0..=x.1 {
                    let h = self.hash([cx, cy, cz]);
                    if !scratch.contains(&h) {
                        scratch.push(h);
                    }
                }
            }
        }
        scratch
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    fn octahedron() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let p = vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let t = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        (p, t)
    }

    /// Every pair, no broad phase: the ground truth for the grid.
    fn brute_force(p: &[[f32; 3]], t: &[[u32; 3]]) -> Vec<(usize, usize)> {
        let c = |t: &[u32; 3]| t.map(|i| p[i as usize].map(f64::from));
        let mut out = Vec::new();
        for i in 0..t.len() {
            if is_degenerate(&c(&t[i])) {
                out.push((i, i));
                continue;
            }
            for j in i + 1..t.len() {
                if !is_degenerate(&c(&t[j])) && triangles_conflict(&c(&t[i]), &c(&t[j])) {
                    out.push((i, j));
                }
            }
        }
        out
    }

    struct Rng(u64);
    impl Rng {
        fn f(&mut self) -> f32 {
            // xorshift64*, top 24 bits → [0, 1).
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40) as f32 / (1u32 << 24) as f32
        }
    }

    #[test]
    fn closed_octahedron_is_clean() {
        let (p, t) = octahedron();
        assert_eq!(self_intersections(&p, &t), vec![]);
    }

    #[test]
    fn unwelded_octahedron_is_clean() {
        // A triangle soup: shared vertices are recognised by coordinates,
        // not indices.
        let (p, t) = octahedron();
        let p2: Vec<[f32; 3]> = t.iter().flatten().map(|&i| p[i as usize]).collect();
        let t2: Vec<[u32; 3]> = (0..t.len() as u32)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect();
        assert_eq!(self_intersections(&p2, &t2), vec![]);
    }

    #[test]
    fn octahedron_with_vertex_pushed_through() {
        // The top vertex goes out through the lower face (x+y−z = 1); the
        // upper face [2, 1, 4] then pierces that face. (Pushing it straight
        // down the axis would only nest the two pyramids, not cross them.)
        let (mut p, t) = octahedron();
        p[4] = [0.4, 0.4, -0.4];
        let found = self_intersections(&p, &t);
        assert!(found.contains(&(1, 4)), "{found:?}");
        assert_eq!(found, brute_force(&p, &t));
        // Straight down the axis: nested, touching only along the equator.
        p[4] = [0.0, 0.0, -2.0];
        assert_eq!(self_intersections(&p, &t), vec![]);
    }

    #[test]
    fn distant_indices_crossing() {
        // A row of small disjoint triangles; the first and last are moved
        // onto each other, crossing.
        let mut p = Vec::new();
        let mut t = Vec::new();
        let n = 2000;
        for k in 0..n {
            let x = k as f32 * 2.0;
            let base = p.len() as u32;
            p.extend([[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x, 1.0, 0.0]]);
            t.push([base, base + 1, base + 2]);
        }
        let last = 3 * (n - 1);
        p[last] = [0.25, 0.25, -1.0];
        p[last + 1] = [0.25, 0.25, 1.0];
        p[last + 2] = [0.5, 0.5, 1.0];
        assert_eq!(self_intersections(&p, &t), vec![(0, n - 1)]);
    }

    #[test]
    fn touching_boxes_are_candidates() {
        // Contact at one point on both boxes' boundary (x = 2).
        let p = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [2.0, 1.0, 0.0],
            [3.0, 1.0, 1.0],
            [3.0, 2.0, -1.0],
        ];
        assert_eq!(
            self_intersections(&p, &[[0, 1, 2], [3, 4, 5]]),
            vec![(0, 1)]
        );
        // Moved off by one f32 ulp: clean.
        let mut q = p;
        q[3][0] = f32::from_bits(2.0f32.to_bits() + 1);
        assert_eq!(self_intersections(&q, &[[0, 1, 2], [3, 4, 5]]), vec![]);
    }

    #[test]
    fn degenerate_and_duplicate_triangles() {
        let (mut p, mut t) = octahedron();
        p.push([2.0, 0.0, 0.0]);
        p.push([f32::NAN, 0.0, 0.0]);
        t.push([0, 6, 0]); // repeated index: zero area
        t.push([0, 1, 6]); // collinear
        t.push([2, 4, 7]); // non-finite
        t.push([4, 2, 0]); // face 0 again, other winding
        let found = self_intersections(&p, &t);
        assert_eq!(found, vec![(0, 11), (8, 8), (9, 9), (10, 10)]);
        assert!(self_intersections(&[], &[]).is_empty());
        assert_eq!(self_intersections(&p, &[[0, 0, 0]]), vec![(0, 0)]);
    }

    #[test]
    #[should_panic(expected = "out of range")]
    fn bad_index_panics() {
        self_intersections(&[[0.0; 3]; 3], &[[0, 1, 3]]);
    }

    /// A dense random soup, with very mixed triangle sizes (so some span
    /// many cells) and points snapped to a coarse lattice (so there is a lot
    /// of exact touching): the grid must find exactly what all pairs find.
    #[test]
    fn grid_matches_brute_force() {
        let mut rng = Rng(0x0123_4567_89AB_CDEF);
        for round in 0..6 {
            let n = 150 + 50 * round;
            let mut p = Vec::new();
            let mut t = Vec::new();
            for k in 0..n {
                let size = if round < 3 {
                    [0.02, 0.1, 0.5, 3.0][k % 4]
                } else {
                    // A quarter of them oversized for the grid.
                    [0.02, 0.05, 0.1, 3.0][k % 4]
                };
                let c = [rng.f(), rng.f(), rng.f()].map(|x| x * 4.0);
                let base = p.len() as u32;
                for _ in 0..3 {
                    let q = [0, 1, 2].map(|a| c[a] + (rng.f() - 0.5) * size);
                    p.push(if round % 2 == 0 {
                        q.map(|x| (x * 8.0).round() / 8.0)
                    } else {
                        q
                    });
                }
                t.push([base, base + 1, base + 2]);
            }
            // Some welded neighbours sharing vertices and edges too.
            for k in 0..n / 4 {
                let base = 3 * k as u32;
                t.push([base, base + 1, (3 * (k + 7) % p.len()) as u32]);
                t.push([base + 2, (3 * (k + 11) % p.len()) as u32 + 1, base]);
            }
            let found = self_intersections(&p, &t);
            assert!(found.len() > 10, "round {round}: too easy");
            assert_eq!(found, brute_force(&p, &t), "round {round}");
        }
    }

    /// Tiny disjoint triangles, one per lattice cell with a random offset
    /// and shape: nothing to report, and the broad phase must keep the
    /// candidate count linear.
    #[test]
    fn many_tiny_disjoint_triangles_are_fast() {
        let side = 47; // 47³ = 103 823 triangles
        let mut rng = Rng(42);
        let mut p = Vec::new();
        let mut t = Vec::new();
        for z in 0..side {
            for y in 0..side {
                for x in 0..side {
                    let c = [x, y, z].map(|v| v as f32 * 0.01);
                    let base = p.len() as u32;
                    for _ in 0..3 {
                        p.push([0, 1, 2].map(|k| c[k] + 0.001 + 0.008 * rng.f()));
                    }
                    t.push([base, base + 1, base + 2]);
                }
            }
        }
        let start = Instant::now();
        let found = self_intersections(&p, &t);
        let took = start.elapsed();
        // Random shapes may include (near-)degenerate ones; nothing else.
        assert!(found.iter().all(|&(i, j)| i == j), "{found:?}");
        // Generous for unoptimised builds on a shared machine; all-pairs
        // would be ~5·10⁹ tests.
        assert!(took < Duration::from_secs(20), "took {took:?}");
    }

    /// A closed, finely tessellated torus with welded vertices.
    fn torus(n_major: u32, n_minor: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let (big, small) = (1.0f64, 0.4f64);
        let mut p = Vec::new();
        for i in 0..n_major {
            let u = i as f64 / n_major as f64 * std::f64::consts::TAU;
            for j in 0..n_minor {
                let v = j as f64 / n_minor as f64 * std::f64::consts::TAU;
                let r = big + small * v.cos();
                p.push([
                    (r * u.cos()) as f32,
                    (r * u.sin()) as f32,
                    (small * v.sin()) as f32,
                ]);
            }
        }
        let id = |i: u32, j: u32| (i % n_major) * n_minor + (j % n_minor);
        let mut t = Vec::new();
        for i in 0..n_major {
            for j in 0..n_minor {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                t.push([a, b, c]);
                t.push([a, c, d]);
            }
        }
        (p, t)
    }

    #[test]
    fn torus_is_clean_and_knotted_torus_is_not() {
        let (mut p, t) = torus(120, 60);
        assert_eq!(self_intersections(&p, &t), vec![]);
        // Pull one vertex through the hole to the other side of the ring.
        p[0] = [-1.45, 0.0, 0.0];
        let found = self_intersections(&p, &t);
        assert!(!found.is_empty());
        assert!(found.iter().all(|&(i, j)| i < j));
    }

    /// A far-away stray triangle must not coarsen the grid (with a dense
    /// grid sized by the bounding volume this degenerates to all pairs), and
    /// a huge triangle slicing through the mesh goes through the oversized
    /// path yet is still found against every triangle it cuts.
    #[test]
    fn outliers_in_position_and_size() {
        let (mut p, mut t) = torus(300, 100);
        let n = t.len();
        let base = p.len() as u32;
        p.extend([
            [1e7, 1e7, 1e7],
            [1e7 + 1.0, 1e7, 1e7],
            [1e7, 1e7 + 1.0, 1e7],
        ]);
        t.push([base, base + 1, base + 2]);
        let start = Instant::now();
        assert_eq!(self_intersections(&p, &t), vec![]);
        assert!(start.elapsed() < Duration::from_secs(20));

        // The plane z = 0.001 cuts the torus along two circles.
        let base = p.len() as u32;
        p.extend([[-3.0, -3.0, 0.001], [3.0, -3.0, 0.001], [0.0, 4.0, 0.001]]);
        t.push([base, base + 1, base + 2]);
        let found = self_intersections(&p, &t);
        assert!(found.len() > 2 * 300, "{}", found.len());
        assert!(found.iter().all(|&(i, j)| i < n && j == n + 1));
        // Everything it cuts, by direct comparison with each triangle.
        let c = |tri: &[u32; 3]| tri.map(|i| p[i as usize].map(f64::from));
        let cutter = c(&t[n + 1]);
        let expected: Vec<_> = (0..n)
            .filter(|&i| triangles_conflict(&c(&t[i]), &cutter))
            .map(|i| (i, n + 1))
            .collect();
        assert_eq!(found, expected);
    }
}
