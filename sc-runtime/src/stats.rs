/// Counts of one extraction (SPEC §6 names).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Stats {
    /// Occupied grid edges: the vertices of Steps 1–3.
    pub v13: u64,
    /// Triangles of Steps 1–3.
    pub t13: u64,
    /// Grey edges merged by Step 4.
    pub merged: u64,
    /// Occupied interior grey edges that Step 4 left alone (embedded mode's blocking rules).
    pub blocked: u64,
    /// Vertices in the output.
    pub vertices: u64,
    /// Triangles in the output.
    pub triangles: u64,
}
