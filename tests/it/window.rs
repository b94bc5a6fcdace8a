//! The real window, under Xvfb with Mesa's software drivers: `orthosim screenshot` opens it,
//! simulates and saves a PNG. Runs when `xvfb-run` is installed (`.ci/run` installs it), and says it
//! skipped otherwise.

use std::process::Command;

fn have_xvfb() -> bool {
    let ok = Command::new("xvfb-run")
        .arg("--help")
        .output()
        .is_ok_and(|o| o.status.success() || !o.stdout.is_empty() || !o.stderr.is_empty());
    if !ok {
        eprintln!("skipped: xvfb-run is not installed (Debian packages xvfb, mesa-vulkan-drivers)");
    }
    ok
}

/// Runs `orthosim screenshot` under Xvfb with `args` and returns the pixels (width, height,
/// channels, bytes).
fn shoot(name: &str, args: &[&str]) -> (u32, u32, usize, Vec<u8>) {
    let out = std::env::temp_dir().join(format!("orthosim-{name}-{}.png", std::process::id()));
    let _ = std::fs::remove_file(&out);
    let run = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24"])
        .arg(env!("CARGO_BIN_EXE_orthosim"))
        .arg("screenshot")
        .args(args)
        .args(["--tree", "octree", "--frames", "20", "--out"])
        .arg(&out)
        .output()
        .expect("xvfb-run starts");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&out).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    let _ = std::fs::remove_file(&out);
    (info.width, info.height, info.color_type.samples(), buf)
}

#[test]
fn screenshot_renders_the_teeth_in_a_real_window() {
    if !have_xvfb() {
        return;
    }
    let (w, h, channels, buf) = shoot("plain", &["--case", "case1", "--view", "frontal"]);
    assert_eq!((w, h), (1280, 720), "the window's size");
    let pixels: Vec<&[u8]> = buf.chunks(channels).collect();
    let distinct: std::collections::HashSet<&[u8]> = pixels.iter().copied().collect();
    assert!(distinct.len() > 200, "{} colours: blank?", distinct.len());
    // Teeth are light on a dark background: a good share of bright pixels.
    let bright = pixels
        .iter()
        .filter(|p| p[..3].iter().all(|&c| c > 150))
        .count();
    let share = bright as f64 / pixels.len() as f64;
    assert!(share > 0.03 && share < 0.8, "bright share {share}");
}

#[test]
fn the_occlusion_map_colours_the_teeth() {
    if !have_xvfb() {
        return;
    }
    let (_, _, channels, buf) = shoot(
        "map",
        &[
            "--case",
            "normal",
            "--overlay",
            "occlusion-map",
            "--overlay",
            "contacts",
            "--overlay",
            "spheres:1",
        ],
    );
    let pixels: Vec<&[u8]> = buf.chunks(channels).collect();
    // Most of each surface is far from the other arch: blue dominates where the teeth are.
    let blue = pixels
        .iter()
        .filter(|p| p[2] > 150 && p[2] as i32 > p[0] as i32 + 30)
        .count();
    let share = blue as f64 / pixels.len() as f64;
    assert!(share > 0.03, "blue share {share}");
}

/// Pixels that differ clearly from the dark background (teeth, roots, overlays).
fn drawn(buf: &[u8], channels: usize) -> usize {
    buf.chunks(channels)
        .filter(|p| p[..3].iter().map(|&c| c as u32).sum::<u32>() > 3 * 70)
        .count()
}

#[test]
fn roots_hide_and_bounding_circles_show() {
    if !have_xvfb() {
        return;
    }
    let (_, _, channels, solid) = shoot(
        "solid-roots",
        &["--case", "normal", "--view", "right", "--roots", "solid"],
    );
    let (_, _, _, hidden) = shoot(
        "circles",
        &[
            "--case",
            "normal",
            "--view",
            "right",
            "--roots",
            "hidden",
            "--algorithm",
            "circles",
            "--overlay",
            "circles",
        ],
    );
    // Without roots much less of the picture is tooth.
    let (with_roots, without) = (drawn(&solid, channels), drawn(&hidden, channels));
    assert!(
        (without as f64) < 0.8 * with_roots as f64,
        "{without} drawn pixels without roots, {with_roots} with"
    );
    // The circles are drawn in green (red where a pair's circles meet).
    let green = |buf: &[u8]| {
        buf.chunks(channels)
            .filter(|p| {
                p[1] > 150 && p[1] as i32 > p[0] as i32 + 60 && p[1] as i32 > p[2] as i32 + 40
            })
            .count()
    };
    assert!(green(&hidden) > 200, "{} green pixels", green(&hidden));
    assert!(
        green(&solid) < green(&hidden) / 4,
        "{} green pixels",
        green(&solid)
    );
}

#[test]
fn the_panel_shows_over_the_view_with_a_selected_tooth() {
    if !have_xvfb() {
        return;
    }
    let region = |buf: &[u8], channels: usize, x0: usize, x1: usize| -> usize {
        // Distinct colours in columns x0..x1 of the 1280-wide image: the panel's text and
        // widgets make many, the dark background few.
        let mut seen = std::collections::HashSet::new();
        for row in buf.chunks(1280 * channels) {
            for px in row[x0 * channels..x1 * channels].chunks(channels) {
                seen.insert(px.to_vec());
            }
        }
        seen.len()
    };
    let (_, _, channels, plain) = shoot("nopanel", &["--case", "crowded"]);
    let (_, _, _, panel) = shoot("panel", &["--case", "crowded", "--panel", "--select", "42"]);
    // The panel (left) and the teeth window (right) are drawn over the view.
    let (left, right) = (
        region(&panel, channels, 0, 300),
        region(&panel, channels, 1000, 1280),
    );
    let (left0, right0) = (
        region(&plain, channels, 0, 300),
        region(&plain, channels, 1000, 1280),
    );
    assert!(left > 4 * left0.max(10), "left {left} from {left0}");
    assert!(right > 4 * right0.max(10), "right {right} from {right0}");
}

#[test]
fn the_plan_window_colours_the_teeth_by_what_they_still_have_to_move() {
    if !have_xvfb() {
        return;
    }
    // Red crowns: 2 mm or 10° still to go; green: nothing.
    let count = |buf: &[u8], channels: usize| {
        let px: Vec<&[u8]> = buf.chunks(channels).collect();
        let red = px
            .iter()
            .filter(|p| p[0] > 150 && p[1] < 100 && p[2] < 100)
            .count();
        let green = px
            .iter()
            .filter(|p| p[1] as i32 > p[0] as i32 + 30 && p[1] as i32 > p[2] as i32 + 30)
            .count();
        (red, green)
    };
    let view = [
        "--case",
        "crowded",
        "--view",
        "mandibular",
        "--hide",
        "upper",
    ];
    let (_, _, channels, first) = shoot("plan-first", &[&view[..], &["--plan", "0"]].concat());
    let (_, _, _, last) = shoot("plan-last", &[&view[..], &["--plan", "999"]].concat());
    let (red0, green0) = count(&first, channels);
    let (red1, green1) = count(&last, channels);
    // (The panel's plot draws a few hundred red pixels of its own at every stage.)
    assert!(
        red0 > red1 + 1000,
        "red pixels: {red0} at stage 0, {red1} at the last"
    );
    assert!(green1 > green0 + 2000, "green {green0} then {green1}");
}

#[test]
fn editing_the_target_draws_the_selected_tooths_handles() {
    if !have_xvfb() {
        return;
    }
    // Saturated red and blue: the mesial arrow and ring, the occlusal arrow and ring.
    let handles = |buf: &[u8], channels: usize| {
        buf.chunks(channels)
            .enumerate()
            .filter(|(i, _)| (350..700).contains(&(i % 1280)))
            .filter(|(_, p)| {
                (p[0] > 200 && p[1] < 80 && p[2] < 80) || (p[2] > 220 && p[0] < 100 && p[1] < 150)
            })
            .count()
    };
    let view = [
        "--case", "crowded", "--view", "left", "--plan", "999", "--select", "33",
    ];
    let (_, _, channels, plain) = shoot("edit-off", &view);
    let (_, _, _, edit) = shoot("edit-on", &[&view[..], &["--edit-target"]].concat());
    let (off, on) = (handles(&plain, channels), handles(&edit, channels));
    assert!(
        on > off + 300,
        "handle pixels: {off} without editing, {on} with"
    );
}

#[test]
fn the_help_window_shows_over_the_view() {
    if !have_xvfb() {
        return;
    }
    // The help window sits in the middle of the window: egui's dark grey over the teeth.
    let dark = |buf: &[u8], channels: usize| {
        buf.chunks(channels)
            .enumerate()
            .filter(|(i, _)| (400..880).contains(&(i % 1280)) && (200..520).contains(&(i / 1280)))
            .filter(|(_, p)| (20..40).contains(&p[0]) && p[0] == p[1] && p[1] == p[2])
            .count()
    };
    let view = ["--case", "normal", "--view", "frontal", "--panel"];
    let (_, _, channels, plain) = shoot("help-off", &view);
    let (_, _, _, help) = shoot("help-on", &[&view[..], &["--show-help"]].concat());
    let (off, on) = (dark(&plain, channels), dark(&help, channels));
    assert!(
        on > off + 40_000,
        "dark grey pixels: {off} without help, {on} with"
    );
}
