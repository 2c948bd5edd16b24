//! Line plots with plotters, written as PNG and SVG. Text uses an embedded DejaVu Sans (font/,
//! Bitstream Vera licence) through plotters' `ab_glyph` backend, so no system fonts are needed.
//! Files are drawn to a buffer (PNG, encoded by the png crate) or a string (SVG) and written
//! atomically.

use plotters::prelude::*;
use plotters::style::FontStyle;
use stamp::io::write_string_atomically;
use stamp::{Result, StampError};
use std::path::{Path, PathBuf};
use std::sync::Once;

static FONT: Once = Once::new();
const FONT_NAME: &str = "stamp-sans";

fn register_font() {
    FONT.call_once(|| {
        // the font is compiled in and valid: a failure here is a build defect, reported by draw errors
        let _ = plotters::style::register_font(FONT_NAME, FontStyle::Normal, include_bytes!("font/DejaVuSans.ttf"));
    });
}

/// One curve.
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Points drawn as markers (e.g. where the data are nodal values); may be empty.
    pub markers: Vec<(f64, f64)>,
}

/// A plot description.
pub struct Plot<'a> {
    /// One line, or several separated by '\n'.
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub series: &'a [Series],
}

/// Okabe & Ito's colour-blind-safe palette without its yellow (unreadable on white), then grey.
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),   // blue
    RGBColor(213, 94, 0),    // vermillion
    RGBColor(0, 158, 115),   // bluish green
    RGBColor(204, 121, 167), // reddish purple
    RGBColor(86, 180, 233),  // sky blue
    RGBColor(230, 159, 0),   // orange
    RGBColor(0, 0, 0),       // black
    RGBColor(128, 128, 128), // grey
];

/// The colour of curve `k`.
pub fn colour(k: usize) -> RGBColor {
    PALETTE[k % PALETTE.len()]
}

fn plot_err(path: &Path, e: impl std::fmt::Display) -> StampError {
    StampError::Input { file: path.display().to_string(), message: format!("cannot draw the plot: {e}") }
}

fn range(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in v.filter(|x| x.is_finite()) {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi - lo <= 1e-12 * hi.abs().max(lo.abs()).max(1e-300) {
        let d = hi.abs().max(1.0) * 0.5;
        return (lo - d, hi + d);
    }
    let pad = 0.03 * (hi - lo);
    (lo - pad, hi + pad)
}

const WIDTH: u32 = 1000;
const HEIGHT: u32 = 620;
const LABEL_FONT: u32 = 16;

/// Width of the legend column to the right of the axes (0 without labels): the legend never covers
/// a curve.
fn legend_width(p: &Plot) -> u32 {
    let longest = p.series.iter().map(|s| s.label.chars().count()).max().unwrap_or(0);
    if longest == 0 {
        0
    } else {
        (longest as u32 * 9 + 60).min(WIDTH / 3)
    }
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, plotters::coord::Shift>, p: &Plot) -> std::result::Result<(), String>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    // a title of several lines: each its own line, the first in the larger font
    let mut area = root.clone();
    for (k, line) in p.title.lines().enumerate() {
        area = area.titled(line, (FONT_NAME, if k == 0 { 22 } else { 18 })).map_err(|e| e.to_string())?;
    }
    let lw = legend_width(p);
    let (plot_area, legend_area) = area.split_horizontally(WIDTH - lw);
    let (x0, x1) = range(p.series.iter().flat_map(|s| s.points.iter().chain(&s.markers).map(|q| q.0)));
    let (mut y0, mut y1) = range(p.series.iter().flat_map(|s| s.points.iter().chain(&s.markers).map(|q| q.1)));
    if y0 > 0.0 {
        y0 = 0.0;
    }
    if y1 < 0.0 {
        y1 = 0.0;
    }
    let mut chart = ChartBuilder::on(&plot_area)
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(p.x_label)
        .y_desc(p.y_label)
        .light_line_style(RGBColor(235, 235, 235))
        .label_style((FONT_NAME, LABEL_FONT))
        .axis_desc_style((FONT_NAME, 18))
        .draw()
        .map_err(|e| e.to_string())?;
    for (k, s) in p.series.iter().enumerate() {
        let color = colour(k);
        chart.draw_series(LineSeries::new(s.points.iter().copied(), color.stroke_width(2))).map_err(|e| e.to_string())?;
        chart.draw_series(s.markers.iter().map(|&q| Circle::new(q, 4, color.filled()))).map_err(|e| e.to_string())?;
    }
    if lw > 0 {
        let font = (FONT_NAME, LABEL_FONT).into_font().color(&BLACK);
        for (k, s) in p.series.iter().enumerate() {
            let y = 30 + 26 * k as i32;
            let color = colour(k);
            legend_area.draw(&PathElement::new(vec![(8, y), (38, y)], color.stroke_width(2))).map_err(|e| e.to_string())?;
            if !s.markers.is_empty() {
                legend_area.draw(&Circle::new((23, y), 4, color.filled())).map_err(|e| e.to_string())?;
            }
            legend_area.draw(&Text::new(s.label.clone(), (46, y - 8), font.clone())).map_err(|e| e.to_string())?;
        }
    }
    root.present().map_err(|e| e.to_string())?;
    Ok(())
}

/// Encode an 8-bit RGB image of WIDTH x HEIGHT as PNG.
fn encode_png(w: &mut dyn std::io::Write, rgb: &[u8]) -> std::io::Result<()> {
    let mut encoder = png::Encoder::new(w, WIDTH, HEIGHT);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    // the library default (fast) gives files three times larger for line plots
    encoder.set_compression(png::Compression::Default);
    encoder.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
    let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
    writer.write_image_data(rgb).map_err(std::io::Error::other)?;
    writer.finish().map_err(std::io::Error::other)
}

/// Draw `p` into `<stem>.png` and `<stem>.svg`. Returns the two paths.
pub fn write_plot(stem: &Path, p: &Plot) -> Result<[PathBuf; 2]> {
    register_font();
    let png = stem.with_extension("png");
    let svg = stem.with_extension("svg");
    // SVG into a string, written atomically
    let mut text = String::new();
    draw(SVGBackend::with_string(&mut text, (WIDTH, HEIGHT)).into_drawing_area(), p).map_err(|e| plot_err(&svg, e))?;
    write_string_atomically(&svg, &text)?;
    // PNG: drawn into an RGB buffer, encoded by the png crate, written atomically (plotters' own
    // encoder would build the `image` crate with its JPEG and BMP codecs, a twentieth of the build)
    let mut rgb = vec![0u8; WIDTH as usize * HEIGHT as usize * 3];
    draw(BitMapBackend::with_buffer(&mut rgb, (WIDTH, HEIGHT)).into_drawing_area(), p).map_err(|e| plot_err(&png, e))?;
    stamp::io::write_atomically(&png, |w| encode_png(w, &rgb))?;
    Ok([png, svg])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The PNG decodes to the plot's size, and the curve (blue, the first series' colour) and the
    /// black text are in it; the SVG has the title.
    #[test]
    fn a_plot_is_written_as_a_png_that_decodes_and_an_svg() {
        let dir = std::env::temp_dir().join(format!("stamp-plot-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let series = [Series { label: "x^2".into(), points: (0..50).map(|i| (i as f64 / 10.0, (i as f64 / 10.0).powi(2))).collect(), markers: vec![] }];
        let p = Plot { title: "a parabola", x_label: "x", y_label: "y", series: &series };
        let [png_path, svg_path] = write_plot(&dir.join("parabola"), &p).unwrap();
        let decoder = png::Decoder::new(std::fs::File::open(&png_path).unwrap());
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height, info.color_type), (WIDTH, HEIGHT, png::ColorType::Rgb));
        let pixels: Vec<&[u8]> = buf[..info.buffer_size()].chunks(3).collect();
        let dark = pixels.iter().filter(|c| c.iter().all(|v| *v < 60)).count();
        let bluish = pixels.iter().filter(|c| c[2] > 120 && c[0] < 60).count();
        assert!(dark > 500 && bluish > 500, "dark {dark}, blue {bluish} pixels");
        assert!(std::fs::read_to_string(&svg_path).unwrap().contains("a parabola"));
        // no temporary file left beside them
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
