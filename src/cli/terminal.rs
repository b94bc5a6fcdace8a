//! What the commands print besides their results: progress on stderr (only when it is a
//! terminal) and JSON on stdout.

use std::io::IsTerminal;

use anyhow::{Context, Result};

/// True when progress should be shown: stderr is a terminal.
pub fn progress_wanted() -> bool {
    std::io::stderr().is_terminal()
}

/// One line of progress on stderr: `\r[####    ] done/total what`, ended when done.
pub fn progress_bar(what: &str, done: usize, total: usize) {
    let filled = (done * 30 / total.max(1)).min(30);
    eprint!(
        "\r[{}{}] {done}/{total} {what}",
        "#".repeat(filled),
        " ".repeat(30 - filled)
    );
    if done == total {
        eprintln!();
    }
}

/// Prints one pretty JSON object on stdout.
pub fn print_json(value: &impl serde::Serialize) -> Result<()> {
    println!(
        "{}",
        serde_json::to_string_pretty(value).context("writing JSON")?
    );
    Ok(())
}
