//! Builds every entry: base order, then ρ and ρ², then demotion for forced folds (SPEC §4).

use crate::cube::greys;
use crate::embed;
use crate::nibble::{Loops, Nibbled, nibble};
use crate::order::class_order;
use crate::table::{ClassTable, Entry, Grey, PaperEntry, Rule, TableSet};
use crate::validate::{Invalid, validate};

const ROTATIONS: [Rule; 3] = [Rule::Base, Rule::Rot1, Rule::Rot2];

/// Generates the full set for class 0's non-grey order `nine`, then validates it exhaustively.
pub fn generate(nine: &[u8; 9]) -> Result<TableSet, Vec<Invalid>> {
    let set = build(nine)?;
    validate(&set)?;
    Ok(set)
}

/// Generates the set without the final validation pass (each entry is still checked for folds
/// and embedding while its rule is chosen). For measurements that try many orders.
pub fn build(nine: &[u8; 9]) -> Result<TableSet, Vec<Invalid>> {
    if !crate::order::is_valid_nine(nine) {
        return Err(vec![Invalid::set(format!(
            "{nine:?} is not an order of class 0's nine non-grey edges"
        ))]);
    }
    let mut errors = vec![];
    let mut classes = vec![];
    for p in 0..8u8 {
        let mut cases = vec![];
        for case in 0..=255u8 {
            match build_entry(nine, p, case) {
                Ok(e) => cases.push(e),
                Err(problem) => errors.push(Invalid {
                    class: Some(p),
                    case: Some(case),
                    problem,
                }),
            }
        }
        classes.push(ClassTable { class: p, cases });
    }
    if errors.is_empty() {
        Ok(TableSet {
            order: *nine,
            classes,
        })
    } else {
        Err(errors)
    }
}

fn build_entry(nine: &[u8; 9], p: u8, case: u8) -> Result<Entry, String> {
    let loops = Loops::of_case(case).map_err(|e| e.0)?;
    let forced: Vec<u8> = greys(p)
        .into_iter()
        .filter(|&g| loops.ear_folds(g))
        .collect();
    let seed = embed::entry_seed(p, case);
    let acceptable = |n: &Nibbled| n.folds().is_empty() && embed::check(&n.triangles, seed).is_ok();

    if forced.is_empty() {
        for rule in ROTATIONS {
            let n = nibble(&loops, &class_order(nine, p, rule));
            if acceptable(&n) {
                let grey = grey_records(&loops, &n, p, &forced);
                return Ok(Entry {
                    case,
                    triangles: n.triangles,
                    grey,
                    rule,
                    paper: None,
                });
            }
        }
        // SPEC §4's last resort: any greys-first order, the rest in lexicographic order.
        let found = orders_keeping(class_order(nine, p, Rule::Base), 3)
            .map(|order| nibble(&loops, &order))
            .find(|n| acceptable(n))
            .ok_or("no greys-first order is fold-free and embedded")?;
        let grey = grey_records(&loops, &found, p, &forced);
        return Ok(Entry {
            case,
            triangles: found.triangles,
            grey,
            rule: Rule::Fallback,
            paper: None,
        });
    }

    let last_resort = {
        let mut base: Vec<u8> = class_order(nine, p, Rule::Base)
            .into_iter()
            .filter(|e| !forced.contains(e))
            .collect();
        base.extend(&forced);
        orders_keeping(base.try_into().expect("12 edges"), 3 - forced.len())
    };
    let demoted = demoted_orders(nine, p, &forced)
        .chain(last_resort)
        .map(|order| nibble(&loops, &order))
        .find(|n| acceptable(n))
        .ok_or("no order with the forced greys demoted is fold-free and embedded")?;
    // Paper mode keeps the greys first: the rotations, then any such order.
    let paper = ROTATIONS
        .iter()
        .map(|&rule| (rule, class_order(nine, p, rule)))
        .chain(orders_keeping(class_order(nine, p, Rule::Base), 3).map(|o| (Rule::Fallback, o)))
        .map(|(rule, order)| (rule, nibble(&loops, &order)))
        .find(|(_, n)| {
            n.folds()
                .iter()
                .all(|f| forced_ear_fold(&loops, &forced, f))
                && embed::check(&n.triangles, seed).is_ok()
        })
        .map(|(rule, n)| PaperEntry {
            grey: grey_records(&loops, &n, p, &forced),
            triangles: n.triangles,
            rule,
        })
        .ok_or("no greys-first order keeps only the forced fold and stays embedded")?;
    Ok(Entry {
        case,
        grey: grey_records(&loops, &demoted, p, &forced),
        triangles: demoted.triangles,
        rule: Rule::Demoted,
        paper: Some(paper),
    })
}

/// The class orders (each rotation) with the forced greys moved to each later position in turn.
fn demoted_orders<'a>(
    nine: &'a [u8; 9],
    p: u8,
    forced: &'a [u8],
) -> impl Iterator<Item = [u8; 12]> + 'a {
    ROTATIONS.into_iter().flat_map(move |rule| {
        let base = class_order(nine, p, rule);
        (3..12).map(move |pos| {
            let mut rest: Vec<u8> = base
                .iter()
                .copied()
                .filter(|e| !forced.contains(e))
                .collect();
            for &g in forced {
                rest.insert(pos.min(rest.len()), g);
            }
            rest.try_into().expect("a reordering keeps all 12 edges")
        })
    })
}

/// Every order that keeps `base`'s first `keep` edges first, the rest permuted in lexicographic
/// order of their positions in `base`.
fn orders_keeping(base: [u8; 12], keep: usize) -> impl Iterator<Item = [u8; 12]> {
    let mut perm: Vec<usize> = (keep..12).collect();
    let mut done = false;
    core::iter::from_fn(move || {
        if done {
            return None;
        }
        let mut order = base;
        for (i, &k) in perm.iter().enumerate() {
            order[keep + i] = base[k];
        }
        done = !next_permutation(&mut perm);
        Some(order)
    })
}

/// Advances to the next permutation in lexicographic order; false after the last.
fn next_permutation(a: &mut [usize]) -> bool {
    let Some(i) = (1..a.len()).rev().find(|&i| a[i - 1] < a[i]) else {
        return false;
    };
    let j = (i..a.len())
        .rev()
        .find(|&j| a[j] > a[i - 1])
        .expect("a[i] > a[i-1]");
    a.swap(i - 1, j);
    a[i..].reverse();
    true
}

/// Whether a fold is the closing side of a forced grey's ear, the one fold paper mode keeps.
fn forced_ear_fold(loops: &Loops, forced: &[u8], fold: &crate::nibble::Fold) -> bool {
    forced
        .iter()
        .any(|&g| match (fold, loops.prev(g), loops.next(g)) {
            (crate::nibble::Fold::Side(s), Some(b), Some(f)) => *s == [b, f],
            _ => false,
        })
}

/// Records of the class's occupied greys, x, y, z: the ear if the vertex has exactly one triangle
/// whose two sides there are face sides, and mergeability (not for forced folds).
fn grey_records(loops: &Loops, n: &Nibbled, p: u8, forced: &[u8]) -> Vec<Grey> {
    greys(p)
        .into_iter()
        .filter(|&g| loops.next(g).is_some())
        .map(|g| {
            let mut touching = n
                .triangles
                .iter()
                .enumerate()
                .filter(|(_, t)| t.contains(&g));
            let ear = match (
                touching.next(),
                touching.next(),
                loops.prev(g),
                loops.next(g),
            ) {
                (Some((i, t)), None, Some(b), Some(f)) if *t == [b, g, f] => Some(i as u8),
                _ => None,
            };
            Grey {
                edge: g,
                ear,
                mergeable: ear.is_some() && !forced.contains(&g),
            }
        })
        .collect()
}
