//! Joining the pieces of a label sweep: the vertices of the plane two pieces share were made
//! by both, and are kept once, with the lower piece's number.

use alloc::vec::Vec;

use super::sweep::{Ear, Edge, Piece};
use super::{Atlas, Label, chunks};

/// The pieces, in order of their layers, as one atlas, with their ears, vertex edges and
/// pinned vertices renumbered alike.
pub(super) fn join<L: Label>(
    pieces: Vec<Piece<L>>,
) -> (Atlas<L>, Vec<Ear<L>>, Vec<Edge>, Vec<u32>) {
    let mut pieces = pieces.into_iter();
    let Some(first) = pieces.next() else {
        return (Atlas::default(), Vec::new(), Vec::new(), Vec::new());
    };
    // The first piece's numbering is the joined one: it is taken whole, not copied.
    let Piece {
        mut atlas,
        mut ears,
        mut edges,
        mut pinned,
        top,
        ..
    } = first;
    // Each list grows once to its joined length, rather than doubling as the copies come.
    let rest: Vec<Piece<L>> = pieces.collect();
    let more = |f: &dyn Fn(&Piece<L>) -> usize| rest.iter().map(f).sum::<usize>();
    atlas.positions.reserve(more(&|p| p.atlas.positions.len()));
    atlas.triangles.reserve(more(&|p| p.atlas.triangles.len()));
    atlas.pairs.reserve(more(&|p| p.atlas.triangles.len()));
    ears.reserve(more(&|p| p.ears.len()));
    edges.reserve(more(&|p| p.edges.len()));
    // The previous piece's top plane, in the joined numbering (plus one, 0 for none).
    let mut shared = top;
    for piece in rest {
        // Per vertex of the piece, its joined id plus one where the lower piece made it, else 0.
        let mut number = chunks::fill(piece.atlas.positions.len(), 0, |_| 0u32);
        for (mine, theirs) in piece.bottom.iter().zip(&shared) {
            for (&m, &t) in mine.iter().zip(theirs) {
                if m != 0 {
                    debug_assert!(
                        t != 0,
                        "a vertex of the shared plane made by one piece only"
                    );
                    number[m as usize - 1] = t;
                }
            }
        }
        let fresh = number_fresh(&mut number, atlas.positions.len());
        extend_mapped(&mut atlas.positions, &fresh, |&v| {
            piece.atlas.positions[v as usize]
        });
        if !piece.edges.is_empty() {
            extend_mapped(&mut edges, &fresh, |&v| piece.edges[v as usize]);
        }
        pinned.extend(piece.pinned.iter().map(|&v| number[v as usize]));
        let first_triangle = atlas.triangles.len() as u32;
        extend_mapped(&mut atlas.triangles, &piece.atlas.triangles, |t| {
            t.map(|v| number[v as usize])
        });
        atlas.pairs.extend_from_slice(&piece.atlas.pairs);
        extend_mapped(&mut ears, &piece.ears, |ear| Ear {
            vertex: number[ear.vertex as usize],
            triangle: first_triangle + ear.triangle,
            ..*ear
        });
        shared = piece.top.map(|plane| {
            plane
                .iter()
                .map(|&v| {
                    if v == 0 {
                        0
                    } else {
                        number[v as usize - 1] + 1
                    }
                })
                .collect()
        });
    }
    (atlas, ears, edges, pinned)
}

/// Numbers the vertices `number` marks 0 (the piece's own) from `next` in their order, and
/// the others by their mark less one; returns the piece's own vertices, in order. In chunks on
/// the current pool: each chunk counts its own vertices, then numbers them after those before.
fn number_fresh(number: &mut [u32], next: usize) -> Vec<u32> {
    let size = chunks::size(number.len(), 0);
    let counts = chunks::map(number.chunks(size).collect(), |c| {
        c.iter().filter(|&&n| n == 0).count()
    });
    let mut fresh = chunks::fill(counts.iter().sum(), 0, |_| 0u32);
    let jobs = number
        .chunks_mut(size)
        .zip(chunks::split(&mut fresh, &counts));
    let jobs = jobs.zip(chunks::offsets(&counts)).enumerate().collect();
    chunks::map(jobs, |(k, ((number, fresh), before))| {
        let mut n = 0;
        for (i, v) in number.iter_mut().enumerate() {
            if *v == 0 {
                *v = (next + before + n) as u32;
                fresh[n] = (k * size + i) as u32;
                n += 1;
            } else {
                *v -= 1;
            }
        }
    });
    fresh
}

/// `to` extended by `f` of each of `from`, on the current pool: the copies are most of a join.
#[cfg(feature = "std")]
fn extend_mapped<S: Sync, T: Send>(to: &mut Vec<T>, from: &[S], f: impl Fn(&S) -> T + Sync + Send) {
    use rayon::prelude::*;
    to.par_extend(from.par_iter().map(f));
}

/// `to` extended by `f` of each of `from`.
#[cfg(not(feature = "std"))]
fn extend_mapped<S, T>(to: &mut Vec<T>, from: &[S], f: impl Fn(&S) -> T) {
    to.extend(from.iter().map(f));
}
