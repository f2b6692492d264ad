//! Nibbling orders: class 0's chosen order, its rotations, and its mirror images in other classes.

use crate::cube::{mirror_edge, rho_edge};
use crate::table::Rule;

/// Class 0's greys in the order they are nibbled.
pub const GREYS0: [u8; 3] = [8, 3, 5];

/// The nine non-grey edges of class 0, in the order chosen by measurement (see the README's
/// "Nibbling order" section and `sc-tablegen optimize-order`).
pub const ORDER0: [u8; 9] = [1, 7, 4, 11, 9, 6, 2, 0, 10];

/// Class 0's full 12-edge order: greys first, then `nine`.
pub fn full_order(nine: &[u8; 9]) -> [u8; 12] {
    let mut o = [0u8; 12];
    o[..3].copy_from_slice(&GREYS0);
    o[3..].copy_from_slice(nine);
    o
}

/// The order used for `rule` in class `p`: class 0's order composed with ρ^k, then mirrored.
pub fn class_order(nine: &[u8; 9], p: u8, rule: Rule) -> [u8; 12] {
    let turns = match rule {
        Rule::Base | Rule::Demoted | Rule::Fallback => 0,
        Rule::Rot1 => 1,
        Rule::Rot2 => 2,
    };
    full_order(nine).map(|e| mirror_edge((0..turns).fold(e, |e, _| rho_edge(e)), p))
}

/// Whether a 12-edge order is a permutation of all edges.
pub fn is_permutation(order: &[u8]) -> bool {
    let mut seen = [false; 12];
    order.len() == 12
        && order
            .iter()
            .all(|&e| e < 12 && !core::mem::replace(&mut seen[usize::from(e)], true))
}

/// Whether `nine` lists exactly class 0's non-grey edges.
pub fn is_valid_nine(nine: &[u8; 9]) -> bool {
    is_permutation(&full_order(nine))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_rule_starts_with_the_class_greys() {
        for p in 0..8 {
            for rule in [Rule::Base, Rule::Rot1, Rule::Rot2] {
                let o = class_order(&ORDER0, p, rule);
                assert!(is_permutation(&o));
                let mut first: Vec<u8> = o[..3].to_vec();
                first.sort();
                let mut g = crate::cube::greys(p).to_vec();
                g.sort();
                assert_eq!(first, g);
            }
        }
    }
}
