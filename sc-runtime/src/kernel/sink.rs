use crate::kernel::vertex::unit;
#[cfg(feature = "alloc")]
use crate::kernel::vertex::units;

/// Receives the mesh as it is built: vertex `i` is the `i`-th vertex sent ([`Sink::vertex`],
/// [`Sink::edge_vertex`] or [`Sink::edge_vertex_toward`], by the sweep that produced it), and
/// every triangle refers only to vertices already sent. A sink can therefore write a mesh out
/// while the volume is still being read.
pub trait Sink {
    /// A new vertex in world units, with its unit normal when normals were asked for.
    fn vertex(&mut self, position: [f32; 3], normal: Option<[f32; 3]>);
    /// A triangle, wound so that `(b − a) × (c − a)` points from filled to empty.
    fn triangle(&mut self, triangle: [u32; 3]);
    /// [`Sink::vertex`], told which grid edge the vertex lies on: its lower end and axis, in the
    /// whole grid's indices. Vertices are named by their edges when blocks meshed apart are
    /// joined (see `extract_block`); the default forgets the name.
    #[inline]
    fn edge_vertex(
        &mut self,
        lower: [usize; 3],
        axis: usize,
        position: [f32; 3],
        normal: Option<[f32; 3]>,
    ) {
        let _ = (lower, axis);
        self.vertex(position, normal);
    }
    /// [`Sink::edge_vertex`] with a normal still to be scaled to unit length: `toward` points
    /// outward, and its squared length, `(x · x + z · z) + y · y` in `f32` (in that order, the
    /// same for `(z, y, x)` coordinates), is a normal, finite `f32`. The normal is `toward` times
    /// `1 / √(squared length)`, each operation correctly rounded, which the default computes at
    /// once. A sink that keeps the normals it is sent may scale them later instead, four at a
    /// time, in [`Sink::settle_normals`], to the same bits: one vertex at a time, the vertex
    /// passes would wait on each normal's square root and division.
    #[inline]
    fn edge_vertex_toward(
        &mut self,
        lower: [usize; 3],
        axis: usize,
        position: [f32; 3],
        toward: [f32; 3],
    ) {
        self.edge_vertex(lower, axis, position, Some(unit(toward)));
    }
    /// Called by the sweep after each layer's vertices, the last layer's included: every normal
    /// sent by [`Sink::edge_vertex_toward`] so far must now be scaled. The default scaled each
    /// one as it came, and has nothing left to do.
    #[inline]
    fn settle_normals(&mut self) {}
    /// The value of the vertex just sent, when [`Params::values`](crate::Params::values) asks
    /// for values: the larger of the two samples at the ends of its edge. The default ignores
    /// it.
    #[inline]
    fn vertex_value(&mut self, value: f32) {
        let _ = value;
    }
    /// [`Sink::triangle`], told which cube emits it (its lower corner, in the whole grid's
    /// indices); a merged pair's triangle belongs to the lower cube of the pair.
    #[inline]
    fn cube_triangle(&mut self, cube: [usize; 3], triangle: [u32; 3]) {
        let _ = cube;
        self.triangle(triangle);
    }
    /// [`Sink::cube_triangle`] if `keep`. Whether a cube owns a merged triangle is data, so the
    /// sweep makes the triangle either way and says whether it counts: a sink with room to
    /// spare (the mesh's vectors) writes it and counts it only if kept, without a branch that
    /// mispredicts. The default tests `keep`.
    #[inline]
    fn cube_triangle_if(&mut self, cube: [usize; 3], triangle: [u32; 3], keep: bool) {
        if keep {
            self.cube_triangle(cube, triangle);
        }
    }
    /// A hint, after each layer: about this many more vertices and triangles are to come
    /// (extrapolated from the layers so far). A sink that allocates can reserve once instead of
    /// growing by doubling; the default ignores it.
    fn expect(&mut self, vertices: usize, triangles: usize) {
        let _ = (vertices, triangles);
    }
}

/// A keeping sink's normals (the mesh's vector, a block's collection, a parallel chunk's
/// stretch), as [`Unsettled`] reads and extends them.
#[cfg(feature = "alloc")]
pub(crate) trait NormalColumn {
    fn push(&mut self, normal: [f32; 3]);
    /// The normals pushed, in order, in up to two slices (a stretch's slots, then what it
    /// spilled).
    fn written_mut(&mut self) -> (&mut [[f32; 3]], &mut [[f32; 3]]);
}

#[cfg(feature = "alloc")]
impl NormalColumn for alloc::vec::Vec<[f32; 3]> {
    #[inline]
    fn push(&mut self, normal: [f32; 3]) {
        self.push(normal);
    }

    fn written_mut(&mut self) -> (&mut [[f32; 3]], &mut [[f32; 3]]) {
        (self, &mut [])
    }
}

/// Where the normals a sink keeps stop being unit vectors: those sent by
/// [`Sink::edge_vertex_toward`] since the sink last settled them.
#[cfg(feature = "alloc")]
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Unsettled(usize);

#[cfg(feature = "alloc")]
impl Unsettled {
    /// The normals from index `from` on are unsettled: those before are a sink's from earlier.
    pub fn from(from: usize) -> Unsettled {
        Unsettled(from)
    }

    /// Scales the unsettled normals of `normals` to unit length ([`units`]); all are settled
    /// after.
    pub fn settle(&mut self, normals: &mut impl NormalColumn) {
        let (head, tail) = normals.written_mut();
        let total = head.len() + tail.len();
        match self.0.checked_sub(head.len()) {
            None => {
                units(&mut head[self.0..]);
                units(tail);
            }
            Some(past) => units(&mut tail[past..]),
        }
        self.0 = total;
    }

    /// Pushes a normal already of unit length (from [`Sink::vertex`] or [`Sink::edge_vertex`]):
    /// the normals before it are settled first, and it is stepped over. Out of line: the sweep
    /// sends few such normals, and inlined this would crowd the vertex passes' registers.
    #[cold]
    #[inline(never)]
    pub fn push_unit(&mut self, normals: &mut impl NormalColumn, normal: [f32; 3]) {
        self.settle(normals);
        normals.push(normal);
        self.0 += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::{NormalColumn, Unsettled};
    use crate::kernel::vertex::unit;
    use alloc::vec::Vec;

    /// Normals in two slices split at `at` (or at the end, if shorter), as a stretch holds its
    /// slots and its spill.
    struct Split {
        normals: Vec<[f32; 3]>,
        at: usize,
    }

    impl NormalColumn for Split {
        fn push(&mut self, normal: [f32; 3]) {
            self.normals.push(normal);
        }

        fn written_mut(&mut self) -> (&mut [[f32; 3]], &mut [[f32; 3]]) {
            let at = self.at.min(self.normals.len());
            self.normals.split_at_mut(at)
        }
    }

    /// Settling scales exactly the normals sent since the last settling, wherever the split
    /// between a stretch's slots and its spill falls, before, at or after where they start; a
    /// unit normal pushed as one stays as it was.
    #[test]
    fn settling_scales_each_unsettled_normal_once() {
        let directions: Vec<[f32; 3]> = (1..=11u8)
            .map(|i| [f32::from(i), f32::from(i % 3) - 1.0, 0.5 * f32::from(i % 5)])
            .collect();
        let scaled: Vec<[f32; 3]> = directions.iter().map(|&d| unit(d)).collect();
        // Of length 13: settled, it changes; pushed as a unit normal, it stays.
        let kept = [3.0, 4.0, 12.0];
        let len = directions.len();
        for from in 0..=len {
            for split in 0..=len + 1 {
                let mut normals = directions.clone();
                normals[..from].copy_from_slice(&scaled[..from]);
                let column = |normals: &Vec<[f32; 3]>| Split {
                    normals: normals.clone(),
                    at: split,
                };
                let mut pushed = column(&normals);
                pushed.normals.push(kept);
                let mut unsettled = Unsettled::from(from);
                unsettled.settle(&mut pushed);
                assert_eq!(
                    pushed.normals[..len],
                    scaled[..],
                    "from {from}, split {split}"
                );
                assert_ne!(pushed.normals[len], kept);
                // The same, with the last normal pushed as a unit normal.
                let mut pushed = column(&normals);
                let mut unsettled = Unsettled::from(from);
                unsettled.push_unit(&mut pushed, kept);
                unsettled.settle(&mut pushed);
                assert_eq!(
                    pushed.normals[..len],
                    scaled[..],
                    "from {from}, split {split}"
                );
                assert_eq!(pushed.normals[len], kept, "from {from}, split {split}");
            }
        }
    }
}
