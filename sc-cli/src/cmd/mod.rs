//! The subcommands.

pub mod extract;
pub mod info;
pub mod labels;
pub mod merge;
pub mod table1;

/// Prints a warning on stderr; warnings are shown even with `-q`.
pub fn warn(message: impl std::fmt::Display) {
    eprintln!("skelclimb: warning: {message}");
}

/// Renames the complete mesh file over its target, and writes the JSON report `json` (if a file
/// was asked for) first: both are complete before either is renamed, all or nothing.
pub fn commit_with_report(
    mesh: sc_io::atomic::Filled,
    report: Option<sc_io::atomic::AtomicFile>,
    json: impl FnOnce() -> serde_json::Value,
) -> sc_io::Result<()> {
    use std::io::Write;

    let report = match report {
        Some(file) => {
            let bytes = serde_json::to_vec_pretty(&json()).map_err(std::io::Error::other);
            Some(file.fill(|out| out.write_all(&bytes?))?)
        }
        None => None,
    };
    crate::interrupt::finish(|| {
        mesh.commit()?;
        report.map_or(Ok(()), |filled| filled.commit())
    })
}
