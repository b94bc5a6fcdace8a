//! `orthosim inspect`: per-tooth mesh data and the exact gaps and penetrations of a case.

use anyhow::Result;
use clap::Args;
use orthosim::{
    analysis::{InspectReport, inspect},
    teeth::{Case, Dentition},
};

use super::terminal::{print_json, progress_wanted};

/// `inspect`'s arguments.
#[derive(Args, Debug)]
pub struct InspectArgs {
    /// Built-in case name or path to a .ron case file.
    #[arg(long, default_value = "normal")]
    pub case: String,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Vertices per procedural tooth, overriding the case (125 is the paper's; 10100 gives
    /// about 20,000 triangles per tooth).
    #[arg(long, value_parser = clap::value_parser!(u32).range(20..=200_000))]
    pub resolution: Option<u32>,
}

/// Builds the case, measures it and prints the report.
pub fn run(args: InspectArgs) -> Result<()> {
    let mut loaded = Case::resolve(&args.case)?;
    if args.resolution.is_some() {
        loaded.case.resolution = args.resolution;
    }
    let progress = progress_wanted();
    if progress {
        eprintln!(
            "orthosim: building teeth at {} vertices and arranging the arches…",
            loaded.case.tooth_resolution().vertices
        );
    }
    let dentition = Dentition::build(loaded)?;
    if progress {
        eprintln!("orthosim: measuring gaps and penetrations…");
    }
    let report = inspect(&dentition);
    if args.json {
        return print_json(&report);
    }
    print_table(&report);
    Ok(())
}

fn print_table(report: &InspectReport) {
    println!(
        "case {} ({}), {} vertices per tooth",
        report.case, report.origin, report.resolution
    );
    println!(
        "{:>4} {:<16} {:<6} {:>5} {:>5} {:>7} {:>9}  crown centre (mm)",
        "fdi", "kind", "arch", "verts", "tris", "closed", "vol mm3"
    );
    for t in &report.teeth {
        let c = t.crown_centre;
        println!(
            "{:>4} {:<16} {:<6} {:>5} {:>5} {:>7} {:>9.1}  ({:>6.2}, {:>6.2}, {:>6.2}){}",
            t.fdi,
            t.kind,
            t.arch,
            t.vertices,
            t.triangles,
            t.closed,
            t.volume_mm3,
            c[0],
            c[1],
            c[2],
            if t.extracted { "  extracted" } else { "" }
        );
    }
    for o in &report.orientation {
        let [rx, ry, rz] = o.rotation_deg;
        let [tx, ty, tz] = o.translation;
        println!(
            "{} {}: rotation_deg ({rx:.2}, {ry:.2}, {rz:.2}), translation ({tx:.2}, {ty:.2}, {tz:.2}) mm{}",
            if o.auto {
                "placed automatically"
            } else {
                "placed by its transform"
            },
            o.files.join(", "),
            o.rms_mm
                .map(|r| format!(" (teeth {r:.2} mm rms from the arrangement's)"))
                .unwrap_or_default()
        );
    }
    if !report.imported.is_empty() {
        println!("teeth read from mesh files (repairs):");
        for m in &report.imported {
            println!("  {}: {}", m.fdi, m.summary);
        }
    }
    for scan in &report.scans {
        if scan.fixes.is_empty() && scan.left_out.is_empty() {
            continue;
        }
        println!("labels of {}:", scan.file);
        // Fixes of one kind grouped: islands come by the dozen in real scans.
        let mut groups: Vec<(&str, u8, u8, usize, usize)> = Vec::new();
        for f in &scan.fixes {
            match groups
                .iter_mut()
                .find(|g| (g.0, g.1, g.2) == (f.action, f.label, f.to))
            {
                Some(g) => {
                    g.3 += 1;
                    g.4 += f.triangles;
                }
                None => groups.push((f.action, f.label, f.to, 1, f.triangles)),
            }
        }
        for (action, label, to, pieces, triangles) in groups {
            let to = match (action, to) {
                ("trimmed", _) => "past the crown".to_owned(),
                (_, 0) => "to the gum".to_owned(),
                (_, n) => format!("to {n}"),
            };
            let pieces = if pieces > 1 {
                format!("{pieces} pieces, ")
            } else {
                String::new()
            };
            println!("  {action} {label}: {pieces}{triangles} triangles {to}");
        }
        for l in &scan.left_out {
            println!("  left out {}: {}", l.fdi, l.reason);
        }
    }
    println!("neighbour gaps (mm):");
    for g in &report.neighbour_gaps_mm {
        match &g.overlap {
            Some(o) => println!(
                "  {}-{}: {:.3} ({} of {} into {} of {} near ({:.2}, {:.2}, {:.2}) mm)",
                g.a, g.b, g.gap_mm, o.level_a, g.a, o.level_b, g.b, o.at[0], o.at[1], o.at[2]
            ),
            None => println!("  {}-{}: {:.3}", g.a, g.b, g.gap_mm),
        }
    }
    println!(
        "max penetration in an arch: {:.4} mm",
        report.max_penetration_mm
    );
    println!(
        "max penetration between arches: {:.4} mm (least gap {:.4} mm)",
        report.occlusal_max_penetration_mm, report.occlusal_min_gap_mm
    );
    let o = &report.occlusion;
    let show = |v: Option<f32>, sign: bool| match v {
        Some(v) if sign => format!("{v:+.2} mm"),
        Some(v) => format!("{v:.2} mm"),
        None => "not measured".into(),
    };
    println!(
        "overjet {}, overbite {}, molar relation {} (0 = class I)",
        show(o.overjet_mm, false),
        show(o.overbite_mm, false),
        show(o.molar_relation_mm, true)
    );
    for (what, why) in &o.unmeasured {
        println!("  {what}: {why}");
    }
    for a in &report.alignment {
        let contacts: Vec<String> = a
            .contacts
            .iter()
            .map(|(x, y, mm)| format!("{x}-{y} {mm:.2}"))
            .collect();
        println!(
            "{} arch: Little's irregularity index {}{}, arch-length discrepancy {}",
            a.arch,
            show(a.irregularity_mm, false),
            if contacts.is_empty() {
                String::new()
            } else {
                format!(" ({})", contacts.join(", "))
            },
            show(a.arch_length_discrepancy_mm, true)
        );
    }
}
