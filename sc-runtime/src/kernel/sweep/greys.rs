//! Step 4's decisions for the grey edges of one plane (SPEC §5), from layers of cube cases and
//! planes of classified samples looked up once per plane. Looked up per edge, by the edge's `z`,
//! they cost a division by 3 or 4 and a row's bounds tests each, and every grey edge of Steps 1–3
//! paid a test of the mode. Which planes and rows hold grey edges is settled here too, so that
//! a vertex pass tests only an edge's `x`, and Steps 1–3 test nothing.

use super::{Decision, Grid};
use crate::Mode;

/// The grey edges along `AXIS` of plane `z` (for z-edges, of layer `z`) whose four cubes lie
/// inside the grid as far as `z` tells. An edge's first cube (see `Grid::cubes_around`) is one
/// step below it along each of the two other axes.
pub(super) struct Greys<'g, const AXIS: usize> {
    grid: &'g Grid<'g>,
    /// The layer of cases of the first two cubes and the one of the other two, from the first
    /// cube's `j · nx + i`: the four are `[cases[0][c], cases[0][c + s], cases[1][c],
    /// cases[1][c + s]]`, with `s` one cube along y for x-edges and along x for the others.
    cases: [&'g [u8]; 2],
    /// The first cube's layer, and its parity class at `i = j = 0`.
    k: usize,
    class: usize,
    /// Which rows and which `x` in them have grey edges: those with `y & 1 == parity[1]` and `x & 1
    /// == parity[0]` (x-edges: any `x`; y-edges: any row).
    parity: [usize; 2],
    /// The grid's mode (Paper mode merges every interior grey) and mergeable bits, copied so a
    /// decision reads them without going through the grid.
    paper: bool,
    mergeable: &'static [u8; 2048],
    /// For SPEC §5 (b), classified samples: plane `z`, then planes `z − 1` and `z + 1` (z-edges
    /// inside the grid only, else empty).
    filled: [&'g [u8]; 3],
}

/// The four cubes around an interior grey edge, by the first of them (see
/// `Grid::cubes_around`); the others follow it at fixed steps, one along each of the two axes
/// across the edge. Made only by [`Greys::decide`], for an edge it found interior: the merge
/// marks (`Out::mark_merged`) rely on that, unchecked.
#[derive(Clone, Copy)]
pub(super) struct Around {
    plane: usize,
    k: usize,
}

impl Around {
    /// The first cube's index in a plane of cubes, `j · nx + i`. It is a cube of the grid (`i <
    /// nx − 1`, `j < ny − 1`), so the index plus `nx + 1`, the furthest the other three lie, is
    /// below `nx · ny`.
    #[inline(always)]
    pub fn plane(self) -> usize {
        self.plane
    }

    /// The first cube's layer.
    #[inline(always)]
    pub fn k(self) -> usize {
        self.k
    }
}

/// How a cube's class differs from the first cube's, in [`Greys::cases`]' order.
const FLIPS: [[usize; 4]; 3] = [[0, 2, 4, 6], [0, 1, 4, 5], [0, 1, 2, 3]];

impl<'g, const AXIS: usize> Greys<'g, AXIS> {
    /// The grey edges of plane (or layer) `z`, if Step 4 may merge any of them: not in Steps
    /// 1–3, nor in a plane without greys along `AXIS`, nor where `z` puts the cubes around them
    /// outside the grid.
    pub fn new(grid: &'g Grid<'g>, z: usize) -> Option<Self> {
        let [nx, ny, nz] = grid.dims;
        let inside = |c: usize, n: usize| c >= 1 && c + 1 < n;
        let [px, py, pz] = grid.offset.map(|o| o & 1);
        // x-greys lie in odd planes, y-greys in even ones (global indices).
        let greys = match AXIS {
            0 => (z ^ pz) & 1 == 1,
            1 => (z ^ pz) & 1 == 0,
            _ => true,
        };
        if grid.mode == Mode::Steps123 || !greys || (AXIS != 2 && !inside(z, nz)) {
            return None;
        }
        let plane = nx * ny;
        let k = if AXIS == 2 { z } else { z - 1 };
        let layer = |k: usize| &grid.cases[(k % 3) * plane..][..plane];
        let cases = match AXIS {
            2 => [layer(k), &layer(k)[nx..]],
            _ => [layer(k), layer(k + 1)],
        };
        let filled = |z: usize| &grid.filled[(z % 4) * plane..][..plane];
        let (below, above) = if AXIS == 2 && inside(z, nz) {
            (filled(z - 1), filled(z + 1))
        } else {
            (&[][..], &[][..])
        };
        Some(Greys {
            grid,
            cases,
            k,
            class: grid.class_of((0, 0, k)),
            // x-greys lie in odd rows, z-greys in even rows and columns, y-greys in odd columns.
            parity: match AXIS {
                0 => [0, py ^ 1],
                1 => [px ^ 1, 0],
                _ => [px, py],
            },
            paper: grid.mode == Mode::Paper,
            mergeable: grid.mergeable,
            filled: [filled(z), below, above],
        })
    }

    /// The plane's grey edges if row `y` has any.
    #[inline(always)]
    pub fn in_row(&self, y: usize) -> Option<&Self> {
        (AXIS == 1 || y & 1 == self.parity[1]).then_some(self)
    }

    /// Whether the edge from `x` of a row [`Greys::in_row`] gave is grey.
    #[inline(always)]
    pub fn is_grey(&self, x: usize) -> bool {
        AXIS == 0 || x & 1 == self.parity[0]
    }

    /// Step 4's decision for the occupied grey edge from `(x, y)` in a row [`Greys::in_row`]
    /// gave.
    #[inline(always)]
    pub fn decide(&self, x: usize, y: usize) -> Decision {
        let [nx, ny, _] = self.grid.dims;
        let inside = |c: usize, n: usize| c >= 1 && c + 1 < n;
        // Interior across the edge, and the edge's upper end in the grid along it (which every
        // occupied edge has; tested for the reads below).
        let interior = match AXIS {
            0 => x + 1 < nx && inside(y, ny),
            1 => inside(x, nx) && y + 1 < ny,
            _ => inside(x, nx) && inside(y, ny),
        };
        if !interior {
            return Decision::Keep;
        }
        let (i, j) = (x - usize::from(AXIS != 0), y - usize::from(AXIS != 1));
        let at = j * nx + i;
        let class = self.class ^ (i & 1) ^ (j & 1) << 1;
        let around = Around {
            plane: at,
            k: self.k,
        };
        if self.paper {
            return Decision::Merge(around);
        }
        let s = if AXIS == 0 { nx } else { 1 };
        let read = |layer: &[u8], at: usize| {
            // SAFETY: the four cubes around an interior edge lie in the grid, so their cases
            // `at` and `at + s` are within the layers `new` took, `nx · ny` long (for z-edges,
            // the second one row on, `nx · (ny − 1)`): with the tests above, the last cube's
            // index is at most `(ny − 2) · nx − 2` for z-edges, `(ny − 1) · nx − 2` otherwise.
            // Read unchecked, with no panic branch to keep their operands live: 2–3 % of the
            // sweep's instructions.
            debug_assert!(at < layer.len());
            unsafe { *layer.get_unchecked(at) }
        };
        let [a, b] = self.cases;
        let cases = [read(a, at), read(a, at + s), read(b, at), read(b, at + s)];
        debug_assert!(
            self.grid
                .cubes_around([x, y, self.z()], AXIS)
                .is_some_and(|cubes| {
                    (0..4).all(|c| {
                        let (i, j, k) = cubes[c];
                        self.grid.class_of((i, j, k)) == class ^ FLIPS[AXIS][c]
                            && self.grid.case_at(i, j, k) == cases[c]
                    })
                })
        );
        // All four bits ANDed, not a short-circuit: one branch on the result instead of four
        // on the data.
        let mut all = 1;
        for (case, flip) in cases.into_iter().zip(FLIPS[AXIS]) {
            let class = (class ^ flip) & 7;
            all &= self.mergeable[class * 256 + usize::from(case)] >> AXIS;
        }
        if all & 1 == 1 && !self.pinch(x, y) {
            Decision::Merge(around)
        } else {
            Decision::Blocked
        }
    }

    /// `Grid::pinch` for the edge from `(x, y)`: the lower end's neighbours in the plane (x- and
    /// y-edges) all differ from it and, if it is empty, its four diagonal neighbours are filled;
    /// for z-edges, its six neighbours all differ from it.
    #[inline(always)]
    fn pinch(&self, x: usize, y: usize) -> bool {
        let [nx, ny, _] = self.grid.dims;
        let [here, below, above] = self.filled;
        if !(x >= 1 && x + 1 < nx && y >= 1 && y + 1 < ny) || AXIS == 2 && below.is_empty() {
            return false;
        }
        let p = y * nx + x;
        let at = |plane: &[u8], q: usize| {
            // SAFETY: `p` is interior in its plane (tested above), so `p ± nx ± 1` are within
            // the planes `new` took, `nx · ny` long (`below` and `above` too, being non-empty
            // here). Unchecked as the cases in `decide`.
            debug_assert!(q < plane.len());
            unsafe { *plane.get_unchecked(q) }
        };
        let centre = at(here, p);
        let faces = at(here, p - 1) != centre
            && at(here, p + 1) != centre
            && at(here, p - nx) != centre
            && at(here, p + nx) != centre;
        let pinch = if AXIS == 2 {
            faces && at(below, p) != centre && at(above, p) != centre
        } else {
            let corners = [p - nx - 1, p - nx + 1, p + nx - 1, p + nx + 1];
            faces && (centre == 1 || corners.into_iter().all(|q| at(here, q) == 1))
        };
        debug_assert_eq!(pinch, self.grid.pinch([x, y, self.z()], AXIS));
        pinch
    }

    /// The plane's `z`, for the checks against `Grid`'s functions of a point.
    fn z(&self) -> usize {
        if AXIS == 2 { self.k } else { self.k + 1 }
    }
}
