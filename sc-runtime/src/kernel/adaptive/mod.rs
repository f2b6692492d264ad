//! Adaptive mode's per-box rules (docs/adaptive.md): which boxes of `s × s × s` cubes (`s` a
//! power of two) may replace their Steps 1–3 triangles, and the triangles they emit.
//!
//! `no_std` and allocation-free. A box reads its samples' crossings and its unit cubes'
//! Steps 1–3 triangles through [`BoxSource`]; the driver (`drivers/adaptive`) decides every
//! box, then emits each accepted one in the variant its neighbours give it.
//!
//! - [`outline`]: the simplicity test (S) and the box's loop of corner vertices, with the
//!   midline vertices of each face the loop crosses.
//! - [`triangulate`]: a variant's polygon, its coarse triangulations and their refinement.
//! - [`checks`]: the geometric tests every emitted triangulation passes: fold-free and embedded
//!   (F), separating (P) and within the error bound (E).

pub(crate) mod checks;
pub(crate) mod outline;
pub(crate) mod triangulate;

pub(crate) use outline::outline;
pub(crate) use triangulate::{accept, triangulate};

/// The most corner vertices a loop can have: one per face it crosses.
pub(crate) const MAX_CORNERS: usize = 6;
/// Midline vertices per face: one per midline, two midlines.
pub(crate) const MAX_MIDS: usize = 2;
/// The most vertices of a box's polygon: corners plus every face's midline vertices.
pub(crate) const MAX_POLYGON: usize = MAX_CORNERS * (1 + MAX_MIDS);
/// The most triangles a box emits: a polygon of `MAX_POLYGON` vertices, triangulated.
pub(crate) const MAX_TRIANGLES: usize = MAX_POLYGON - 2;

/// An occupied unit edge's crossing (SPEC §1): where along the edge. Which way it crosses is
/// read from the samples ([`BoxSource::filled`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Crossing {
    /// Distance of the vertex from the edge's lower end, in grid steps (SPEC §1's clamp keeps it
    /// inside `(0, 1)`).
    pub t: f64,
}

/// What a box reads of the volume, in the whole grid's sample indices.
pub(crate) trait BoxSource {
    /// Whether the sample at `p` is filled (SPEC §1).
    fn filled(&self, p: [usize; 3]) -> bool;
    /// The crossing of the unit edge from `lower` along `axis`, if it is occupied.
    fn crossing(&self, lower: [usize; 3], axis: usize) -> Option<Crossing>;
    /// Calls `f` with each Steps 1–3 triangle of unit cube `cube`, its corners in grid steps,
    /// wound as emitted.
    fn cube_triangles(&self, cube: [usize; 3], f: &mut dyn FnMut([[f64; 3]; 3]));
}

/// A Step 1 vertex on a box's boundary: its grid edge, its place in grid steps, and the box
/// faces it lies on (bit `2 · axis + side`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Vertex {
    /// The lower end of its grid edge.
    pub lower: [usize; 3],
    /// The grid edge's axis.
    pub axis: usize,
    /// Position in grid steps.
    pub p: [f64; 3],
    /// The faces of the box it lies on.
    pub faces: u8,
}

impl Vertex {
    /// The vertex of the occupied unit edge from `lower` along `axis`, placed in the box of side
    /// `side` whose lower corner is `corner`.
    fn new(lower: [usize; 3], axis: usize, c: Crossing, corner: [usize; 3], side: usize) -> Vertex {
        let mut faces = 0;
        for n in 0..3 {
            if n != axis {
                if lower[n] == corner[n] {
                    faces |= 1 << (2 * n);
                } else if lower[n] == corner[n] + side {
                    faces |= 1 << (2 * n + 1);
                }
            }
        }
        Vertex {
            lower,
            axis,
            p: core::array::from_fn(|d| lower[d] as f64 + if d == axis { c.t } else { 0.0 }),
            faces,
        }
    }
}

/// A box's Steps 1–3 triangles in a [`Tolerance`]'s units, grouped by unit cube, so that (E)
/// measures a point against the triangles of the cubes near it only.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Patch<'a> {
    /// The triangles, cube by cube.
    pub tris: &'a [[[f64; 3]; 3]],
    /// Each triangle's bounding box, lower and upper corner ([`checks::bounds`]).
    pub boxes: &'a [[[f64; 3]; 2]],
    /// Cube `c`'s triangles are `tris[starts[c]..starts[c + 1]]`, `c = x + side · (y + side · z)`
    /// in cubes from the box's corner.
    pub starts: &'a [u32],
    /// The box's lower corner, in samples.
    pub corner: [usize; 3],
    /// The box's side, in cubes.
    pub side: usize,
    /// Multiplies each coordinate in grid steps (the tolerance's scale).
    pub scale: [f64; 3],
}

/// How far a box's triangles may depart from Steps 1–3's: distances in grid steps scaled per
/// axis (the spacing, for an error bound in world units; ones for voxels) up to `limit`, and
/// whether samples may end up on the wrong side.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tolerance {
    /// Multiplies each coordinate in grid steps.
    pub scale: [f64; 3],
    /// The largest distance allowed between the box's triangles and Steps 1–3's, both ways.
    pub limit: f64,
    /// Whether the separation test (P) is waived, as the 1998 paper waives it.
    pub allow_wrong_side: bool,
}
