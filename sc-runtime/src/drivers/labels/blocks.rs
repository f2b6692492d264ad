//! Label volumes meshed block by block — on other threads, processes or machines — into exactly
//! the atlas [`extract_labels`](super::extract_labels) makes of the whole volume.
//!
//! As for binary blocks (`drivers/blocks.rs`), a block owns the triangles its cubes make and
//! shares join by merging sorted lists, reusing [`BlockMesh::merge_traced`]. What differs is the
//! vertex order to reproduce: a label sweep numbers vertices as cubes first use them, so a vertex
//! is named by the cube that first uses it and its rank among that cube's vertices. A block finds
//! that cube by sweeping its cubes plus two around them: every cube sharing a vertex with the
//! block's triangles, merged pairs included, lies within that reach.

use alloc::vec;
use alloc::vec::Vec;
use core::ops::Range;

use super::sweep::{self, Padded, Piece};
use super::{Atlas, Label, LabelParams, merge, smooth};
use crate::drivers::blocks::{BlockMesh, check_cubes, check_halo, check_share, cube_key};
use crate::{Error, Stats, Volume};

/// Cubes swept around a block's: those sharing a vertex with a cube whose ear the block's merged
/// pairs take (one further along each axis).
const AROUND: usize = 2;

/// Bits of a vertex key for its rank within the cube that first uses it: a cube uses at most 45
/// vertices (12 edges, 6 faces, 27 inside).
const RANK_BITS: u32 = 6;

/// One block's share of an atlas: the triangles its cubes own, over the vertices they use, with
/// global names. Join shares with [`AtlasBlock::merge`] (in any order or tree) and finish with
/// [`AtlasBlock::into_atlas`].
#[derive(Clone, Debug, PartialEq)]
pub struct AtlasBlock<L> {
    /// Samples of the whole volume along x, y, z.
    pub grid: [usize; 3],
    /// Whether the volume is meshed padded ([`LabelParams::pad`]).
    pub pad: bool,
    /// Per vertex, the key of the cube that first uses it with its rank there: the order of
    /// [`extract_labels`](super::extract_labels)'s vertices. Strictly increasing.
    pub keys: Vec<u64>,
    /// Vertex positions in world units, one per key.
    pub positions: Vec<[f32; 3]>,
    /// Triangles as indices into `keys`, wound as [`Atlas::triangles`].
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle, its two labels, as [`Atlas::pairs`].
    pub pairs: Vec<[L; 2]>,
    /// Per triangle, the key of the cube that owns it; non-decreasing.
    pub cubes: Vec<u64>,
    /// The counts of the owned cubes; they add up across blocks (`vertices` and `triangles`
    /// are filled in by [`AtlasBlock::into_atlas`]).
    pub stats: Stats,
    /// Cubes owned, so that [`AtlasBlock::into_atlas`] can tell a whole grid from a partial one.
    pub covered: u64,
}

/// An empty share, for any label type, joining any other.
impl<L> Default for AtlasBlock<L> {
    fn default() -> Self {
        AtlasBlock {
            grid: [0; 3],
            pad: false,
            keys: Vec::new(),
            positions: Vec::new(),
            triangles: Vec::new(),
            pairs: Vec::new(),
            cubes: Vec::new(),
            stats: Stats::default(),
            covered: 0,
        }
    }
}

/// The cubes of a volume of `grid` samples as meshed: one fewer than the samples per axis, or
/// one more with the padding, whose cube `c` then lies between samples `c − 1` and `c`.
fn cube_grid(grid: [usize; 3], pad: bool) -> [usize; 3] {
    grid.map(|n| n + 2 * usize::from(pad))
}

/// Samples before and past a block's cubes (lower corners) that meshing it reads, in the padded
/// grid: the cubes [`AROUND`] it and their samples, one more for Step 4's pinch test, and with
/// smoothing, the Gaussian's reach from the ends of the edges of the cubes next to the block.
fn halo(smoothing: f64) -> (usize, usize) {
    let reach = if smoothing > 0.0 {
        smooth::reach(smoothing)
    } else {
        0
    };
    (AROUND.max(1 + reach), (AROUND + 1).max(2 + reach))
}

/// The samples meshing the cubes `cubes` (lower corners, per axis) of a volume of `grid` samples
/// reads, clipped to the volume.
///
/// Cubes are numbered as the grid is meshed: `0 .. n − 1` along an axis of `n` samples, or with
/// [`LabelParams::pad`], `0 .. n + 1`, cube `c` lying between samples `c − 1` and `c` (the
/// padding is virtual background beyond the volume's border, never a block's).
///
/// The halo reaches two samples before the cubes and three past them: a merged pair takes its
/// ears from the four cubes around its grey edge, and naming its vertices needs the cubes around
/// those. With smoothing, it reaches one sample more than the Gaussian's reach, `⌈3σ⌉`, on each
/// side, when that is further.
///
/// ```
/// use sc_runtime::labels::{LabelParams, block_samples};
///
/// let params = LabelParams::<u8> { pad: false, ..LabelParams::default() };
/// assert_eq!(block_samples([100; 3], [10..20, 0..99, 97..99], &params).unwrap(), [8..23, 0..100, 95..100]);
/// let smooth = LabelParams::<u8> { pad: false, smoothing: 1.0, ..LabelParams::default() };
/// assert_eq!(block_samples([100; 3], [10..20, 0..99, 97..99], &smooth).unwrap(), [6..25, 0..100, 93..100]);
/// ```
pub fn block_samples<L: Label>(
    grid: [usize; 3],
    cubes: [Range<usize>; 3],
    params: &LabelParams<L>,
) -> Result<[Range<usize>; 3], Error> {
    super::check(params)?;
    check_cubes(cube_grid(grid, params.pad), &cubes)?;
    let (before, after) = halo(params.smoothing);
    let pad = usize::from(params.pad);
    Ok(core::array::from_fn(|d| {
        let end = (cubes[d].end + after).saturating_sub(pad).min(grid[d]);
        cubes[d].start.saturating_sub(before + pad).min(end)..end
    }))
}

/// Meshes the cubes `cubes` (see [`block_samples`] for their numbering) of a volume of `grid`
/// samples. `samples` holds the samples of a box starting at volume index `at`, which must cover
/// [`block_samples`]; a box that is too small is refused rather than meshed wrongly. `params`
/// must be the same for every block of a volume.
///
/// ```
/// use sc_runtime::Volume;
/// use sc_runtime::labels::{AtlasBlock, LabelParams, block_samples, extract_block, extract_labels};
///
/// let dims = [12, 10, 9];
/// let labels: Vec<u16> = (0..12 * 10 * 9).map(|i| ((i * 7919) % 13 / 5) as u16).collect();
/// let volume = Volume::new(&labels, dims).unwrap();
/// let params = LabelParams::default();
/// // Padded, the grid has dims + 1 cubes per axis: two slabs along z.
/// let shares = [0..4, 4..10].map(|z| {
///     let cubes = [0..13, 0..11, z];
///     let need = block_samples(dims, cubes.clone(), &params).unwrap();
///     let slab = &labels[need[2].start * 120..need[2].end * 120];
///     let samples = Volume::new(slab, [12, 10, need[2].len()]).unwrap();
///     extract_block(samples, [0, 0, need[2].start], dims, cubes, &params).unwrap()
/// });
/// let joined = AtlasBlock::merge_all(shares).unwrap().into_atlas().unwrap();
/// assert_eq!(joined, extract_labels(volume, &params).unwrap());
/// ```
pub fn extract_block<L: Label>(
    samples: Volume<'_, L>,
    at: [usize; 3],
    grid: [usize; 3],
    cubes: [Range<usize>; 3],
    params: &LabelParams<L>,
) -> Result<AtlasBlock<L>, Error> {
    let need = block_samples(grid, cubes.clone(), params)?;
    check_halo(samples.dims(), at, grid, &need)?;
    let n = cube_grid(grid, params.pad);
    let mut out = AtlasBlock {
        grid,
        pad: params.pad,
        covered: cubes.iter().map(|r| r.len() as u64).product(),
        ..AtlasBlock::default()
    };
    if out.covered == 0 {
        return Ok(out);
    }
    let window = Padded::window(samples, at, grid, params);
    let swept = core::array::from_fn(|d| {
        cubes[d].start.saturating_sub(AROUND)..(cubes[d].end + AROUND).min(n[d] - 1)
    });
    let piece = sweep::sweep(&window, params, swept, true)?;
    share(&window, params, &cubes, piece, &mut out);
    Ok(out)
}

/// Fills `out` with what `piece`, swept around the block `cubes`, gives the block.
fn share<L: Label>(
    window: &Padded<'_, L>,
    params: &LabelParams<L>,
    cubes: &[Range<usize>; 3],
    piece: Piece<L>,
    out: &mut AtlasBlock<L>,
) {
    let Piece {
        mut atlas,
        ears,
        edges,
        pinned,
        emitters,
        ..
    } = piece;
    let owns = |c: [usize; 3]| (0..3).all(|d| cubes[d].contains(&c[d]));
    let (nt, nv) = (atlas.triangles.len(), atlas.positions.len());
    // Per triangle, the emitter that made it; per vertex, its key (see `AtlasBlock::keys`).
    let mut maker = vec![0u32; nt];
    let mut key = vec![0u64; nv];
    let mut seen: Vec<u32> = Vec::with_capacity(1 << RANK_BITS);
    for (e, em) in emitters.iter().enumerate() {
        let next = emitters.get(e + 1);
        let triangles = em.triangle..next.map_or(nt as u32, |n| n.triangle);
        let made = em.vertex..next.map_or(nv as u32, |n| n.vertex);
        if owns(em.cube) {
            out.stats.t13 += u64::from(triangles.end - triangles.start);
            out.stats.v13 += u64::from(made.end - made.start);
        }
        let base = cube_key(window.n, em.cube) << RANK_BITS;
        seen.clear();
        for t in triangles {
            maker[t as usize] = e as u32;
            for &v in &atlas.triangles[t as usize] {
                if !seen.contains(&v) {
                    if made.contains(&v) {
                        key[v as usize] = base | seen.len() as u64;
                    }
                    seen.push(v);
                }
            }
        }
        debug_assert!(seen.len() <= 1 << RANK_BITS);
    }
    let owned = |t: usize| owns(emitters[maker[t] as usize].cube);
    // Step 4 on the grey vertices with an ear in the block: the four cubes around each lie in
    // the sweep. A vertex's merge counts for the block owning its first ear's cube.
    let mut touched = vec![false; nv];
    for ear in &ears {
        touched[ear.vertex as usize] |= owned(ear.triangle as usize);
    }
    let ears: Vec<_> = ears
        .into_iter()
        .filter(|e| touched[e.vertex as usize])
        .collect();
    let mut around = vec![(0u8, false); nv];
    for ear in &ears {
        let (count, counts) = &mut around[ear.vertex as usize];
        if *count == 0 {
            *counts = owned(ear.triangle as usize);
        }
        *count += 1;
    }
    let merged = merge::merge(window, params, ears, &mut atlas);
    let new_id = |v: usize| merged.as_ref().map_or(v as u32, |m| m.kept[v]);
    for (v, &(count, counts)) in around.iter().enumerate() {
        if count == 4 && counts {
            if new_id(v) == u32::MAX {
                out.stats.merged += 1;
            } else {
                out.stats.blocked += 1;
            }
        }
    }
    // The owned triangles that survived, and the vertices they use, in the atlas's order.
    let mut used = vec![u32::MAX; atlas.positions.len()];
    let mut now = 0;
    for t in 0..nt {
        if merged.as_ref().is_some_and(|m| m.gone(t)) {
            continue;
        }
        if owned(t) {
            out.triangles.push(atlas.triangles[now]);
            out.pairs.push(atlas.pairs[now]);
            let em = &emitters[maker[t] as usize];
            out.cubes.push(cube_key(window.n, em.cube));
            for v in atlas.triangles[now] {
                used[v as usize] = 0;
            }
        }
        now += 1;
    }
    let mut old = vec![0u32; atlas.positions.len()];
    for v in 0..nv {
        let n = new_id(v);
        if n != u32::MAX {
            old[n as usize] = v as u32;
        }
    }
    let mut share_edges = Vec::new();
    for (v, slot) in used.iter_mut().enumerate() {
        if *slot == 0 {
            *slot = out.keys.len() as u32;
            out.keys.push(key[old[v] as usize]);
            out.positions.push(atlas.positions[v]);
            share_edges.extend(edges.get(old[v] as usize));
        }
    }
    debug_assert!(out.keys.windows(2).all(|w| w[0] < w[1]));
    for t in &mut out.triangles {
        *t = t.map(|v| used[v as usize]);
    }
    if params.smoothing > 0.0 {
        let pinned: Vec<u32> = pinned
            .iter()
            .map(|&v| new_id(v as usize))
            .filter(|&v| v != u32::MAX && used[v as usize] != u32::MAX)
            .map(|v| used[v as usize])
            .collect();
        smooth::place(window, params, &mut out.positions, &share_edges, &pinned);
    }
}

impl<L: Label> AtlasBlock<L> {
    /// Checks the rules [`AtlasBlock::merge`] relies on, for a share that crossed a process or a
    /// file and may have been damaged on the way: those of [`BlockMesh::check`], and one pair per
    /// triangle. A share from [`extract_block`] always passes.
    pub fn check(&self) -> Result<(), Error> {
        if self.pairs.len() != self.triangles.len() {
            return Err(Error::BlockMalformed {
                what: "the triangle and pair arrays differ in length",
            });
        }
        check_share(
            &self.keys,
            self.positions.len(),
            None,
            &self.triangles,
            &self.cubes,
        )
    }

    /// Joins two shares of the same volume into one: the union of their vertices (in key
    /// order) and of their triangles (in cube order). Associative and commutative, so shares
    /// can be joined in any order or as a tree. Shares that own the same cube are refused.
    pub fn merge(self, other: AtlasBlock<L>) -> Result<AtlasBlock<L>, Error> {
        Self::merge_all([self, other])
    }

    /// Joins any number of shares at once, as [`AtlasBlock::merge`] joins two, copying each
    /// vertex and triangle once.
    pub fn merge_all(
        shares: impl IntoIterator<Item = AtlasBlock<L>>,
    ) -> Result<AtlasBlock<L>, Error> {
        let mut pad = None;
        let mut meshes = Vec::new();
        let mut pairs = Vec::new();
        for share in shares {
            if (share.covered != 0 || !share.keys.is_empty())
                && *pad.get_or_insert(share.pad) != share.pad
            {
                return Err(Error::BlocksDiffer);
            }
            let (mesh, p) = share.into_parts();
            meshes.push(mesh);
            pairs.push(p);
        }
        let mut joined = Vec::with_capacity(pairs.iter().map(Vec::len).sum());
        let mesh = BlockMesh::merge_traced(meshes, |s, t| joined.push(pairs[s][t]))?;
        Ok(AtlasBlock {
            grid: mesh.grid,
            pad: pad.unwrap_or_default(),
            keys: mesh.keys,
            positions: mesh.positions,
            triangles: mesh.triangles,
            pairs: joined,
            cubes: mesh.cubes,
            stats: mesh.stats,
            covered: mesh.covered,
        })
    }

    /// The whole atlas, once the shares joined cover every cube of the grid: exactly what
    /// [`extract_labels`](super::extract_labels) gives for the whole volume.
    pub fn into_atlas(self) -> Result<Atlas<L>, Error> {
        let need: u64 = cube_grid(self.grid, self.pad)
            .iter()
            .map(|&n| n.saturating_sub(1) as u64)
            .product();
        if self.covered != need {
            return Err(Error::BlocksMissing {
                covered: self.covered,
                cubes: need,
            });
        }
        if u32::try_from(self.keys.len()).is_err() {
            return Err(Error::TooManyVertices);
        }
        let stats = Stats {
            vertices: self.positions.len() as u64,
            triangles: self.triangles.len() as u64,
            ..self.stats
        };
        Ok(Atlas {
            positions: self.positions,
            triangles: self.triangles,
            pairs: self.pairs,
            stats,
        })
    }

    /// The share as a binary block mesh without normals, and its pairs.
    fn into_parts(self) -> (BlockMesh, Vec<[L; 2]>) {
        let mesh = BlockMesh {
            grid: self.grid,
            keys: self.keys,
            positions: self.positions,
            normals: Vec::new(),
            triangles: self.triangles,
            cubes: self.cubes,
            stats: self.stats,
            covered: self.covered,
        };
        (mesh, self.pairs)
    }
}
