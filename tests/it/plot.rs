//! `--plot FILE.png`: the PNG writer (valid file, size, drawn content, text
//! with the run-time font, atomic replacement) and the subcommands that use
//! it (repose, compare, saltation), including bad paths (exit 2, no panic).

use demx::analysis::repose::projection_profile;
use demx::plot::{write_png, Chart, Series, SeriesKind, PANEL_SIZE};
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Decoded RGB(A) image: width, height, bytes per pixel, pixels.
struct Image {
    w: u32,
    h: u32,
    bpp: usize,
    px: Vec<u8>,
}

impl Image {
    fn rgb(&self, x: u32, y: u32) -> [u8; 3] {
        let i = (y as usize * self.w as usize + x as usize) * self.bpp;
        [self.px[i], self.px[i + 1], self.px[i + 2]]
    }
    /// Pixels of colour `c` in rows `rows` (all columns).
    fn count(&self, c: [u8; 3], rows: std::ops::Range<u32>) -> usize {
        rows.flat_map(|y| (0..self.w).map(move |x| (x, y))).filter(|&(x, y)| self.rgb(x, y) == c).count()
    }
}

/// Check the signature and the IHDR chunk by hand, then decode.
fn read_png(p: &Path) -> Image {
    let bytes = std::fs::read(p).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&bytes[12..16], b"IHDR", "first chunk");
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    let dec = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut r = dec.read_info().unwrap();
    let mut px = vec![0; r.output_buffer_size()];
    let info = r.next_frame(&mut px).unwrap();
    assert_eq!((info.width, info.height), (w, h));
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    let bpp = match info.color_type {
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        c => panic!("colour type {c:?}"),
    };
    px.truncate(info.buffer_size());
    Image { w, h, bpp, px }
}

/// The first series colour of the plot palette.
const BLUE: [u8; 3] = [31, 119, 180];
const ORANGE: [u8; 3] = [255, 127, 14];

fn font_present() -> bool {
    Path::new(demx::plot::DEFAULT_FONT).is_file() && std::env::var_os("DEMX_PLOT_FONT").is_none()
}

#[test]
fn two_panels_give_a_png_of_two_panel_widths_with_the_series_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("out.png");
    let sq = Series { label: "square".into(), points: vec![(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)], kind: SeriesKind::Polygon };
    let lin = Chart {
        title: "geometry".into(),
        x_label: "x (m)".into(),
        y_label: "z (m)".into(),
        equal_aspect: true,
        series: vec![sq],
        ..Chart::default()
    };
    let decay: Vec<(f64, f64)> = (0..50).map(|i| (i as f64, 10f64.powi(-i / 5))).collect();
    let err = decay.iter().map(|p| 0.3 * p.1).collect();
    let log = Chart {
        title: "decay".into(),
        log_y: true,
        series: vec![
            // a zero and a NaN cannot be drawn on a log axis: skipped, no failure
            Series { label: "line".into(), points: vec![(0.0, 1.0), (1.0, 0.0), (2.0, f64::NAN), (3.0, 1e-3)], kind: SeriesKind::Line },
            Series { label: "measured".into(), points: decay, kind: SeriesKind::ErrorBars(err) },
            Series { label: String::new(), points: vec![], kind: SeriesKind::Points },
        ],
        ..Chart::default()
    };
    write_png(&p, &[lin, log]).unwrap();
    let img = read_png(&p);
    assert_eq!((img.w, img.h), (2 * PANEL_SIZE.0, PANEL_SIZE.1));
    // the corner is the white background; the square outline (first
    // colour) is in the left panel only; the error bars (second colour) in
    // the right panel only
    assert_eq!(img.rgb(0, 0), [255, 255, 255]);
    let left = |c| (0..img.h).flat_map(|y| (0..PANEL_SIZE.0).map(move |x| (x, y))).filter(|&(x, y)| img.rgb(x, y) == c).count();
    let blue_left = left(BLUE);
    assert!(blue_left > 400, "square outline drawn: {blue_left} px");
    let orange_left = left(ORANGE);
    assert_eq!(orange_left, 0);
    assert!(img.count(ORANGE, 0..img.h) > 200);
    // equal aspect: the unit square's outline has equally long horizontal and
    // vertical sides, in pixels
    let cols: Vec<u32> = (0..PANEL_SIZE.0).filter(|&x| (0..img.h).filter(|&y| img.rgb(x, y) == BLUE).count() > 100).collect();
    let rows: Vec<u32> = (0..img.h).filter(|&y| (0..PANEL_SIZE.0).filter(|&x| img.rgb(x, y) == BLUE).count() > 100).collect();
    assert!(cols.len() >= 2 && rows.len() >= 2, "{cols:?} {rows:?}");
    let side_x = cols[cols.len() - 1] - cols[0];
    let side_y = rows[rows.len() - 1] - rows[0];
    assert!(side_x.abs_diff(side_y) <= 2, "square drawn {side_x} x {side_y} px");
    if font_present() {
        // the title strip holds dark text pixels
        let dark = (0..30).flat_map(|y| (0..img.w).map(move |x| (x, y))).filter(|&(x, y)| img.rgb(x, y).iter().all(|&c| c < 100)).count();
        assert!(dark > 50, "title text drawn: {dark} px");
    }
    // readable like any other output (the temporary file is private)
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        assert_eq!(std::fs::metadata(&p).unwrap().permissions().mode() & 0o777, 0o644);
    }
    // no temporary file left beside the result
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, vec![std::ffi::OsString::from("out.png")]);
}

#[test]
fn write_png_replaces_a_file_and_rejects_bad_targets() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("old.png");
    std::fs::write(&p, b"not a png").unwrap();
    let c = Chart { series: vec![Series { label: "a".into(), points: vec![(1.0, 2.0), (2.0, 2.0)], kind: SeriesKind::Line }], ..Chart::default() };
    write_png(&p, std::slice::from_ref(&c)).unwrap();
    assert_eq!(read_png(&p).w, PANEL_SIZE.0);
    for bad in [dir.path().join("missing/x.png"), dir.path().join("x.jpg"), dir.path().to_path_buf()] {
        let e = write_png(&bad, std::slice::from_ref(&c)).unwrap_err();
        assert_eq!(e.exit_code(), 2, "{bad:?}: {e}");
        assert!(e.message().contains("cannot write plot"), "{}", e.message());
    }
    assert_eq!(write_png(&dir.path().join("empty.png"), &[]).unwrap_err().exit_code(), 2);
}

#[test]
fn fitted_triangle_has_the_boundary_area_and_the_repose_angle() {
    // one sphere r = 1 resting on the plate: boundary area 2 + pi/2 over base 2,
    // so the same-area triangle is (2 + pi/2) high with base corners at -1, 1
    let p = projection_profile(&[0.0], &[1.0], &[1.0], 1e-4).unwrap();
    let [a, apex, b] = p.triangle();
    let h = 2.0 + std::f64::consts::FRAC_PI_2;
    assert!((a.0 + 1.0).abs() < 2e-4 && (b.0 - 1.0).abs() < 2e-4, "{a:?} {b:?}");
    assert!(a.1 == 0.0 && b.1 == 0.0 && apex.0.abs() < 2e-4);
    assert!((apex.1 - h).abs() < 1e-3, "{apex:?}");
    assert!((p.theta - h.atan().to_degrees()).abs() < 0.01);
    // the boundary over the sphere's centre is its top
    let mid = p.top.iter().cloned().fold(0.0, f64::max);
    assert!((mid - 2.0).abs() < 1e-6);
}

fn demx(args: &[&str], env: &[(&str, &str)]) -> (i32, String, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_demx"));
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    let o = c.output().unwrap();
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stdout).into(), String::from_utf8_lossy(&o.stderr).into())
}

/// A heap of r = 0.5 spheres: a 30-degree cone of base radius 8 on z = 0.
fn heap_dump(dir: &Path) -> PathBuf {
    let t = 30f64.to_radians().tan();
    let mut atoms = vec![];
    for i in -18..=18 {
        for j in -18..=18 {
            let (x, y) = (0.5 * i as f64, 0.5 * j as f64);
            let rho = (x * x + y * y).sqrt();
            if rho <= 8.0 {
                atoms.push([x, y, (t * (8.0 - rho) - 0.5 / 30f64.to_radians().cos()).max(0.5)]);
            }
        }
    }
    let mut s = format!("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n{}\nITEM: BOX BOUNDS ff ff ff\n-10 10\n-10 10\n-1 10\n", atoms.len());
    s.push_str("ITEM: ATOMS id type radius x y z\n");
    for (i, a) in atoms.iter().enumerate() {
        writeln!(s, "{} 1 0.5 {} {} {}", i + 1, a[0], a[1], a[2]).unwrap();
    }
    let p = dir.join("heap.dump");
    std::fs::write(&p, s).unwrap();
    p
}

#[test]
fn repose_plot_draws_both_projections() {
    let dir = tempfile::tempdir().unwrap();
    let d = heap_dump(dir.path());
    let out = dir.path().join("heap.png");
    let (code, stdout, stderr) = demx(&["repose", d.to_str().unwrap(), "--plot", out.to_str().unwrap()], &[]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("theta_r"), "{stdout}");
    // the Bond number says which surface energy it assumed, and takes --gamma
    assert!(stdout.contains("with gamma = 0.05 J/m^2"), "{stdout}");
    let (_, stdout_g, _) = demx(&["repose", d.to_str().unwrap(), "--gamma", "0.5"], &[]);
    let bo = |s: &str| -> f64 { s.split("rho) = ").nth(1).and_then(|t| t.split_whitespace().next()).and_then(|x| x.parse().ok()).unwrap() };
    assert!((bo(&stdout_g) / bo(&stdout) - 10.0).abs() < 1e-9, "{stdout_g}");
    let img = read_png(&out);
    assert_eq!((img.w, img.h), (2 * PANEL_SIZE.0, PANEL_SIZE.1));
    // boundary (first colour) and triangle (second) in each panel
    for panel in 0..2 {
        let xs = panel * PANEL_SIZE.0..(panel + 1) * PANEL_SIZE.0;
        let n = |c| xs.clone().flat_map(|x| (0..img.h).map(move |y| (x, y))).filter(|&(x, y)| img.rgb(x, y) == c).count();
        assert!(n(BLUE) > 300 && n(ORANGE) > 300, "panel {panel}: {} {}", n(BLUE), n(ORANGE));
    }
}

#[test]
fn repose_plot_without_font_still_draws_and_warns() {
    let dir = tempfile::tempdir().unwrap();
    let d = heap_dump(dir.path());
    let out = dir.path().join("heap.png");
    let (code, _, stderr) = demx(&["repose", d.to_str().unwrap(), "--plot", out.to_str().unwrap()], &[("DEMX_PLOT_FONT", "/nonexistent/font.ttf")]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("warning") && stderr.contains("without text"), "{stderr}");
    let img = read_png(&out);
    assert!(img.count(BLUE, 0..img.h) > 300);
}

#[test]
fn bad_plot_paths_exit_2_with_a_message() {
    let dir = tempfile::tempdir().unwrap();
    let d = heap_dump(dir.path());
    let d = d.to_str().unwrap();
    let missing = dir.path().join("no/such/dir/p.png");
    let jpg = dir.path().join("p.jpg");
    for bad in [missing.to_str().unwrap(), jpg.to_str().unwrap(), dir.path().to_str().unwrap()] {
        let (code, _, stderr) = demx(&["repose", d, "--plot", bad], &[]);
        assert_eq!(code, 2, "{bad}: {stderr}");
        assert!(stderr.contains("cannot write plot") && !stderr.contains("panicked"), "{stderr}");
    }
    let (code, _, stderr) = demx(&["saltation", "--plot", missing.to_str().unwrap(), d], &[]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("cannot write plot"), "{stderr}");
    let (code, _, stderr) = demx(&["compare", d, d, "--plot", missing.to_str().unwrap()], &[]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("cannot write plot"), "{stderr}");
}

fn two_frames(dir: &Path, name: &str, dx: f64) -> String {
    let mut s = String::new();
    for step in [0, 100, 200] {
        let x = 0.001 + dx * step as f64 / 100.0;
        write!(
            s,
            "ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp ff\n0 0.01\n0 0.01\n0 0.01\n\
             ITEM: ATOMS id type x y z vx vy vz radius mass\n1 1 {x} 0.005 0.005 1.0 0 0 5e-4 1e-6\n2 1 0.007 0.005 0.005 -0.5 0 0 5e-4 1e-6\n"
        )
        .unwrap();
    }
    let p = dir.join(name);
    std::fs::write(&p, s).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn compare_and_saltation_plots() {
    let dir = tempfile::tempdir().unwrap();
    let a = two_frames(dir.path(), "a.dump", 0.0);
    let b = two_frames(dir.path(), "b.dump", 1e-5);
    let out = dir.path().join("cmp.png");
    let (code, _, stderr) = demx(&["compare", &a, &b, "--plot", out.to_str().unwrap()], &[]);
    // particle 1 of B drifts by 0.01 d per 100 steps: beyond the tolerance
    assert_eq!(code, 1, "{stderr}");
    let img = read_png(&out);
    assert_eq!(img.w, 2 * PANEL_SIZE.0);
    // RMS (first colour) on the log deviation panel, A's KE on the right
    assert!(img.count(BLUE, 0..img.h) > 200);
    let out = dir.path().join("q.png");
    let (code, stdout, stderr) = demx(&["saltation", "--from", "150", "--plot", out.to_str().unwrap(), &a], &[]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.starts_with("step,time,Q"), "{stdout}");
    let img = read_png(&out);
    // the flux over time, and the concentration profile above the bed (the
    // dump has z, vz and radius, and both grains fly above the floor)
    assert_eq!((img.w, img.h), (2 * PANEL_SIZE.0, PANEL_SIZE.1));
    let blue_in = |x0: u32, x1: u32| (0..img.h).flat_map(|y| (x0..x1).map(move |x| (x, y))).filter(|&(x, y)| img.rgb(x, y) == BLUE).count();
    assert!(blue_in(0, PANEL_SIZE.0) > 200, "flux curve");
    assert!(blue_in(PANEL_SIZE.0, img.w) > 20, "profile markers");
    // a dump without heights has the flux panel alone
    let flat = dir.path().join("flat.dump");
    std::fs::write(&flat, std::fs::read_to_string(&a).unwrap().replace("id type x y z vx vy vz radius mass", "id type x y zz vx vy vz radius mass"))
        .unwrap();
    let out = dir.path().join("q1.png");
    let (code, _, stderr) = demx(&["saltation", "--plot", out.to_str().unwrap(), flat.to_str().unwrap()], &[]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!((read_png(&out).w, read_png(&out).h), PANEL_SIZE);
}
