//! A box's triangles in one variant (docs/adaptive.md §3).
//!
//! A face of the box keeps its arc's midline vertices unless a box at least as large is across
//! it (the smaller boxes or unit cubes across have those vertices on their edges); bit `i` of
//! `refined` says so for arc `i`. The corner polygon (3 to 6 vertices) is triangulated in each of its 1,
//! 2, 5 or 14 ways; in each, a coarse triangle whose sides include kept midline vertices becomes
//! a small polygon, fanned from the one of its vertices that gives the best-shaped triangles
//! with none lying in a face. Of the candidates that pass (F), (P) and (E), the one whose worst
//! triangle is best shaped is taken, the first in enumeration order on a tie, so the choice is a
//! function of the box's samples and its variant alone: the variant tested when the box was
//! accepted is the one emitted.

use super::checks::{Memo, faces_up, in_wall, quality, separates, simple_projection, within_bound};
use super::outline::Outline;
use super::{BoxSource, MAX_CORNERS, MAX_MIDS, MAX_TRIANGLES, Patch, Tolerance, Vertex};

/// A box's triangles, wound filled → empty.
#[derive(Clone, Debug)]
pub(crate) struct Triangulation {
    tris: [[Vertex; 3]; MAX_TRIANGLES],
    n: usize,
}

impl Triangulation {
    /// The triangles.
    pub fn triangles(&self) -> &[[Vertex; 3]] {
        &self.tris[..self.n]
    }

    fn push(&mut self, t: [Vertex; 3]) -> bool {
        if self.n == MAX_TRIANGLES {
            return false;
        }
        self.tris[self.n] = t;
        self.n += 1;
        true
    }
}

/// Calls `f` with each triangulation of the convex polygon `0 .. n` (`3 ≤ n ≤ 6`), as triples
/// in increasing order, which is the polygon's order: each triangle keeps the loop's turn.
pub(crate) fn each_coarse(n: usize, f: &mut dyn FnMut(&[[u8; 3]])) {
    type Pending = [(u8, u8); MAX_CORNERS];
    type Tris = [[u8; 3]; MAX_CORNERS - 2];
    fn go(pending: Pending, np: usize, tris: Tris, nt: usize, f: &mut dyn FnMut(&[[u8; 3]])) {
        if np == 0 {
            f(&tris[..nt]);
            return;
        }
        let (l, r) = pending[np - 1];
        if r - l < 2 {
            go(pending, np - 1, tris, nt, f);
            return;
        }
        for k in l + 1..r {
            let (mut p, mut t) = (pending, tris);
            t[nt] = [l, k, r];
            p[np - 1] = (l, k);
            p[np] = (k, r);
            go(p, np + 1, t, nt + 1, f);
        }
    }
    if (3..=MAX_CORNERS).contains(&n) {
        let mut pending = [(0, 0); MAX_CORNERS];
        pending[0] = (0, n as u8 - 1);
        go(pending, 1, [[0; 3]; MAX_CORNERS - 2], 0, f);
    }
}

/// The boundary of coarse triangle `tri` in a variant: its corners, with the kept midline
/// vertices of the arcs among its sides.
fn refined_boundary(
    outline: &Outline,
    refined: u8,
    tri: [u8; 3],
) -> ([Vertex; 3 + 3 * MAX_MIDS], usize) {
    let mut out = [Vertex::default(); 3 + 3 * MAX_MIDS];
    let mut m = 0;
    for s in 0..3 {
        let (x, y) = (usize::from(tri[s]), usize::from(tri[(s + 1) % 3]));
        out[m] = outline.corners[x];
        m += 1;
        for &w in side_mids(outline, refined, x, y) {
            out[m] = w;
            m += 1;
        }
    }
    (out, m)
}

/// The kept midline vertices on side `x → y` of a coarse triangle: those of arc `x`, if the
/// side is that arc and the variant keeps them.
fn side_mids(outline: &Outline, refined: u8, x: usize, y: usize) -> &[Vertex] {
    if (x + 1) % outline.n == y && refined >> x & 1 == 1 {
        &outline.mids[x][..usize::from(outline.mid_count[x])]
    } else {
        &[]
    }
}

/// How many triangles coarse triangle `tri`'s fan has: one, and one per kept midline vertex on
/// its sides ([`refined_boundary`]'s length less two).
fn fan_size(outline: &Outline, refined: u8, tri: [u8; 3]) -> usize {
    (0..3)
        .map(|s| {
            let (x, y) = (usize::from(tri[s]), usize::from(tri[(s + 1) % 3]));
            side_mids(outline, refined, x, y).len()
        })
        .sum::<usize>()
        + 1
}

/// The best fan of a small polygon whose triangles all face up and none lies in a face: its
/// apex and its worst triangle's quality (the first apex on a tie).
fn best_fan(outline: &Outline, q: &[Vertex]) -> Option<(usize, f64)> {
    let m = q.len();
    let mut best: Option<(usize, f64)> = None;
    let apexes = if m == 3 { 1 } else { m };
    for apex in 0..apexes {
        let mut worst = f64::INFINITY;
        let mut ok = true;
        for s in 0..m - 2 {
            let t = fan_triangle(q, apex, s);
            if in_wall(&t) || !faces_up(&t, outline) {
                ok = false;
                break;
            }
            worst = worst.min(quality(&t));
        }
        if ok && best.is_none_or(|b| worst > b.1) {
            best = Some((apex, worst));
        }
    }
    best
}

/// Triangle `s` of the fan of small polygon `q` from vertex `apex`.
#[inline]
fn fan_triangle(q: &[Vertex], apex: usize, s: usize) -> [Vertex; 3] {
    let m = q.len();
    [q[apex], q[(apex + 1 + s) % m], q[(apex + 2 + s) % m]]
}

/// Corner triangles of a polygon of at most six corners: `C(6, 3)`.
const CORNER_TRIANGLES: usize = 20;

/// Corner triangle `x < y < z`'s number, in `0 .. CORNER_TRIANGLES`.
#[inline]
fn corner_slot([x, y, z]: [u8; 3]) -> usize {
    let (x, y, z) = (usize::from(x), usize::from(y), usize::from(z));
    z * (z - 1) * (z - 2) / 6 + y * (y - 1) / 2 + x
}

/// The best fans of a variant's corner triangles, each found once: the 1 to 14 coarse
/// triangulations share 1 to 20 corner triangles.
struct Fans<'o> {
    outline: &'o Outline,
    refined: u8,
    /// Per corner triangle ([`corner_slot`]): not yet asked, or its best fan if it has one.
    found: [Option<Option<(u8, f64)>>; CORNER_TRIANGLES],
}

impl<'o> Fans<'o> {
    fn new(outline: &'o Outline, refined: u8) -> Self {
        Fans {
            outline,
            refined,
            found: [None; CORNER_TRIANGLES],
        }
    }

    /// Corner triangle `tri`'s best fan ([`best_fan`]): its apex and its worst quality.
    fn get(&mut self, tri: [u8; 3]) -> Option<(u8, f64)> {
        let (outline, refined) = (self.outline, self.refined);
        *self.found[corner_slot(tri)].get_or_insert_with(|| {
            let (q, len) = refined_boundary(outline, refined, tri);
            best_fan(outline, &q[..len]).map(|(apex, worst)| (apex as u8, worst))
        })
    }

    /// The worst triangle's quality of coarse triangulation `coarse` refined, if every small
    /// polygon has a fan that faces up with no triangle in a face, and the fans fit.
    fn rank(&mut self, coarse: &[[u8; 3]]) -> Option<f64> {
        let mut worst = f64::INFINITY;
        let mut count = 0;
        for &tri in coarse {
            let (_, w) = self.get(tri)?;
            worst = worst.min(w);
            count += fan_size(self.outline, self.refined, tri);
        }
        (count <= MAX_TRIANGLES).then_some(worst)
    }

    /// The refined triangles of coarse triangulation `coarse`, if [`Fans::rank`] ranks it.
    fn refine(&mut self, coarse: &[[u8; 3]]) -> Option<Triangulation> {
        let mut out = Triangulation {
            tris: [[Vertex::default(); 3]; MAX_TRIANGLES],
            n: 0,
        };
        for &tri in coarse {
            let (apex, _) = self.get(tri)?;
            let (q, len) = refined_boundary(self.outline, self.refined, tri);
            for s in 0..len - 2 {
                if !out.push(fan_triangle(&q[..len], usize::from(apex), s)) {
                    return None;
                }
            }
        }
        Some(out)
    }
}

/// The most coarse triangulations of a corner polygon: 14, of a hexagon.
const MAX_COARSE: usize = 14;

/// The triangulation of the whole polygon, midline vertices included, whose worst triangle is
/// best shaped among those whose triangles all face up with none in a face; `None` if there is
/// none. The coarse-then-fan candidates are some of these triangulations; this one is tried when
/// none of them passes, as where a coarse triangle with two refined sides has no fan that
/// faces up. By dynamic programming over the polygon's chains, `O(m³)` for `m ≤ 18` vertices;
/// ties go to the first apex, so the result is a function of the polygon alone.
fn best_whole(outline: &Outline, polygon: &[Vertex]) -> Option<Triangulation> {
    const N: usize = super::MAX_POLYGON;
    let m = polygon.len();
    // worst[i][j]: the best worst quality of chain i..=j closed by the chord (i, j);
    // -1 where the chain has no valid triangulation. apex[i][j]: the apex over (i, j).
    let mut worst = [[-1.0f64; N]; N];
    let mut apex = [[0u8; N]; N];
    for i in 0..m - 1 {
        worst[i][i + 1] = f64::INFINITY;
    }
    for gap in 2..m {
        for i in 0..m - gap {
            let j = i + gap;
            for k in i + 1..j {
                let t = [polygon[i], polygon[k], polygon[j]];
                let w = worst[i][k].min(worst[k][j]);
                if w < 0.0 || in_wall(&t) || !faces_up(&t, outline) {
                    continue;
                }
                let w = w.min(quality(&t));
                if w > worst[i][j] {
                    worst[i][j] = w;
                    apex[i][j] = k as u8;
                }
            }
        }
    }
    if worst[0][m - 1] < 0.0 {
        return None;
    }
    let mut out = Triangulation {
        tris: [[Vertex::default(); 3]; MAX_TRIANGLES],
        n: 0,
    };
    let mut chains = [(0u8, 0u8); N];
    chains[0] = (0, m as u8 - 1);
    let mut pending = 1;
    while pending > 0 {
        pending -= 1;
        let (i, j) = chains[pending];
        let (i, j) = (usize::from(i), usize::from(j));
        if j - i < 2 {
            continue;
        }
        let k = usize::from(apex[i][j]);
        out.push([polygon[i], polygon[k], polygon[j]]);
        chains[pending] = (i as u8, k as u8);
        chains[pending + 1] = (k as u8, j as u8);
        pending += 2;
    }
    Some(out)
}

/// The box's triangles in the variant `refined`, if some triangulation passes every test: of
/// those that do, the one whose worst triangle is best shaped. Candidates are refined and
/// ranked first, then tested best first, so (P) and (E), the costly tests, usually run once.
/// `patch` is the box's Steps 1–3 triangles in the tolerance's units.
pub(crate) fn triangulate(
    src: &impl BoxSource,
    outline: &Outline,
    refined: u8,
    patch: &Patch<'_>,
    tolerance: &Tolerance,
    memo: &mut Memo,
) -> Option<Triangulation> {
    let (polygon, m) = outline.polygon(refined);
    if !simple_projection(&polygon[..m], outline.axis) {
        return None;
    }
    // Every coarse triangulation, and (quality, enumeration index) of each whose fans exist.
    let mut coarses = [([[0u8; 3]; MAX_CORNERS - 2], 0usize); MAX_COARSE];
    let mut ranked = [(0.0, 0u8); MAX_COARSE];
    let mut fans = Fans::new(outline, refined);
    let (mut n, mut index) = (0, 0usize);
    each_coarse(outline.n, &mut |coarse| {
        coarses[index].0[..coarse.len()].copy_from_slice(coarse);
        coarses[index].1 = coarse.len();
        if let Some(worst) = fans.rank(coarse) {
            ranked[n] = (worst, index as u8);
            n += 1;
        }
        index += 1;
    });
    // Best shaped first; on a tie, the first enumerated (a stable sort, by hand: n ≤ 14).
    let ranked = &mut ranked[..n];
    for i in 1..ranked.len() {
        let mut j = i;
        while j > 0 && ranked[j].0 > ranked[j - 1].0 {
            ranked.swap(j, j - 1);
            j -= 1;
        }
    }
    for &(_, wanted) in ranked.iter() {
        let (coarse, len) = &coarses[usize::from(wanted)];
        let Some(t) = fans.refine(&coarse[..*len]) else {
            continue;
        };
        if passes(src, outline, refined, &t, patch, tolerance, memo) {
            return Some(t);
        }
    }
    best_whole(outline, &polygon[..m])
        .filter(|t| passes(src, outline, refined, t, patch, tolerance, memo))
}

/// (P), unless the tolerance allows wrong-side samples, and (E).
fn passes(
    src: &impl BoxSource,
    outline: &Outline,
    refined: u8,
    t: &Triangulation,
    patch: &Patch<'_>,
    tolerance: &Tolerance,
    memo: &mut Memo,
) -> bool {
    (tolerance.allow_wrong_side || separates(src, outline, refined, t.triangles()))
        && within_bound(t.triangles(), patch, tolerance, memo)
}

/// Whether the box can be emitted in every variant its neighbours may give it: bit `i` of
/// `may_chord` is set iff the neighbour across arc `i`'s face may be a box of this size.
pub(crate) fn accept(
    src: &impl BoxSource,
    outline: &Outline,
    may_chord: u8,
    patch: &Patch<'_>,
    tolerance: &Tolerance,
) -> bool {
    let with_mids = (0..outline.n)
        .filter(|&i| outline.has_mids(i))
        .fold(0u8, |m, i| m | 1 << i);
    let free = may_chord & with_mids;
    let mut memo = Memo::new();
    let mut chords = free;
    loop {
        if triangulate(
            src,
            outline,
            with_mids & !chords,
            patch,
            tolerance,
            &mut memo,
        )
        .is_none()
        {
            return false;
        }
        if chords == 0 {
            return true;
        }
        chords = (chords - 1) & free;
    }
}

#[cfg(test)]
mod tests {
    use super::each_coarse;
    use alloc::vec::Vec;

    /// The Catalan numbers, each triangulation a set of `n − 2` increasing triples covering
    /// every polygon side once, and no two alike.
    #[test]
    fn coarse_triangulations_are_all_the_triangulations() {
        for (n, count) in [(3, 1), (4, 2), (5, 5), (6, 14)] {
            let mut seen: Vec<Vec<[u8; 3]>> = Vec::new();
            each_coarse(n, &mut |t| {
                assert_eq!(t.len(), n - 2);
                assert!(t.iter().all(|x| x[0] < x[1] && x[1] < x[2]));
                for i in 0..n as u8 {
                    let j = (i + 1) % n as u8;
                    let (a, b) = (i.min(j), i.max(j));
                    let sides = t
                        .iter()
                        .filter(|x| [(x[0], x[1]), (x[1], x[2]), (x[0], x[2])].contains(&(a, b)))
                        .count();
                    assert_eq!(sides, 1, "side {a}-{b} of {t:?}");
                }
                let mut s = t.to_vec();
                s.sort_unstable();
                assert!(!seen.contains(&s));
                seen.push(s);
            });
            assert_eq!(seen.len(), count, "n = {n}");
        }
    }
}
