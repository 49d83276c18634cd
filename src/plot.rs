//! PNG charts for the analysis subcommands (`--plot FILE.png`): x-y charts of
//! lines, points, error bars and closed outlines, several panels side by side.
//!
//! The one entry point is [`write_png`]; callers describe what to draw with
//! [`Chart`] and [`Series`] and never touch the drawing backend (plotters,
//! bitmap backend). Text (titles, axis labels, tick labels, legends) is drawn
//! with the DejaVu Sans font read at run time from
//! [`DEFAULT_FONT`] (Debian package `fonts-dejavu-core`; the environment
//! variable `DEMX_PLOT_FONT` names another TrueType/OpenType file). Without a
//! usable font the charts are drawn without any text and a warning is printed
//! once. The image is drawn in memory, then written to a temporary file next
//! to the target and renamed, so an interrupted run never leaves a partial
//! PNG under the requested name.

use crate::error::{Error, Result};
use plotters::coord::ranged1d::{AsRangedCoord, Ranged};
use plotters::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

/// How a series is drawn.
#[derive(Clone, Debug, PartialEq)]
pub enum SeriesKind {
    /// Points joined by straight lines.
    Line,
    /// Markers only.
    Points,
    /// Markers with symmetric vertical error bars (one half-width per point).
    ErrorBars(Vec<f64>),
    /// A closed outline (polygon), e.g. a fitted triangle.
    Polygon,
}

/// One data series of a chart.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend label (empty: no legend entry).
    pub label: String,
    /// (x, y) points in data units.
    pub points: Vec<(f64, f64)>,
    /// Drawing style.
    pub kind: SeriesKind,
}

/// One panel: axes, labels and series.
#[derive(Clone, Debug, Default)]
pub struct Chart {
    /// Panel title.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// Equal scales on both axes (geometry, e.g. heap projections).
    pub equal_aspect: bool,
    /// The series, drawn in order.
    pub series: Vec<Series>,
}

/// Font file read for chart text unless `DEMX_PLOT_FONT` names another.
pub const DEFAULT_FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

/// Width and height of one panel, pixels.
pub const PANEL_SIZE: (u32, u32) = (640, 480);

/// Most panels in one image.
const MAX_PANELS: usize = 32;
/// Font family name the loaded font is registered under.
const FAMILY: &str = "sans-serif";
/// Outer margin of a panel, pixels.
const MARGIN: u32 = 12;
/// Height of the area below the plot (tick labels + x label), pixels.
const X_LABEL_AREA: u32 = 44;
/// Width of the area left of the plot (tick labels + y label), pixels.
const Y_LABEL_AREA: u32 = 78;

/// Colours of successive series (the "tab10" palette).
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Whether chart text can be drawn: loads and registers the font once; on
/// failure prints one warning and returns false from then on.
fn text_enabled() -> bool {
    static FONT: OnceLock<bool> = OnceLock::new();
    *FONT.get_or_init(|| {
        let path = std::env::var_os("DEMX_PLOT_FONT").unwrap_or_else(|| DEFAULT_FONT.into());
        let shown = Path::new(&path).display().to_string();
        let bytes = match std::fs::read(&path) {
            Ok(b) => b,
            Err(e) => {
                eprintln!(
                    "warning: cannot read font '{shown}' ({e}): plots are drawn without text \
                     (install fonts-dejavu-core, or set DEMX_PLOT_FONT to a .ttf file)"
                );
                return false;
            }
        };
        // The font table of plotters keeps &'static references; the font is
        // loaded once per process, so leaking it is bounded.
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        if plotters::style::register_font(FAMILY, FontStyle::Normal, bytes).is_err() {
            eprintln!("warning: '{shown}' is not a TrueType/OpenType font: plots are drawn without text");
            return false;
        }
        true
    })
}

/// Check before any work that `path` can take a PNG: a `.png` name in an
/// existing directory. [`write_png`] checks the same; callers use this to
/// fail before a long analysis.
pub fn check_path(path: &Path) -> Result<()> {
    let ok_ext = path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !ok_ext {
        return Err(Error::usage(format!("cannot write plot '{}': the file name must end in .png", path.display())));
    }
    if path.file_name().is_none() {
        return Err(Error::usage(format!("cannot write plot '{}': not a file name", path.display())));
    }
    let dir = parent_dir(path);
    if !dir.is_dir() {
        return Err(Error::usage(format!("cannot write plot '{}': directory '{}' does not exist", path.display(), dir.display())));
    }
    if path.is_dir() {
        return Err(Error::usage(format!("cannot write plot '{}': it is a directory", path.display())));
    }
    Ok(())
}

fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Write the charts side by side into one PNG file.
pub fn write_png(path: &Path, charts: &[Chart]) -> Result<()> {
    check_path(path)?;
    if charts.is_empty() {
        return Err(Error::usage(format!("cannot write plot '{}': nothing to plot", path.display())));
    }
    if charts.len() > MAX_PANELS {
        return Err(Error::usage(format!("cannot write plot '{}': {} panels (at most {MAX_PANELS})", path.display(), charts.len())));
    }
    let text = text_enabled();
    let (w, h) = (PANEL_SIZE.0 * charts.len() as u32, PANEL_SIZE.1);
    let fail = |what: String| Error::runtime(format!("cannot draw plot '{}': {what}", path.display()));
    // Draw in memory first; plotters is third-party code, so a panic inside it
    // becomes an error instead of ending the program.
    let drawn = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| -> std::result::Result<Vec<u8>, String> {
        let mut buf = vec![0u8; (w * h * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            let panels = root.split_evenly((1, charts.len()));
            for (chart, area) in charts.iter().zip(&panels) {
                draw_panel(area, chart, text)?;
            }
            root.present().map_err(|e| e.to_string())?;
        }
        Ok(buf)
    }));
    let buf = match drawn {
        Ok(Ok(b)) => b,
        Ok(Err(e)) => return Err(fail(e)),
        Err(_) => return Err(fail("the drawing library failed".into())),
    };
    save_atomically(path, &buf, (w, h))
}

/// Encode `buf` (RGB, `w` x `h`) as PNG into a temporary file beside `path`,
/// then rename it to `path`.
fn save_atomically(path: &Path, buf: &[u8], (w, h): (u32, u32)) -> Result<()> {
    let io = |e: &dyn std::fmt::Display| Error::usage(format!("cannot write plot '{}': {e}", path.display()));
    let tmp = tempfile::Builder::new().prefix(".demx-plot-").suffix(".png").tempfile_in(parent_dir(path)).map_err(|e| io(&e))?;
    {
        let mut bm = BitMapBackend::new(tmp.path(), (w, h));
        bm.blit_bitmap((0, 0), (w, h), buf).map_err(|e| io(&e))?;
        bm.present().map_err(|e| io(&e))?;
    }
    crate::io::persist_public(tmp, path).map_err(|e| io(&e))
}

/// Axis range of one axis over every drawable value.
#[derive(Clone, Copy, Debug)]
struct Span {
    lo: f64,
    hi: f64,
}

impl Span {
    /// Range covering `values` (non-finite and, on log axes, non-positive
    /// values skipped), padded; a default when nothing is left.
    fn of(values: impl Iterator<Item = f64>, log: bool) -> Span {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values.filter(|v| usable(*v, log)) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if lo > hi {
            return if log { Span { lo: 1.0, hi: 10.0 } } else { Span { lo: 0.0, hi: 1.0 } };
        }
        if log {
            let (l, h) = (lo.log10(), hi.log10());
            let pad = if h > l { 0.05 * (h - l) } else { 0.5 };
            return Span { lo: 10f64.powf(l - pad), hi: 10f64.powf(h + pad) };
        }
        let d = hi - lo;
        if d > 0.0 && d.is_finite() {
            Span { lo: lo - 0.05 * d, hi: hi + 0.05 * d }
        } else {
            let p = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
            Span { lo: lo - p, hi: hi + p }
        }
    }
    fn width(&self) -> f64 {
        self.hi - self.lo
    }
    /// Widen around the centre to `w`.
    fn widen(&mut self, w: f64) {
        let c = 0.5 * (self.lo + self.hi);
        self.lo = c - 0.5 * w;
        self.hi = c + 0.5 * w;
    }
}

fn usable(v: f64, log: bool) -> bool {
    v.is_finite() && v.abs() < 1e300 && (!log || v > 0.0)
}

/// Every value a series puts on the x (`false`) or y (`true`) axis.
fn series_values(s: &Series, y: bool) -> Vec<f64> {
    let mut out: Vec<f64> = s.points.iter().map(|p| if y { p.1 } else { p.0 }).collect();
    if let (true, SeriesKind::ErrorBars(e)) = (y, &s.kind) {
        for (p, e) in s.points.iter().zip(e) {
            if e.is_finite() {
                out.push(p.1 - e.abs());
                out.push(p.1 + e.abs());
            }
        }
    }
    out
}

/// Tick label: plain decimals for moderate magnitudes, else scientific.
fn fmt_tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        return "0".into();
    }
    if (1e-3..1e5).contains(&a) {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        return if s == "-0" { "0".into() } else { s.to_string() };
    }
    let s = format!("{v:.2e}");
    match s.split_once('e') {
        Some((m, e)) => {
            let m = m.trim_end_matches('0').trim_end_matches('.');
            format!("{m}e{e}")
        }
        None => s,
    }
}

/// Draw one panel into `area`.
fn draw_panel(area: &DrawingArea<BitMapBackend, plotters::coord::Shift>, c: &Chart, text: bool) -> std::result::Result<(), String> {
    let xs = c.series.iter().flat_map(|s| series_values(s, false));
    let ys = c.series.iter().flat_map(|s| series_values(s, true));
    let mut sx = Span::of(xs, c.log_x);
    let mut sy = Span::of(ys, c.log_y);
    let (xl, yl) = if text { (X_LABEL_AREA, Y_LABEL_AREA) } else { (0, 0) };
    // The title takes its own strip, so the plot's pixel size is known
    // exactly (equal aspect needs it).
    let area = if text && !c.title.is_empty() { area.titled(&c.title, (FAMILY, 18)).map_err(|e| e.to_string())? } else { area.clone() };
    if c.equal_aspect && !c.log_x && !c.log_y {
        let (w, h) = area.dim_in_pixel();
        // plotters maps the range onto pixels 0 ..= size - 1
        let pw = w.saturating_sub(2 * MARGIN + yl + 1).max(1) as f64;
        let ph = h.saturating_sub(2 * MARGIN + xl + 1).max(1) as f64;
        let scale = (sx.width() / pw).max(sy.width() / ph);
        if scale.is_finite() && scale > 0.0 {
            sx.widen(scale * pw);
            sy.widen(scale * ph);
        }
    }
    let mut b = ChartBuilder::on(&area);
    b.margin(MARGIN).x_label_area_size(xl).y_label_area_size(yl);
    let (x, y) = (sx.lo..sx.hi, sy.lo..sy.hi);
    match (c.log_x, c.log_y) {
        (false, false) => finish(b, x, y, c, text),
        (true, false) => finish(b, x.log_scale(), y, c, text),
        (false, true) => finish(b, x, y.log_scale(), c, text),
        (true, true) => finish(b, x.log_scale(), y.log_scale(), c, text),
    }
}

/// Build the axes and draw mesh, series and legend.
fn finish<X, Y>(mut b: ChartBuilder<BitMapBackend>, x: X, y: Y, c: &Chart, text: bool) -> std::result::Result<(), String>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>,
    Y::CoordDescType: Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>,
{
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let mut ch = b.build_cartesian_2d(x, y).map_err(|e| err(&e))?;
    {
        let fmt = |v: &f64| fmt_tick(*v);
        let mut mesh = ch.configure_mesh();
        mesh.x_label_formatter(&fmt).y_label_formatter(&fmt).x_labels(8).y_labels(8);
        if text {
            mesh.x_desc(c.x_label.as_str()).y_desc(c.y_label.as_str()).label_style((FAMILY, 13)).axis_desc_style((FAMILY, 15));
        }
        mesh.draw().map_err(|e| err(&e))?;
    }
    if !text {
        // No tick labels without a font: frame the plot so the axes show.
        let (xr, yr) = (ch.x_range(), ch.y_range());
        let frame = vec![(xr.start, yr.start), (xr.end, yr.start), (xr.end, yr.end), (xr.start, yr.end), (xr.start, yr.start)];
        ch.draw_series(std::iter::once(PathElement::new(frame, BLACK))).map_err(|e| err(&e))?;
    }
    let mut labelled = false;
    for (k, s) in c.series.iter().enumerate() {
        let color = PALETTE[k % PALETTE.len()];
        let style = ShapeStyle::from(&color).stroke_width(2);
        let ok = |p: &(f64, f64)| usable(p.0, c.log_x) && usable(p.1, c.log_y);
        let anno = match &s.kind {
            SeriesKind::Line => {
                // A value that cannot be shown (NaN, <= 0 on a log axis) breaks the line.
                let mut runs: Vec<Vec<(f64, f64)>> = vec![vec![]];
                for p in &s.points {
                    match (ok(p), runs.last_mut()) {
                        (true, Some(r)) => r.push(*p),
                        (false, Some(r)) if !r.is_empty() => runs.push(vec![]),
                        _ => {}
                    }
                }
                let elems: Vec<_> = runs.into_iter().filter(|r| !r.is_empty()).map(|r| PathElement::new(r, style)).collect();
                ch.draw_series(elems).map_err(|e| err(&e))?
            }
            SeriesKind::Points => {
                let elems: Vec<_> = s.points.iter().filter(|p| ok(p)).map(|p| Circle::new(*p, 3, color.filled())).collect();
                ch.draw_series(elems).map_err(|e| err(&e))?
            }
            SeriesKind::ErrorBars(e) => {
                let mut elems = vec![];
                for (i, p) in s.points.iter().enumerate().filter(|(_, p)| ok(p)) {
                    let half = e.get(i).copied().filter(|v| v.is_finite()).map_or(0.0, f64::abs);
                    let (mut lo, hi) = (p.1 - half, p.1 + half);
                    if c.log_y && !(lo > 0.0) {
                        lo = p.1 * 1e-3;
                    }
                    elems.push(ErrorBar::new_vertical(p.0, lo, p.1, hi, style, 8));
                }
                ch.draw_series(elems).map_err(|e| err(&e))?;
                let dots: Vec<_> = s.points.iter().filter(|p| ok(p)).map(|p| Circle::new(*p, 3, color.filled())).collect();
                ch.draw_series(dots).map_err(|e| err(&e))?
            }
            SeriesKind::Polygon => {
                let mut pts: Vec<(f64, f64)> = s.points.iter().filter(|p| ok(p)).copied().collect();
                if let Some(first) = pts.first().copied() {
                    pts.push(first);
                }
                ch.draw_series(std::iter::once(PathElement::new(pts, style))).map_err(|e| err(&e))?
            }
        };
        if text && !s.label.is_empty() {
            labelled = true;
            let marker = s.kind.clone();
            anno.label(s.label.as_str()).legend(move |(x, y)| -> DynElement<'static, BitMapBackend, (i32, i32)> {
                match marker {
                    SeriesKind::Points | SeriesKind::ErrorBars(_) => Circle::new((x + 10, y), 3, color.filled()).into_dyn(),
                    _ => PathElement::new(vec![(x, y), (x + 20, y)], style).into_dyn(),
                }
            });
        }
    }
    if labelled {
        ch.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.5))
            .label_font((FAMILY, 13))
            .draw()
            .map_err(|e| err(&e))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_short() {
        assert_eq!(fmt_tick(0.0), "0");
        assert_eq!(fmt_tick(0.25), "0.25");
        assert_eq!(fmt_tick(-3.0), "-3");
        assert_eq!(fmt_tick(1.5e-6), "1.5e-6");
        assert_eq!(fmt_tick(2.0e7), "2e7");
    }

    #[test]
    fn equal_spans_pad_and_skip_unplottable() {
        let s = Span::of([1.0, 3.0, f64::NAN].into_iter(), false);
        assert!((s.lo - 0.9).abs() < 1e-12 && (s.hi - 3.1).abs() < 1e-12);
        let l = Span::of([0.0, -1.0, 10.0, 1000.0].into_iter(), true);
        assert!((l.lo.log10() + 0.1 - 1.0).abs() < 1e-12 && (l.hi.log10() - 3.1).abs() < 1e-12);
        let d = Span::of([5.0].into_iter(), false);
        assert!((d.lo - 4.5).abs() < 1e-12 && (d.hi - 5.5).abs() < 1e-12);
    }
}
