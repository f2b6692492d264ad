//! Case tables as static data, produced at compile time by [`sc_macros::include_tables!`].
//!
//! The default set, [`DEFAULT`], comes from the committed `tables/skeleton-climbing.ron`. A crate
//! can build its own set (say, with another nibbling order) in `build.rs` with `sc_tablegen`, and
//! include it the same way; see the `custom-tables` example crate.

/// Marks a grey axis without an ear in [`Entry::ears`].
pub const NO_EAR: u8 = 0xFF;

/// One class-and-case entry, packed for the extraction loop. Aligned to 32 bytes, so that an
/// entry never straddles two cache lines and its address is a shift.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(align(32))]
pub struct Entry {
    /// Triangles as edge-id triples; only the first `count` are used. Ear triangles are stored
    /// with their grey edge in the middle, `[back, grey, forward]`.
    pub tris: [[u8; 3]; 5],
    /// Number of triangles.
    pub count: u8,
    /// Per grey axis (x, y, z): index of the grey edge's ear in `tris`, or [`NO_EAR`].
    pub ears: [u8; 3],
    /// Bit `axis` set iff that grey edge is occupied and mergeable.
    pub mergeable: u8,
    /// Bit `axis` set iff `ears[axis]` is not [`NO_EAR`] and the cube owns that grey edge's merged
    /// pair: it emits the pair's triangle, and its partner, the neighbour across the face the two
    /// ears share, emits nothing. x-greys pair with the y-neighbour and y-greys with the
    /// x-neighbour, so the diagonal is horizontal; z-greys pair along y in even layers and along
    /// x in odd ones, so the quads above and below a sample choose different diagonals. The owner
    /// is the lower cube of the pair. Derived when the tables are included, so that Step 4 tests
    /// ownership with the entry it has already read.
    pub owned_ears: u8,
    /// Indexed by a set of merged grey axes (bit `axis`): bit `n` set iff triangle `n` is
    /// kept, that is, it is one of the first `count` and not the ear of a merged axis. Derived
    /// from `count` and `ears` when the tables are included, so that Step 4's per-cube
    /// bookkeeping is one load instead of a loop over the three axes.
    pub kept: [u8; 8],
    /// Per grey axis with an ear, what Step 4 needs to put the merged triangle of the pair
    /// together without reading the partner's ear. In the pair's owner (the lower cube along the
    /// pairing axis), [`BACK_SHARED`] if the ear's back vertex lies on the face the two share;
    /// in the partner, the edge of its ear's outer vertex off that face. Derived when the tables
    /// are included.
    pub merge: [u8; 3],
}

/// In an owner's [`Entry::merge`]: its ear's back vertex lies on the face it shares with the
/// partner.
pub const BACK_SHARED: u8 = 1 << 4;

/// The two 2048-entry tables: the embedded one (Steps 1–3 and Embedded mode) and the paper one
/// (forced folds nibbled greys-first anyway, for Paper mode). Index: `class * 256 + case`.
#[derive(Debug)]
pub struct CaseTables {
    embedded: &'static [Entry; 2048],
    paper: &'static [Entry; 2048],
    mergeable: &'static [u8; 2048],
}

impl CaseTables {
    /// Wraps generated arrays. Called by the code `include_tables!` emits.
    #[doc(hidden)]
    pub const fn from_static(
        embedded: &'static [Entry; 2048],
        paper: &'static [Entry; 2048],
        mergeable: &'static [u8; 2048],
    ) -> Self {
        CaseTables {
            embedded,
            paper,
            mergeable,
        }
    }

    /// The embedded table's [`Entry::mergeable`] bits alone, compact for the merge decision.
    #[inline]
    pub fn mergeable(&self) -> &'static [u8; 2048] {
        self.mergeable
    }

    /// The table a mode reads; adaptive mode's unit cubes are Steps 1–3's.
    #[inline]
    pub fn for_mode(&self, mode: crate::Mode) -> &'static [Entry; 2048] {
        match mode {
            crate::Mode::Paper => self.paper,
            crate::Mode::Embedded | crate::Mode::Steps123 | crate::Mode::Adaptive => self.embedded,
        }
    }
}

/// The committed tables.
pub static DEFAULT: CaseTables = sc_macros::include_tables!("tables/skeleton-climbing.ron");

/// The grey edge of class `p` along `axis` (SPEC §2), as a cube-local edge id.
#[inline]
pub const fn grey_edge(p: u8, axis: usize) -> u8 {
    let (a, b, c) = (p & 1, (p >> 1) & 1, (p >> 2) & 1);
    match axis {
        0 => (1 - b) + 2 * (1 - c),
        1 => 4 + (1 - a) + 2 * c,
        _ => 8 + a + 2 * b,
    }
}
