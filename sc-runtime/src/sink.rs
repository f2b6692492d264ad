/// Receives the mesh as it is built: vertex `i` is the `i`-th call to [`Sink::vertex`] (for the
/// sweep that produced it), and every triangle refers only to vertices already sent. A sink can
/// therefore write a mesh out while the volume is still being read.
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
