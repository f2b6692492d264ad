//! Replays the fuzzing corpus (`fuzz/corpus/<target>/`) and every file a fuzzer once broke a
//! reader with (`fuzz/regressions/<target>/`) through the readers, as the AFL target does: each
//! must read, or fail with an error naming the file, in seconds, and never panic. This is how the findings
//! of `fuzz/run.sh` stay fixed without AFL in the test suite.

#[path = "../../fuzz/src/stage.rs"]
mod stage;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use stage::Target;

/// Longer than any reader may take on a small file.
const SLOW: Duration = Duration::from_secs(5);

fn files(kind: &str, target: Target) -> Vec<PathBuf> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fuzz")
        .join(kind)
        .join(target.name());
    let mut v: Vec<PathBuf> = match std::fs::read_dir(&folder) {
        Ok(entries) => entries.map(|e| e.unwrap().path()).collect(),
        Err(_) => Vec::new(),
    };
    v.sort();
    v
}

/// Runs `target`'s files of `kind`; returns how many were accepted and how many refused.
fn replay(kind: &str, target: Target) -> (usize, usize) {
    let (mut accepted, mut refused) = (0, 0);
    for file in files(kind, target) {
        let data = std::fs::read(&file).unwrap();
        let scratch = tempfile::tempdir().unwrap();
        let started = Instant::now();
        match target.run(scratch.path(), &data) {
            Ok(true) => accepted += 1,
            Ok(false) => refused += 1,
            Err(why) => panic!("{}: {why}", file.display()),
        }
        // AFL counts 2 s as a hang; this leaves room for a loaded test machine.
        let took = started.elapsed();
        assert!(took < SLOW, "{}: took {took:?}", file.display());
    }
    (accepted, refused)
}

#[test]
fn the_corpus_reads_or_is_refused_with_the_file_named() {
    for target in Target::ALL {
        let (accepted, refused) = replay("corpus", target);
        // Each target's corpus starts from valid files (fuzz/seeds.py): if none reads any more,
        // the reader has broken, or the seeds no longer exercise it.
        assert!(
            accepted > 0,
            "{}: none of {refused} files reads",
            target.name()
        );
    }
}

#[test]
fn past_findings_are_refused_with_the_file_named() {
    let mut replayed = 0;
    for target in Target::ALL {
        let (accepted, refused) = replay("regressions", target);
        replayed += accepted + refused;
    }
    // Findings are kept, never deleted: an empty folder means the path above is wrong.
    assert!(replayed > 0, "no regression files found");
}

/// The shards target's label seeds (`labels-*`, fuzz/seeds.py) merge as label shards, staged
/// from their members and as they are, so that the fuzzer starts from label shards that read.
#[test]
fn the_label_shard_seeds_merge() {
    let seeds: Vec<PathBuf> = files("corpus", Target::Shards)
        .into_iter()
        .filter(|f| {
            f.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("labels-")
        })
        .collect();
    assert_eq!(seeds.len(), 2, "{seeds:?}");
    for file in seeds {
        let data = std::fs::read(&file).unwrap();
        let scratch = tempfile::tempdir().unwrap();
        assert_eq!(
            Target::Shards.run(scratch.path(), &data),
            Ok(true),
            "{}",
            file.display()
        );
    }
}
