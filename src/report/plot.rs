//! Charts for reports, drawn by plotters as SVG (for the page and for
//! editing) and PNG (for slides and papers). Text is set in the bundled
//! DejaVu Sans, so a PNG looks the same on every machine and needs no
//! system fonts.

use crate::fsutil::{PngEffort, png};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::sync::Once;

/// Colors of series and shaded spans, by index (Tableau 10, its gray
/// swapped for navy: gray shades what no primitive stands for).
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(0, 0, 128),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// The color of index `i` (wrapping round the palette).
pub fn color(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// The font every chart uses; registered with plotters once.
const FONT: &str = "sans-serif";

pub(crate) fn register_font() {
    static REGISTER: Once = Once::new();
    REGISTER.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("font/DejaVuSans.ttf");
        if plotters::style::register_font(FONT, FontStyle::Normal, bytes).is_err() {
            unreachable!("the bundled font is a valid TrueType file");
        }
    });
}

/// One point of a series.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    /// A vertical bar from `lo` to `hi` (such as min–max over seeds).
    pub range: Option<(f64, f64)>,
    /// Marker radius in pixels (a line's points are not marked at 0).
    pub size: f64,
}

impl Point {
    pub fn new(x: f64, y: f64) -> Point {
        Point { x, y, range: None, size: 3.0 }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Style {
    /// Points joined by a line (with their range bars).
    Line,
    /// Filled circles of each point's size, not joined.
    Markers,
}

#[derive(Clone, Debug)]
pub struct Series {
    pub name: String,
    pub color: usize,
    pub style: Style,
    pub points: Vec<Point>,
}

/// A shaded stretch of the x axis, such as one true activity.
#[derive(Clone, Debug)]
pub struct Span {
    pub from: f64,
    pub to: f64,
    pub label: String,
    /// A palette index, or `None` for gray.
    pub color: Option<usize>,
}

/// One panel: axes, shaded spans, series.
#[derive(Clone, Debug)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    /// Category names at x = 0, 1, 2, … in place of numbers.
    pub categories: Option<Vec<String>>,
    pub spans: Vec<Span>,
    pub series: Vec<Series>,
}

impl Chart {
    /// A chart whose x range fits `series` and whose y range fits them
    /// with their ranges, from 0 when every value is positive.
    pub fn fitted(title: &str, x_label: &str, y_label: &str, series: Vec<Series>) -> Chart {
        let points = || series.iter().flat_map(|s| &s.points);
        let xs = points().map(|p| p.x);
        let (x0, x1) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
        let ys = points().flat_map(|p| [p.y, p.range.map_or(p.y, |r| r.0), p.range.map_or(p.y, |r| r.1)]);
        let (y0, y1) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| (a.min(y), b.max(y)));
        let (x0, x1) = if x0.is_finite() { (x0, x1) } else { (0.0, 1.0) };
        let (y0, y1) = if y0.is_finite() { (y0.min(0.0), y1) } else { (0.0, 1.0) };
        let pad = |a: f64, b: f64| if b > a { (b - a) * 0.05 } else { 1.0 };
        Chart {
            title: title.to_string(),
            x_label: x_label.to_string(),
            y_label: y_label.to_string(),
            x_range: (x0, x1 + if x1 > x0 { 0.0 } else { 1.0 }),
            y_range: (y0, y1 + pad(y0, y1)),
            categories: None,
            spans: Vec::new(),
            series,
        }
    }
}

/// Panels stacked top to bottom, all `width` wide.
#[derive(Clone, Debug)]
pub struct Figure {
    pub width: u32,
    pub panel_height: u32,
    pub panels: Vec<Chart>,
}

impl Figure {
    pub fn new(width: u32, panel_height: u32, panels: Vec<Chart>) -> Figure {
        Figure { width, panel_height, panels }
    }

    fn size(&self) -> (u32, u32) {
        (self.width, self.panel_height * self.panels.len().max(1) as u32)
    }

    /// The figure as an SVG document.
    pub fn svg(&self) -> String {
        register_font();
        let mut out = String::new();
        {
            let root = SVGBackend::with_string(&mut out, self.size()).into_drawing_area();
            self.draw(&root);
            root.present().expect("drawing into a string cannot fail");
        }
        out
    }

    /// The figure as a PNG file's bytes.
    pub fn png(&self) -> Vec<u8> {
        register_font();
        let (w, h) = self.size();
        let mut rgb = vec![0u8; (w * h * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
            self.draw(&root);
            root.present().expect("drawing into memory cannot fail");
        }
        encode_png(w, h, rgb)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) {
        root.fill(&WHITE).expect("drawing into memory cannot fail");
        let areas = root.split_evenly((self.panels.len().max(1), 1));
        for (chart, area) in self.panels.iter().zip(&areas) {
            draw_chart(chart, area).expect("drawing into memory cannot fail");
        }
    }
}

/// An RGB buffer as PNG bytes, compressed hard.
pub fn encode_png(width: u32, height: u32, rgb: Vec<u8>) -> Vec<u8> {
    png(&rgb, width, height, image::ExtendedColorType::Rgb8, PngEffort::Smallest)
}

type Drawn<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

fn draw_chart<DB: DrawingBackend>(chart: &Chart, area: &DrawingArea<DB, Shift>) -> Drawn<DB> {
    let (x0, x1) = chart.x_range;
    let (y0, y1) = chart.y_range;
    let mut plot = ChartBuilder::on(area)
        .caption(&chart.title, (FONT, 15))
        .margin(8)
        .x_label_area_size(34)
        .y_label_area_size(52)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    let categories = chart.categories.clone();
    let x_format = move |x: &f64| match &categories {
        Some(names) => {
            let i = x.round();
            if (x - i).abs() < 1e-6 && i >= 0.0 {
                names.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        }
        None => format!("{}", (x * 1000.0).round() / 1000.0),
    };
    let mut mesh = plot.configure_mesh();
    mesh.x_desc(&chart.x_label)
        .y_desc(&chart.y_label)
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 13))
        .x_label_formatter(&x_format)
        .y_labels(6)
        .max_light_lines(0)
        .bold_line_style(BLACK.mix(0.08));
    if let Some(names) = &chart.categories {
        mesh.x_labels(names.len() * 2 + 1);
    }
    mesh.draw()?;
    for span in &chart.spans {
        let c = span.color.map_or(RGBColor(150, 150, 150), color);
        plot.draw_series(std::iter::once(Rectangle::new([(span.from, y0), (span.to, y1)], c.mix(0.15).filled())))?;
        let label = Text::new(span.label.clone(), (span.from, y1), (FONT, 11).into_font().color(&c));
        plot.draw_series(std::iter::once(label))?;
    }
    for series in &chart.series {
        let c = color(series.color);
        for p in &series.points {
            if let Some((lo, hi)) = p.range {
                plot.draw_series(std::iter::once(PathElement::new(vec![(p.x, lo), (p.x, hi)], c.stroke_width(1))))?;
            }
        }
        let drawn = match series.style {
            Style::Line => {
                let line = LineSeries::new(series.points.iter().map(|p| (p.x, p.y)), c.stroke_width(2));
                plot.draw_series(line)?;
                let dots = series.points.iter().filter(|p| p.size > 0.0);
                plot.draw_series(dots.map(|p| Circle::new((p.x, p.y), p.size, c.filled())))?
            }
            Style::Markers => {
                plot.draw_series(series.points.iter().map(|p| Circle::new((p.x, p.y), p.size.max(0.5), c.filled())))?
            }
        };
        drawn.label(series.name.clone()).legend(move |(x, y)| Circle::new((x + 6, y), 4, c.filled()));
    }
    if chart.series.iter().any(|s| !s.name.is_empty()) {
        plot.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font((FONT, 11))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.3))
            .draw()?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figure() -> Figure {
        let series = |name: &str, color, k: f64| Series {
            name: name.to_string(),
            color,
            style: Style::Line,
            points: (0..6)
                .map(|i| Point {
                    range: Some((k * i as f64 - 1.0, k * i as f64 + 1.0)),
                    ..Point::new(i as f64, k * i as f64)
                })
                .collect(),
        };
        let mut chart = Chart::fitted("error", "particles", "mm", vec![series("a", 0, 2.0), series("b", 1, 3.0)]);
        chart.categories = Some(["6", "12", "25", "50", "100", "200"].map(String::from).to_vec());
        chart.spans.push(Span { from: 1.0, to: 2.0, label: "wave".into(), color: Some(2) });
        Figure::new(480, 240, vec![chart.clone(), chart])
    }

    #[test]
    fn a_fitted_chart_spans_its_points_and_their_ranges_from_zero() {
        let chart = &figure().panels[0];
        assert_eq!(chart.x_range, (0.0, 5.0));
        assert_eq!(chart.y_range.0, -1.0);
        // The top is the largest range end (16) plus 5% of the span.
        assert!((chart.y_range.1 - (16.0 + 0.05 * 17.0)).abs() < 1e-12, "{:?}", chart.y_range);
    }

    #[test]
    fn a_figure_draws_to_svg_with_its_text_and_to_a_png_of_its_size_the_same_each_time() {
        let f = figure();
        let svg = f.svg();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        for text in ["error", "particles", "mm", "wave", "200", "a", "b"] {
            assert!(svg.contains(&format!(">\n{text}\n<")), "{text} missing from the SVG");
        }
        let png = f.png();
        let image = image::load_from_memory(&png).unwrap();
        assert_eq!((image.width(), image.height()), (480, 480));
        // Drawn, not blank: the series' blue is in the image.
        let blue = image.to_rgb8().pixels().filter(|p| p.0 == [31, 119, 180]).count();
        assert!(blue > 50, "{blue} blue pixels");
        assert_eq!(png, f.png());
        assert_eq!(svg, f.svg());
    }
}
