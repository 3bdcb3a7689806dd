//! Pictures: one drawing for SVG and PNG. The text font (DejaVu Sans, `host/assets/`, Bitstream Vera licence) is
//! compiled into the binary and registered with plotters' own font rasteriser, so PNG pictures carry the same
//! labels as SVG without a system font library.

use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

/// The font every picture's text uses.
pub const FONT: &str = "sans-serif";

static FONT_DATA: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TrueType font (checked by the test below); a failure leaves text undrawn in PNG
        // only, never a panic.
        let _ = register_font(FONT, FontStyle::Normal, FONT_DATA);
    });
}

/// Why a picture was not written.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Drawing or writing it failed (plotters' error, which differs by backend, in words).
    #[error("{}: {reason}", path.display())]
    Draw {
        /// The picture's file.
        path: PathBuf,
        /// What failed.
        reason: String,
    },
    /// The file's name says no format this writes.
    #[error("{}: a picture is .svg or .png", .0.display())]
    Format(PathBuf),
}

/// Maps a plotting error to one that names the picture.
pub fn failed(out: &Path) -> impl Fn(&dyn std::fmt::Display) -> PlotError + '_ {
    move |e| PlotError::Draw {
        path: out.to_path_buf(),
        reason: e.to_string(),
    }
}

/// Something drawn on any plotters backend.
pub trait Picture {
    /// Draws on `root`; `fail` names the picture in errors.
    fn paint<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, out: &Path) -> Result<(), PlotError>
    where
        DB::ErrorType: 'static;
}

/// Fills the picture white and writes `title` (of `size` points) in a 40-pixel band at the top; the area below.
pub fn titled<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    size: u32,
    out: &Path,
) -> Result<DrawingArea<DB, Shift>, PlotError>
where
    DB::ErrorType: 'static,
{
    let fail = failed(out);
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let (band, body) = root.split_vertically(40);
    band.draw(&Text::new(title.to_owned(), (20, 12), (FONT, size)))
        .map_err(|e| fail(&e))?;
    Ok(body)
}

/// Writes `picture` to `out`: SVG when the name ends in `.svg`, PNG when it ends in `.png`. It is drawn in memory
/// and written whole ([`super::file::write`]): a full disk leaves no partial picture behind, and is an error.
pub fn save(out: &Path, size: (u32, u32), picture: &impl Picture) -> Result<(), PlotError> {
    register_fonts();
    let fail = failed(out);
    let bytes = match out.extension().and_then(|e| e.to_str()) {
        Some("svg") => {
            let mut text = String::new();
            {
                let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
                picture.paint(&root, out)?;
                root.present().map_err(|e| fail(&e))?;
            }
            text.into_bytes()
        }
        Some("png") => {
            let mut pixels = vec![0u8; size.0 as usize * size.1 as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area();
                picture.paint(&root, out)?;
                root.present().map_err(|e| fail(&e))?;
            }
            let mut png = Vec::new();
            image::ImageEncoder::write_image(
                image::codecs::png::PngEncoder::new(&mut png),
                &pixels,
                size.0,
                size.1,
                image::ColorType::Rgb8,
            )
            .map_err(|e| fail(&e))?;
            png
        }
        _ => return Err(PlotError::Format(out.to_path_buf())),
    };
    super::file::write(out, &bytes).map_err(|e| fail(&e))
}

/// One line of a time panel.
pub struct Series {
    /// Legend text.
    pub name: String,
    /// `(time s, value)`; non-finite values are left out.
    pub points: Vec<(f64, f64)>,
    /// Line colour.
    pub colour: RGBColor,
}

impl Series {
    /// A series of `points`.
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>, colour: RGBColor) -> Self {
        Self {
            name: name.into(),
            points,
            colour,
        }
    }
}

/// A marked moment on the time axis (a limit, a refusal, a state change).
pub struct Event {
    /// When (s).
    pub t: f64,
    /// What, for the legend (events of one kind share a colour and one legend entry).
    pub kind: String,
    /// Marker colour.
    pub colour: RGBColor,
}

/// One panel of a time plot: a title, the unit of its values, its lines and its events.
pub struct Panel {
    /// Panel caption.
    pub title: String,
    /// Y axis label.
    pub unit: String,
    /// The lines.
    pub series: Vec<Series>,
    /// Vertical markers.
    pub events: Vec<Event>,
}

/// A map of coloured cells over `u` x `v` (the workspace's sections, the Gram slices): a chart with its caption and
/// labelled axes and no mesh (the cells are the picture), each cell a filled rectangle.
pub struct CellMap<'a> {
    /// The caption and its font size.
    pub caption: (&'a str, u32),
    /// Around the chart (pixels).
    pub margin: u32,
    /// Room for the x and the y labels (pixels).
    pub label_areas: (u32, u32),
    /// The x and y axes' names, and their labels' font size.
    pub axes: (&'a str, &'a str, u32),
    /// The ranges drawn.
    pub u: (f64, f64),
    pub v: (f64, f64),
}

impl CellMap<'_> {
    /// Draws the chart and the cells (corners, colour) on `area`.
    pub fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        out: &Path,
        cells: impl Iterator<Item = ([(f64, f64); 2], RGBColor)>,
    ) -> Result<(), PlotError>
    where
        DB::ErrorType: 'static,
    {
        let fail = failed(out);
        let mut chart = ChartBuilder::on(area)
            .margin(self.margin)
            .caption(self.caption.0, (FONT, self.caption.1))
            .x_label_area_size(self.label_areas.0)
            .y_label_area_size(self.label_areas.1)
            .build_cartesian_2d(self.u.0..self.u.1, self.v.0..self.v.1)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc(self.axes.0)
            .y_desc(self.axes.1)
            .label_style((FONT, self.axes.2))
            .disable_mesh()
            .draw()
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(cells.map(|(corners, c)| Rectangle::new(corners, c.filled())))
            .map_err(|e| fail(&e))?;
        Ok(())
    }
}

/// Panels stacked over one time axis, under a title.
pub struct TimePlot {
    /// Title of the picture.
    pub title: String,
    /// The panels, top to bottom.
    pub panels: Vec<Panel>,
}

/// The largest value an axis reaches either way.
const AXIS_LIMIT: f64 = 1e300;

/// A panel's value axis: its values with 8 % room each way. Values that are all the same (an axis that did not
/// move) get one unit either way, or a tenth of the value when that is more: a width of a millionth would
/// label every tick with the same rounded number ("0.0" down a panel of zeros).
fn value_range(panel: &Panel) -> (f64, f64) {
    let (lo, hi) = panel
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
    let size = lo.abs().max(hi.abs()).max(1.0);
    if lo.is_finite() && hi.is_finite() && hi - lo <= 1e-6 * size {
        let centre = (lo / 2.0 + hi / 2.0).clamp(-AXIS_LIMIT, AXIS_LIMIT);
        let half = (0.1 * centre.abs()).max(1.0);
        return (centre - half, centre + half);
    }
    match widened(lo, hi, 1e-6) {
        // 8 % of the span each way; half-spans, so that values near f64's limits do not overflow to infinity
        // (an infinite axis made the tick loop endless).
        Some((lo, hi)) => {
            let pad = 0.16 * (hi / 2.0 - lo / 2.0);
            // plotters computes the axis's width: it must stay finite, so values beyond 1e300 (garbage in a record)
            // are drawn at the edge.
            ((lo - pad).max(-AXIS_LIMIT), (hi + pad).min(AXIS_LIMIT))
        }
        None => (-1.0, 1.0),
    }
}

/// `lo..hi` made at least `least` wide (relative to the values' size, so that it is wider at 1e300 too), or `None`
/// when there are no finite values.
fn widened(lo: f64, hi: f64, least: f64) -> Option<(f64, f64)> {
    if !lo.is_finite() || !hi.is_finite() {
        return None;
    }
    let (lo, hi) = (lo.clamp(-AXIS_LIMIT, AXIS_LIMIT), hi.clamp(-AXIS_LIMIT, AXIS_LIMIT));
    let least = least * lo.abs().max(hi.abs()).max(1.0);
    Some((lo, hi.max(lo + least)))
}

impl TimePlot {
    fn time_range(&self) -> (f64, f64) {
        let (t0, t1) = self
            .panels
            .iter()
            .flat_map(|p| p.series.iter().flat_map(|s| s.points.iter().map(|q| q.0)))
            .filter(|t| t.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), t| (l.min(t), h.max(t)));
        widened(t0, t1, 1e-3).unwrap_or((0.0, 1.0))
    }
}

impl Picture for TimePlot {
    fn paint<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, out: &Path) -> Result<(), PlotError>
    where
        DB::ErrorType: 'static,
    {
        let fail = failed(out);
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let root = root.titled(&self.title, (FONT, 20)).map_err(|e| fail(&e))?;
        let (t0, t1) = self.time_range();
        let areas = root.split_evenly((self.panels.len().max(1), 1));
        for (area, panel) in areas.iter().zip(&self.panels) {
            let (lo, hi) = value_range(panel);
            let mut chart = ChartBuilder::on(area)
                .caption(&panel.title, (FONT, 15))
                .margin(8)
                .x_label_area_size(32)
                .y_label_area_size(64)
                .build_cartesian_2d(t0..t1, lo..hi)
                .map_err(|e| fail(&e))?;
            chart
                .configure_mesh()
                .x_desc("time (s)")
                .y_desc(panel.unit.as_str())
                .label_style((FONT, 12))
                .draw()
                .map_err(|e| fail(&e))?;
            for s in &panel.series {
                let colour = s.colour;
                chart
                    .draw_series(LineSeries::new(
                        // Within the axes: plotters turns every point into pixels, which values near f64's
                        // limits overflow.
                        s.points
                            .iter()
                            .filter(|p| p.0.is_finite() && p.1.is_finite())
                            .map(|p| (p.0.clamp(t0, t1), p.1.clamp(lo, hi))),
                        colour,
                    ))
                    .map_err(|e| fail(&e))?
                    .label(s.name.as_str())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour));
            }
            let mut kinds: Vec<(&str, RGBColor)> = Vec::new();
            for e in &panel.events {
                if !kinds.iter().any(|k| k.0 == e.kind) {
                    kinds.push((&e.kind, e.colour));
                }
            }
            for (kind, colour) in kinds {
                let style = colour.mix(0.5);
                chart
                    .draw_series(
                        panel
                            .events
                            .iter()
                            .filter(|e| e.kind == kind && (t0..=t1).contains(&e.t))
                            .map(|e| PathElement::new(vec![(e.t, lo), (e.t, hi)], style)),
                    )
                    .map_err(|e| fail(&e))?
                    .label(kind)
                    .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 3, y + 5)], colour.filled()));
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperLeft)
                .label_font((FONT, 12))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw()
                .map_err(|e| fail(&e))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plot() -> TimePlot {
        TimePlot {
            title: "test".into(),
            panels: vec![Panel {
                title: "a panel".into(),
                unit: "m".into(),
                series: vec![Series::new("line", vec![(0.0, 0.0), (1.0, 1.0)], BLUE)],
                events: vec![Event {
                    t: 0.5,
                    kind: "limited".into(),
                    colour: RED,
                }],
            }],
        }
    }

    fn panel_of(values: &[f64]) -> Panel {
        Panel {
            title: "p".into(),
            unit: "m/s".into(),
            series: vec![Series::new(
                "s",
                values.iter().enumerate().map(|(i, v)| (i as f64, *v)).collect(),
                BLUE,
            )],
            events: Vec::new(),
        }
    }

    /// A panel whose values are all the same spans a unit either way (a tenth of the value when more), so its
    /// tick labels differ; before, a panel of zeros spanned 1e-6 and every label read "0.0".
    #[test]
    fn a_constant_panel_spans_a_unit_either_way() {
        for (value, half) in [(0.0, 1.0), (0.227, 1.0), (-3.0, 1.0), (5e6, 5e5), (-1e300, 1e299)] {
            let (lo, hi) = value_range(&panel_of(&[value; 50]));
            assert!(lo < value && value < hi, "{value}: {lo}..{hi}");
            let width = hi - lo;
            assert!((width - 2.0 * half).abs() <= 1e-9 * width, "{value}: {lo}..{hi}");
            // Labels to one decimal (plotters' for a span of 2) differ from the bottom tick to the top one.
            if half == 1.0 {
                assert_ne!(format!("{lo:.1}"), format!("{hi:.1}"));
            }
        }
        // Values that vary keep their own range with 8 % room each way; none at all, -1..1.
        let (lo, hi) = value_range(&panel_of(&[0.0, 1.0]));
        assert!((lo + 0.08).abs() < 1e-12 && (hi - 1.08).abs() < 1e-12, "{lo}..{hi}");
        assert_eq!(value_range(&panel_of(&[f64::NAN])), (-1.0, 1.0));
    }

    #[test]
    fn the_shipped_font_is_a_font() {
        assert!(ab_glyph::FontRef::try_from_slice(FONT_DATA).is_ok());
    }

    /// PNG text is drawn: the same plot with and without its labels differs in dark pixels (text is black on
    /// white), and the SVG names its labels as text.
    #[test]
    fn png_and_svg_carry_labels() {
        let dir = std::env::temp_dir().join(format!("ringpod-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let svg = dir.join("p.svg");
        save(&svg, (600, 300), &plot()).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        for label in ["time (s)", "a panel", "limited", "line"] {
            assert!(text.contains(label), "{label} missing from the SVG");
        }
        let png = dir.join("p.png");
        save(&png, (600, 300), &plot()).unwrap();
        let image = image::open(&png).unwrap().to_rgb8();
        // The title's band above the panel holds nothing but the title's text: without a font it stays white.
        let dark = (0..image.width())
            .flat_map(|x| (0..22).map(move |y| (x, y)))
            .filter(|&(x, y)| image.get_pixel(x, y).0.iter().all(|c| *c < 100))
            .count();
        assert!(dark > 30, "only {dark} dark pixels in the title band: no text drawn");
        assert!(save(&dir.join("p.jpg"), (10, 10), &plot()).is_err());
        std::fs::remove_dir_all(&dir).ok();
    }
}
