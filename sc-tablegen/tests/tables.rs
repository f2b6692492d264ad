//! The generator's output, validated exhaustively, and the validator shown to catch each kind of
//! bad entry.

use sc_tablegen::validate::forced_fold;
use sc_tablegen::{ORDER0, Rule, TableSet, generate, validate};

fn fresh() -> TableSet {
    generate(&ORDER0).unwrap_or_else(|e| panic!("{} invalid entries, first: {}", e.len(), e[0]))
}

#[test]
fn all_2048_entries_validate_and_match_the_committed_file() {
    let set = fresh();
    assert!(validate(&set).is_ok());
    assert_eq!(set.classes.len(), 8);
    assert!(set.classes.iter().all(|c| c.cases.len() == 256));
    let committed = include_str!("../tables/skeleton-climbing.ron");
    assert_eq!(
        set.to_ron(),
        committed,
        "run `sc-tablegen generate` and commit tables/"
    );
    assert_eq!(TableSet::from_ron(committed).unwrap(), set);
}

#[test]
fn twelve_forced_folds_per_class_and_class_zero_matches_the_spec() {
    let set = fresh();
    for c in &set.classes {
        let demoted: Vec<u8> = c
            .cases
            .iter()
            .filter(|e| e.rule == Rule::Demoted)
            .map(|e| e.case)
            .collect();
        let blocked: Vec<u8> = c
            .cases
            .iter()
            .filter(|e| e.grey.iter().any(|g| !g.mergeable))
            .map(|e| e.case)
            .collect();
        assert_eq!(demoted.len(), 12, "class {}", c.class);
        assert_eq!(demoted, blocked, "class {}", c.class);
        assert!(
            c.cases
                .iter()
                .all(|e| e.paper.is_some() == (e.rule == Rule::Demoted))
        );
    }
    let class0: Vec<u8> = (0..=255)
        .filter(|&c| set.entry(0, c).rule == Rule::Demoted)
        .collect();
    assert_eq!(
        class0,
        [103, 111, 118, 124, 125, 167, 173, 183, 188, 190, 237, 246]
    );
    // Four per grey edge, two per end of it.
    for p in 0..8 {
        for g in sc_tablegen::cube::greys(p) {
            assert_eq!((0..=255u8).filter(|&c| forced_fold(c, g)).count(), 4);
        }
    }
}

/// Each corruption must be reported, naming its class and case.
#[test]
fn validation_catches_corrupted_entries() {
    let set = fresh();
    let broken = |what: &str, p: u8, case: u8, f: &dyn Fn(&mut sc_tablegen::Entry)| {
        let mut s = set.clone();
        f(&mut s.classes[usize::from(p)].cases[usize::from(case)]);
        let errors = validate(&s).expect_err(what);
        assert!(
            errors
                .iter()
                .any(|e| e.class == Some(p) && e.case == Some(case)),
            "{what}: {errors:?}"
        );
    };
    broken("reversed triangle", 2, 1, &|e| e.triangles[0].reverse());
    broken("missing triangle", 3, 0x69, &|e| {
        e.triangles.pop();
    });
    broken("vertex on an unoccupied edge", 0, 1, &|e| {
        e.triangles[0][0] = 11
    });
    broken("wrong ear", 0, 0x69, &|e| e.grey[0].ear = Some(3));
    broken("forced fold marked mergeable", 0, 103, &|e| {
        e.grey.iter_mut().for_each(|g| g.mergeable = true)
    });
    broken("ordinary grey marked not mergeable", 0, 1, &|e| {
        e.grey[0].mergeable = false
    });
    broken("rule out of step", 4, 7, &|e| e.rule = Rule::Demoted);
    // The paper alternative of a forced fold, whose folded ear is allowed only there.
    let paper = set
        .entry(0, 103)
        .paper
        .clone()
        .expect("forced folds have a paper entry");
    broken("paper triangles as the embedded ones", 0, 103, &|e| {
        e.triangles = paper.triangles.clone()
    });
}

/// The geometric check accepts a lone corner triangle and rejects triangles that meet beyond
/// what they share: the same triangle twice, either way round.
#[test]
fn embedding_check_rejects_coinciding_triangles() {
    assert!(sc_tablegen::embed::check(&[[4, 8, 0]], 1).is_ok());
    assert!(sc_tablegen::embed::check(&[[4, 8, 0], [4, 8, 0]], 1).is_err());
    assert!(sc_tablegen::embed::check(&[[4, 8, 0], [0, 8, 4]], 1).is_err());
}
