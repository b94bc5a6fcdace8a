//! The real window, under Xvfb with Mesa's software drivers: `orthosim screenshot` opens it,
//! simulates and saves a PNG. Runs when `xvfb-run` is installed (`.ci/run` installs it), and says it
//! skipped otherwise.

use std::process::Command;

#[test]
fn screenshot_renders_the_teeth_in_a_real_window() {
    let have_xvfb = Command::new("xvfb-run")
        .arg("--help")
        .output()
        .is_ok_and(|o| o.status.success() || !o.stdout.is_empty() || !o.stderr.is_empty());
    if !have_xvfb {
        eprintln!("skipped: xvfb-run is not installed (Debian packages xvfb, mesa-vulkan-drivers)");
        return;
    }
    let out = std::env::temp_dir().join(format!("orthosim-shot-{}.png", std::process::id()));
    let _ = std::fs::remove_file(&out);
    let run = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24"])
        .arg(env!("CARGO_BIN_EXE_orthosim"))
        .args([
            "screenshot",
            "--case",
            "case1",
            "--view",
            "frontal",
            "--tree",
            "octree",
            "--frames",
            "20",
            "--out",
        ])
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
    assert_eq!((info.width, info.height), (1280, 720), "the window's size");
    let channels = info.color_type.samples();
    let pixels: Vec<&[u8]> = buf[..info.buffer_size()].chunks(channels).collect();
    let distinct: std::collections::HashSet<&[u8]> = pixels.iter().copied().collect();
    assert!(distinct.len() > 200, "{} colours: blank?", distinct.len());
    // Teeth are light on a dark background: a good share of bright pixels.
    let bright = pixels
        .iter()
        .filter(|p| p[..3].iter().all(|&c| c > 150))
        .count();
    let share = bright as f64 / pixels.len() as f64;
    assert!(share > 0.03 && share < 0.8, "bright share {share}");
    let _ = std::fs::remove_file(&out);
}
