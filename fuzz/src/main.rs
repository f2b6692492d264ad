//! The AFL++ fuzz target for every reader: `SC_FUZZ_TARGET` names the reader (see
//! [`stage::Target`]), and each input is written as that reader's file and read. A panic, an
//! abort (such as an allocation past AFL's memory limit) or a hang is a finding; so is an error
//! that does not name the file, which is turned into a panic here. `fuzz/run.sh` runs it.

mod stage;

use stage::Target;

/// Public for `src/read_zarr.rs`, the same target in sc-io's build with `zarr`.
pub fn main() {
    let name = std::env::var("SC_FUZZ_TARGET").unwrap_or_default();
    let Some(target) = Target::ALL.into_iter().find(|t| t.name() == name) else {
        let names: Vec<&str> = Target::ALL.iter().map(|t| t.name()).collect();
        eprintln!("set SC_FUZZ_TARGET to one of: {}", names.join(", "));
        std::process::exit(2);
    };
    // One scratch folder per process: AFL's persistent mode runs many inputs in it, each staged
    // over the last under the same names.
    let dir = tempfile::tempdir().expect("a scratch folder");
    // `fuzz_nohook`: a panic that a reader catches on purpose (ply-rs and the DICOM pixel
    // decoders panic on some corrupt input; sc-io turns that into an error naming the file) is
    // not a finding; one that escapes still aborts.
    afl::fuzz_nohook!(|data: &[u8]| {
        if let Err(why) = target.run(dir.path(), data) {
            panic!("{name}: {why}");
        }
    });
}
