//! `orthosim validate`: the PDL model's centres of resistance and rotation, moment-to-force
//! ratios, initial displacement and rate of movement beside the published numbers.

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;
use orthosim::{
    analysis::{Validation, validate},
    movement::MovementSettings,
    teeth::ToothResolution,
};

use super::terminal::print_json;

/// `validate`'s arguments.
#[derive(Args, Debug)]
pub struct ValidateArgs {
    /// Movement settings (a RON `MovementSettings`; its `pdl` parameters are validated).
    #[arg(long)]
    pub settings: Option<PathBuf>,
    /// Vertices per tooth of the built-in teeth measured (default: the cases' resolution, 125).
    #[arg(long, default_value_t = 125, value_parser = clap::value_parser!(u32).range(60..=200_000))]
    pub vertices: u32,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Computes the table and prints it; exits non-zero when a row is outside its reference.
pub fn run(args: ValidateArgs) -> Result<()> {
    let settings = match &args.settings {
        Some(path) => MovementSettings::load(path)?,
        None => MovementSettings::default(),
    };
    let table = validate(
        &settings,
        ToothResolution {
            vertices: args.vertices,
        },
    )?;
    if args.json {
        print_json(&table)?;
    } else {
        print_table(&table);
    }
    let failing: Vec<String> = table
        .rows
        .iter()
        .filter(|r| !r.passes())
        .map(|r| format!("{} ({})", r.name, r.tooth))
        .collect();
    if !failing.is_empty() {
        bail!("outside the published range: {}", failing.join(", "));
    }
    Ok(())
}

fn print_table(t: &Validation) {
    println!(
        "model {}: built-in anatomy ({} vertices per tooth) beside published biomechanics",
        t.model, t.vertices
    );
    println!(
        "{:<36} {:>5} {:>5} {:>9} {:>17}  {:<24} source",
        "quantity", "tooth", "M/F", "value", "reference", "unit"
    );
    for r in &t.rows {
        let mf = r.mf.map_or(String::new(), |m| format!("{m:.0}"));
        // Rows of the archwire alone have no tooth.
        let tooth = if r.tooth == 0 {
            "wire".to_owned()
        } else {
            r.tooth.to_string()
        };
        let reference = r
            .reference
            .map_or("—".to_owned(), |[lo, hi]| format!("{lo:.3}–{hi:.3}"));
        println!(
            "{:<36} {:>5} {:>5} {:>9.3} {:>17}  {:<24} {}{}",
            r.name,
            tooth,
            mf,
            r.value,
            reference,
            r.unit,
            r.source,
            if r.passes() { "" } else { "  << OUTSIDE" }
        );
    }
}
