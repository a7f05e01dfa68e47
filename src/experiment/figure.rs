//! Drawing a [`Figure`] (panels of line series) to SVG with plotters and from that SVG to PNG with
//! resvg; what to draw is decided in `plot`, how it looks here.

use std::path::Path;

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::error::ExperimentError;
use super::font::{FAMILY, plot_fonts};
use crate::atomic::write_if_changed;

/// One line: `points` sorted by x, with an optional band around it.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// `(x, low, high)` sorted by x: the spread of the values averaged into each point (the
    /// lowest and highest trial), drawn as a shaded band; empty for none.
    pub band: Vec<(f64, f64, f64)>,
}

/// The legend entry of the shaded bands of an experiment's trials (see [`Series::band`]).
pub const BAND_LABEL: &str = "band: lowest to highest trial";

/// A horizontal reference line drawn dashed, e.g. chance level (1 / number of objects).
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceLine {
    pub y: f64,
    pub label: String,
}

/// One set of axes.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Empty for a single-panel figure.
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    pub series: Vec<Series>,
    /// Draw a marker at every point (for sparse x, e.g. noise levels).
    pub markers: bool,
    /// Draw a legend (not for a lone unnamed line without a band); it explains the bands.
    pub legend: bool,
    /// Label the x axis at integers only (counts, such as the number of readings).
    pub integer_x: bool,
    pub reference: Option<ReferenceLine>,
    /// The legend entry of the bands: what they span ([`BAND_LABEL`] for the trials' spread).
    pub band_label: &'static str,
}

/// A titled figure of one or more panels, laid out two per row.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    pub title: String,
    pub panels: Vec<Panel>,
}

/// Line colours: the Tableau 10 palette, then black and a dark teal, distinct for the up-to-twelve
/// lines of a panel (`fusion`'s three kinds of evidence at two L, fixed and perturbed).
const PALETTE: [RGBColor; 12] = [
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
    RGBColor(0, 0, 0),
    RGBColor(0, 95, 115),
];

impl Figure {
    /// Pixel size: 800 x 560 for one panel, else 640 x 460 per panel, two panels per row.
    fn size(&self) -> (u32, u32) {
        let n = self.panels.len().max(1) as u32;
        if n == 1 {
            (800, 560)
        } else {
            (2 * 640, n.div_ceil(2) * 460 + 50)
        }
    }

    /// The figure as SVG text (text in the generic `sans-serif` family).
    pub fn to_svg(&self) -> Result<String, String> {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, self.size()).into_drawing_area();
            self.draw(root)?;
        }
        Ok(svg)
    }

    /// Writes the figure as SVG to `path` (atomically).
    pub fn write_svg(&self, path: &Path) -> Result<(), ExperimentError> {
        let svg = self.to_svg().map_err(|what| ExperimentError::Plot {
            path: path.to_path_buf(),
            what,
        })?;
        Ok(write_if_changed(path, svg.as_bytes())?)
    }

    /// Writes the figure as PNG to `path` (atomically); see [`to_png`](Self::to_png).
    pub fn write_png(&self, path: &Path) -> Result<(), ExperimentError> {
        let bytes = self.to_png().map_err(|what| ExperimentError::Plot {
            path: path.to_path_buf(),
            what,
        })?;
        Ok(write_if_changed(path, &bytes)?)
    }

    /// The figure as an 8-bit RGB PNG: the SVG of [`to_svg`](Self::to_svg) rendered by `resvg`
    /// with the font of `plot_fonts`, so the PNG shows exactly what the SVG does.
    pub fn to_png(&self) -> Result<Vec<u8>, String> {
        let fontdb = plot_fonts().map_err(|e| e.to_string())?;
        let svg = self.to_svg()?;
        let options = resvg::usvg::Options {
            fontdb,
            ..Default::default()
        };
        let tree = resvg::usvg::Tree::from_str(&svg, &options).map_err(|e| e.to_string())?;
        let (w, h) = self.size();
        let mut pixmap =
            resvg::tiny_skia::Pixmap::new(w, h).ok_or_else(|| format!("cannot allocate {w}x{h} pixels"))?;
        pixmap.fill(resvg::tiny_skia::Color::WHITE);
        resvg::render(
            &tree,
            resvg::tiny_skia::Transform::default(),
            &mut pixmap.as_mut(),
        );
        // Opaque white background: the premultiplied RGBA is plain RGB plus alpha 255.
        let rgb: Vec<u8> = pixmap
            .data()
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        let png_err = |e: png::EncodingError| e.to_string();
        let mut bytes = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut bytes, w, h);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            let mut writer = encoder.write_header().map_err(png_err)?;
            writer.write_image_data(&rgb).map_err(png_err)?;
            writer.finish().map_err(png_err)?;
        }
        Ok(bytes)
    }

    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), String> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(err)?;
        let body = root.titled(&self.title, (FAMILY, 24)).map_err(err)?;
        let n = self.panels.len().max(1);
        let cols = n.min(2);
        let areas = body.split_evenly((n.div_ceil(cols), cols));
        for (panel, area) in self.panels.iter().zip(areas) {
            draw_panel(panel, &area).map_err(err)?;
        }
        root.present().map_err(err)
    }
}

/// A panel's chart: its axes and the coordinates its series are drawn in.
type PanelChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;
type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// Draws one panel: its axes, the bands, the reference line, the lines, then the legend.
fn draw_panel<DB: DrawingBackend>(panel: &Panel, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
    let mut chart = panel_chart(panel, area)?;
    draw_bands(panel, &mut chart)?;
    draw_reference(panel, &mut chart)?;
    draw_lines(panel, &mut chart)?;
    if !panel.legend {
        return Ok(());
    }
    chart
        .configure_series_labels()
        .position(legend_corner(panel))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font((FAMILY, 14))
        .draw()
}

/// The panel's chart with its caption, axes, labels and grid drawn.
fn panel_chart<'a, DB: DrawingBackend>(
    panel: &Panel,
    area: &'a DrawingArea<DB, Shift>,
) -> Result<PanelChart<'a, DB>, DrawingAreaErrorKind<DB::ErrorType>> {
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(14)
        .margin_right(26)
        .x_label_area_size(50)
        .y_label_area_size(64);
    if !panel.title.is_empty() {
        builder.caption(&panel.title, (FAMILY, 18));
    }
    let (x0, x1) = panel.x_range;
    let (y0, y1) = panel.y_range;
    let mut chart = builder.build_cartesian_2d(x0..x1, y0..y1)?;
    let integer_label = |v: &f64| {
        if v.fract() == 0.0 {
            format_number(*v)
        } else {
            String::new()
        }
    };
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(&panel.x_label)
        .y_desc(&panel.y_label)
        .label_style((FAMILY, 14))
        .axis_desc_style((FAMILY, 16))
        .y_label_formatter(&|v| format_number(*v))
        .light_line_style(RGBColor(242, 242, 242))
        .bold_line_style(RGBColor(205, 205, 205));
    if panel.integer_x {
        // As many labels as integers in the range (at most 11): plotters puts its ticks at round
        // values, and the formatter leaves any fractional one blank.
        let integers = (x1.floor() - x0.ceil() + 1.0).clamp(2.0, 11.0) as usize;
        mesh.x_labels(integers).x_label_formatter(&integer_label);
    } else {
        mesh.x_label_formatter(&|v| format_number(*v));
    }
    mesh.draw()?;
    Ok(chart)
}

/// Each series' band, shaded in its colour; one legend entry for all ([`Panel::band_label`]).
fn draw_bands<DB: DrawingBackend>(panel: &Panel, chart: &mut PanelChart<'_, DB>) -> DrawResult<DB> {
    let mut band_explained = false;
    for (i, series) in panel.series.iter().enumerate() {
        if series.band.len() < 2 {
            continue;
        }
        let color = PALETTE[i % PALETTE.len()];
        let outline: Vec<(f64, f64)> = series
            .band
            .iter()
            .map(|&(x, _, high)| (x, high))
            .chain(series.band.iter().rev().map(|&(x, low, _)| (x, low)))
            .collect();
        let drawn = chart.draw_series(std::iter::once(Polygon::new(outline, color.mix(0.1).filled())))?;
        // One legend entry says what every band is.
        if !band_explained {
            band_explained = true;
            drawn.label(panel.band_label).legend(|(x, y)| {
                Rectangle::new(
                    [(x, y - 5), (x + 22, y + 5)],
                    RGBColor(90, 90, 90).mix(0.2).filled(),
                )
            });
        }
    }
    Ok(())
}

/// The panel's reference line (chance), dashed across the whole x range.
fn draw_reference<DB: DrawingBackend>(panel: &Panel, chart: &mut PanelChart<'_, DB>) -> DrawResult<DB> {
    let Some(reference) = &panel.reference else {
        return Ok(());
    };
    let (x0, x1) = panel.x_range;
    let style = ShapeStyle::from(RGBColor(90, 90, 90)).stroke_width(1);
    chart
        .draw_series(DashedLineSeries::new(
            [(x0, reference.y), (x1, reference.y)],
            6,
            4,
            style,
        ))?
        .label(reference.label.as_str())
        .legend(move |(x, y)| {
            plotters::element::DashedPathElement::new(vec![(x, y), (x + 22, y)], 6, 4, style)
        });
    Ok(())
}

/// Each series as a line in its colour, with a marker at each point when the panel wants them.
fn draw_lines<DB: DrawingBackend>(panel: &Panel, chart: &mut PanelChart<'_, DB>) -> DrawResult<DB> {
    for (i, series) in panel.series.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        let line = ShapeStyle::from(color).stroke_width(2);
        chart
            .draw_series(LineSeries::new(series.points.iter().copied(), line))?
            .label(series.label.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], line));
        if panel.markers {
            chart.draw_series(series.points.iter().map(|&p| Circle::new(p, 4, color.filled())))?;
        }
    }
    Ok(())
}

/// The corner of the panel with the fewest data points near it, so the legend hides little.
fn legend_corner(panel: &Panel) -> SeriesLabelPosition {
    let (x0, x1) = panel.x_range;
    let (y0, y1) = panel.y_range;
    let span = |a: f64, b: f64| if b > a { b - a } else { 1.0 };
    let near = |fx: bool, fy: bool| {
        panel
            .series
            .iter()
            .flat_map(|s| &s.points)
            .filter(|(x, y)| {
                let u = (x - x0) / span(x0, x1);
                let v = (y - y0) / span(y0, y1);
                (if fx { u > 0.55 } else { u < 0.45 }) && (if fy { v > 0.55 } else { v < 0.45 })
            })
            .count()
    };
    let corners = [
        (near(true, false), SeriesLabelPosition::LowerRight),
        (near(true, true), SeriesLabelPosition::UpperRight),
        (near(false, true), SeriesLabelPosition::UpperLeft),
        (near(false, false), SeriesLabelPosition::LowerLeft),
    ];
    corners
        .into_iter()
        .min_by_key(|(count, _)| *count)
        .map_or(SeriesLabelPosition::LowerRight, |(_, p)| p)
}

/// `v` with at most four decimals and no trailing zeros: `0.25`, `12.5`, `100`; for tick labels
/// and tables.
pub fn format_number(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".to_string() } else { s.to_string() }
}
