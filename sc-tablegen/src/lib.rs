//! Generates, validates and prints the Skeleton Climbing case tables (SPEC §1–5).
//!
//! For each of the 8 parity classes and 256 cube cases, the generator joins occupied edges by face
//! sides, links them into loops, and nibbles the loops greys-first into triangles. Where the class
//! order would fold a triangle into a face, it swaps to the order rotated by ρ or ρ², or, for the
//! 12 forced folds per class, demotes the folding grey. Every entry is then validated exhaustively,
//! including a geometric embedding check with exact predicates.
//!
//! ```
//! let set = sc_tablegen::generate(&sc_tablegen::ORDER0).unwrap();
//! assert_eq!(set.entry(0, 1).triangles, vec![[4, 8, 0]]);
//! ```

pub mod cube;
pub mod embed;
mod generate;
pub mod intersect;
pub mod nibble;
pub mod order;
pub mod rng;
pub mod sides;
pub mod table;
pub mod validate;

pub use generate::{build, generate};
pub use order::ORDER0;
pub use table::{ClassTable, Entry, Grey, PaperEntry, Rule, TableSet};
pub use validate::{Invalid, validate};
