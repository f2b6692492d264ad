//! The subcommands.

pub mod extract;
pub mod info;
pub mod merge;
pub mod table1;

/// Prints a warning on stderr; warnings are shown even with `-q`.
pub fn warn(message: impl std::fmt::Display) {
    eprintln!("skelclimb: warning: {message}");
}
