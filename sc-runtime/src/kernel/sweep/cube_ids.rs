//! The triangle pass's reads of vertex ids and merge marks, by cube, with one bounds test per cube
//! instead of one per read, which saves the pass about a tenth of its instructions.

/// The vertex ids and merge marks of the cubes of one layer: the id planes the vertex passes
/// wrote, for each cube-local edge where its id lies relative to the cube's `i + nx · j`, and the
/// marks.
pub(super) struct CubeIds<'a> {
    ids: &'a [u32],
    /// The merge marks, a byte per cube (`Out::merged`), at least `cubes` of them.
    marks: &'a [u8],
    /// By a byte's worth of edge numbers, so that an edge read from the tables needs neither a
    /// test nor a mask: each edge's offset at its number and again 16, 32, … further on, where
    /// [`Entry::merge`](crate::tables::Entry::merge)'s flags put it. Each offset is followed by
    /// at least `cubes` ids ([`CubeIds::new`] makes sure).
    edge_at: [usize; 256],
    /// `nx · ny − nx − 1`: every cube's `i + nx · j` (`i < nx − 1`, `j < ny − 1`) is below it.
    cubes: usize,
}

impl<'a> CubeIds<'a> {
    /// The ids of layer `k`'s cubes, laid out as the vertex passes write them: the x- and
    /// y-edges of plane `z` at `2 · nx · ny · (z % 2)` and `nx · ny` after it, the layer's z-edges
    /// at `4 · nx · ny`. `ids` holds the five planes (`WORD_PLANES`), `marks` a plane.
    pub fn new(ids: &'a [u32], marks: &'a [u8], dims: [usize; 3], k: usize) -> CubeIds<'a> {
        let [nx, ny, _] = dims;
        let plane = nx * ny;
        let cubes = plane.saturating_sub(nx + 1);
        let (lo, hi) = (k % 2, (k + 1) % 2);
        let edges: [usize; 16] = core::array::from_fn(|e| {
            let r = e % 4;
            let (a, b) = (r & 1, r >> 1);
            match e / 4 {
                0 => [lo, hi][b] * 2 * plane + a * nx,
                1 => [lo, hi][b] * 2 * plane + plane + a,
                2 => 4 * plane + a + b * nx,
                _ => 0,
            }
        });
        // Holds for every layer: the largest offset is `4 · nx · ny + nx + 1`, `ids` holds five
        // planes and `marks` one. Tested once per layer, since the reads below rely on it.
        let room = ids.len().checked_sub(cubes);
        let edge_at = core::array::from_fn(|e| edges[e % 16]);
        assert!(
            room.is_some_and(|room| edges.iter().all(|&o| o <= room)) && marks.len() >= cubes,
            "the id planes and marks hold layer {k}'s cubes"
        );
        CubeIds {
            ids,
            marks,
            edge_at,
            cubes,
        }
    }

    /// The cube at `at = i + nx · j` in the layer; `None` past the last cube.
    #[inline(always)]
    pub fn cube(&self, at: usize) -> Option<Cube<'_, 'a>> {
        (at < self.cubes).then_some(Cube { ids: self, at })
    }
}

/// One cube's vertex ids and merge marks.
#[derive(Clone, Copy)]
pub(super) struct Cube<'c, 'a> {
    ids: &'c CubeIds<'a>,
    /// `i + nx · j`, below [`CubeIds::cubes`].
    at: usize,
}

impl Cube<'_, '_> {
    /// The id of the vertex on cube-local edge `edge` (its low four bits).
    #[inline(always)]
    pub fn id(&self, edge: u8) -> u32 {
        let CubeIds { ids, edge_at, .. } = self.ids;
        // SAFETY: `at < cubes` (`CubeIds::cube`) and every offset is at most
        // `ids.len() − cubes` (`CubeIds::new`), so `at + offset < ids.len()`. Offset from the
        // cube's own ids, whose address the compiler computes once for all the cube's reads.
        unsafe {
            *ids.get_unchecked(self.at..)
                .get_unchecked(edge_at[usize::from(edge)])
        }
    }

    /// The cube's merge marks.
    #[inline(always)]
    pub fn marks(&self) -> u8 {
        // SAFETY: `at < cubes <= marks.len()` (`CubeIds::cube`, `CubeIds::new`).
        unsafe { *self.ids.marks.get_unchecked(self.at) }
    }

    /// The id of the vertex on edge `edge` of the cube `step` further on in the layer: a merged
    /// grey edge's partner, one read per merged triangle, with its bounds test.
    #[inline(always)]
    pub fn next_id(&self, step: usize, edge: u8) -> u32 {
        let CubeIds { ids, edge_at, .. } = self.ids;
        ids[edge_at[usize::from(edge)] + self.at + step]
    }
}
