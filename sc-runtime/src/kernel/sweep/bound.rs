//! The error bound on Step 4 (`Params::max_error`): one more local blocking rule.
//!
//! A merge removes a grey edge's vertex and replaces the fan of four ears around it by two
//! triangles; each is the three distinct outer vertices of a pair of ears (see
//! `Grid::merged_triangle`). The rule measures both ways: the removed vertex must lie within the
//! bound of the two new triangles, and the new diagonal (at its quarter points and middle) within
//! the bound of the four old ones. It reads the same samples as the other rules, so blocks,
//! threads and streaming all decide alike. Blocking a merge changes nothing but that grey edge's own four ears: every other
//! merge keeps its ears and its triangles, so no decision depends on another.

use super::Grid;
use crate::geometry::point_triangle_distance_squared as distance_squared;
use crate::kernel::vertex::{Field, edge_crossing};
use crate::tables::Entry;
use crate::{ErrorBound, Params, Scalar};

impl Grid<'_> {
    /// Whether the merge of the occupied interior grey edge from `p` along `axis` moves the
    /// surface by less than `bound`.
    pub(super) fn within_bound<T: Scalar>(
        &self,
        p: [usize; 3],
        axis: usize,
        bound: ErrorBound,
        field: &Field<'_, T>,
        params: &Params,
    ) -> bool {
        let (limit, world) = match bound {
            ErrorBound::World(d) => (d, true),
            ErrorBound::Voxels(d) => (d, false),
        };
        // Zero, negative or NaN: nothing is close enough.
        if limit.is_nan() || limit <= 0.0 {
            return false;
        }
        let Some(cubes) = self.cubes_around(p, axis) else {
            return true;
        };
        let point = |q: [usize; 3], a: usize| -> [f64; 3] {
            let t = edge_crossing(field, q, a, params.iso);
            core::array::from_fn(|d| {
                let c = (q[d] + self.offset[d]) as f64 + if d == a { t } else { 0.0 };
                if world {
                    params.origin[d] + c * params.spacing[d]
                } else {
                    c
                }
            })
        };
        // The outer edges of each cube's ear around this grey edge.
        let outer = cubes.map(|(i, j, k)| {
            let class = self.class_of((i, j, k));
            let entry: &Entry = &self.entries[class * 256 + usize::from(self.case_at(i, j, k))];
            let [b, _, f] = entry.tris[usize::from(entry.ears[axis])];
            [b, f].map(|e| cube_edge([i, j, k], e))
        });
        // Pairs share a face: along y for x-greys and even-layer z-greys, else along x.
        let n = p[2] + self.offset[2];
        let pairs = if axis == 2 && n.is_multiple_of(2) {
            [(0, 2), (1, 3)]
        } else {
            [(0, 1), (2, 3)]
        };
        let g = point(p, axis);
        // The two replacing triangles, as edges: each is the three distinct outer edges of a
        // pair's ears (the two ears share one).
        let replacing = pairs.map(|(a, b)| {
            let mut corners = [outer[a][0], outer[a][1], outer[b][0], outer[b][1]];
            corners.sort_unstable();
            if corners[0] == corners[1] {
                [corners[1], corners[2], corners[3]]
            } else if corners[1] == corners[2] {
                [corners[0], corners[2], corners[3]]
            } else {
                [corners[0], corners[1], corners[3]]
            }
        });
        let limit2 = limit * limit;
        let new = replacing.map(|t| t.map(|(q, a)| point(q, a)));
        // One way: the removed vertex is close to the new triangles.
        if !new.iter().all(|&t| distance_squared(g, t) < limit2) {
            return false;
        }
        // The other way: the new diagonal (the edge both replacing triangles have) stays close to
        // the four old triangles. Where the quad is twisted, the diagonal runs farthest from
        // them near its middle, while the removed vertex can sit close to a corner of the new
        // triangles; the quarter points and the middle catch that.
        let fan = outer.map(|[b, f]| [point(b.0, b.1), g, point(f.0, f.1)]);
        let shared: [([usize; 3], usize); 2] = {
            let mut it = replacing[0].iter().filter(|e| replacing[1].contains(e));
            match (it.next(), it.next()) {
                (Some(&u), Some(&v)) => [u, v],
                _ => return false,
            }
        };
        let [u, v] = shared.map(|(q, a)| point(q, a));
        [0.25, 0.5, 0.75].iter().all(|&t| {
            let m: [f64; 3] = core::array::from_fn(|d| u[d] + t * (v[d] - u[d]));
            fan.iter().any(|&f| distance_squared(m, f) < limit2)
        })
    }
}

/// The lower end and axis of cube-local edge `e` of cube `(i, j, k)` (SPEC §2 numbering: edge
/// `4 · axis + r`, with `r`'s bits the offsets along the other two axes in order).
fn cube_edge(cube: [usize; 3], e: u8) -> ([usize; 3], usize) {
    let axis = usize::from(e / 4);
    let (a, b) = (usize::from(e & 1), usize::from(e >> 1 & 1));
    let offset = match axis {
        0 => [0, a, b],
        1 => [a, 0, b],
        _ => [a, b, 0],
    };
    (core::array::from_fn(|d| cube[d] + offset[d]), axis)
}
