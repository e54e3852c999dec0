//! The `snee` binary as a user runs it: commands, options and errors (`commands`), `snee info`
//! in the scene's words (`info`), and refusals before work starts (`refusals`).

mod commands;
mod info;
mod refusals;

use std::process::Command;

/// The `snee` binary, run from the repository root.
pub fn snee() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_snee"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}
