//! `orthosim occlusion`: where the arches meet, and with `--settle` where they meet once the lower
//! arch has closed onto the upper under a bite force.

use anyhow::Result;
use clap::Args;
use orthosim::{
    analysis::{ExcursionKind, bite, excursion, measures::Posed},
    teeth::{Case, Dentition},
};

use super::terminal::print_json;

/// `occlusion`'s arguments.
#[derive(Args, Debug)]
pub struct OcclusionArgs {
    /// Built-in case name or path to a .ron case file.
    #[arg(long, default_value = "normal")]
    pub case: String,
    /// Close the lower arch onto the upper under a bite force until it is stable.
    #[arg(long)]
    pub settle: bool,
    /// How far apart the settle starts (mm, 0–5; from where the case places the arches).
    #[arg(long, default_value_t = 0.0, value_parser = opening)]
    pub opening: f32,
    /// Slide the lower arch from the bite: forwards or to the patient's right or left, in 0.5 mm
    /// steps (implies `--settle`).
    #[arg(long, value_parser = ["protrusive", "right", "left"])]
    pub excursion: Option<String>,
    /// How far the excursion goes (mm, 0.5–6).
    #[arg(long, default_value_t = 6.0, value_parser = excursion_mm)]
    pub mm: f32,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

fn excursion_mm(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if (0.5..=6.0).contains(&v) => Ok(v),
        _ => Err(format!("'{s}': give an excursion from 0.5 to 6 mm")),
    }
}

fn opening(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if (0.0..=5.0).contains(&v) => Ok(v),
        _ => Err(format!("'{s}': give an opening from 0 to 5 mm")),
    }
}

/// Measures (and settles) the bite and prints it.
pub fn run(args: OcclusionArgs) -> Result<()> {
    let loaded = Case::resolve(&args.case)?;
    let name = loaded.case.name.clone();
    let d = Dentition::build(loaded)?;
    let teeth = Posed::of_dentition(&d);
    let kind = args.excursion.as_deref().map(|k| match k {
        "protrusive" => ExcursionKind::Protrusive,
        "right" => ExcursionKind::Right,
        _ => ExcursionKind::Left,
    });
    let mut b = bite(&name, &teeth, args.settle || kind.is_some(), args.opening);
    if let Some(kind) = kind {
        b.excursion = Some(excursion(&teeth, &b.lower_pose, kind, args.mm));
    }
    if args.json {
        return print_json(&b);
    }
    println!(
        "case {}: {}{}",
        b.case,
        if b.stable { "stable" } else { "not stable" },
        b.why
            .as_deref()
            .map_or(String::new(), |w| format!(" ({w})"))
    );
    if args.settle || b.excursion.is_some() {
        if b.opened_mm > 0.0 {
            println!(
                "the arches started interpenetrating: opened {:.3} mm at the incisors about the condylar hinge first",
                b.opened_mm
            );
        }
        println!(
            "settle: {} steps, lower arch moved {:.3} mm and turned {:.2}°; condyles carry left {:.1} N, right {:.1} N of a {} N bite",
            b.iterations,
            b.lower_travel_mm,
            b.lower_turn_deg,
            b.condyles.left,
            b.condyles.right,
            orthosim::analysis::bite::BITE_FORCE_N
        );
    }
    println!(
        "contacting upper teeth: right {}, left {}; incisor gap {:.3} mm; max penetration {:.4} mm",
        b.contact_teeth.right, b.contact_teeth.left, b.incisor_gap_mm, b.max_penetration_mm
    );
    println!("{:>7} {:>10} {:>10}", "pair", "area mm²", "gap mm");
    for c in &b.contacts {
        println!(
            "{:>7} {:>10.3} {:>10.4}",
            format!("{}-{}", c.upper, c.lower),
            c.area_mm2,
            c.min_gap_mm
        );
    }
    if let Some(e) = &b.excursion {
        let pairs = |list: &[[orthosim::teeth::Fdi; 2]]| {
            list.iter()
                .map(|[u, l]| format!("{u}-{l}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        println!("{} excursion:", e.kind.name());
        println!(
            "{:>5} {:>8} {:>15}  contacts / interferences",
            "mm", "open mm", "guidance"
        );
        for s in &e.steps {
            println!(
                "{:>5.1} {:>8.2} {:>15}  {} / {}",
                s.mm,
                s.opening_mm,
                s.guidance,
                pairs(&s.contacts),
                pairs(&s.interferences)
            );
        }
    }
    Ok(())
}
