//! `orthosim cases`: the built-in cases, one line each.

use anyhow::Result;
use orthosim::teeth::Case;

/// Lists the built-in cases with their descriptions.
pub fn run() -> Result<()> {
    for name in Case::builtin_names() {
        let loaded = Case::resolve(name)?;
        println!("{name:<8} {}", loaded.case.description);
    }
    Ok(())
}
