use std::process::ExitCode;

use clap::Parser;
use sc_cli::cli::Cli;

fn main() -> ExitCode {
    // clap exits with status 2 on usage errors it finds.
    sc_cli::interrupt::exit_quietly_on_closed_pipe();
    let cli = Cli::parse();
    sc_cli::interrupt::remove_temporaries_on_interrupt();
    match sc_cli::run(&cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("skelclimb: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
