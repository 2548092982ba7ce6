//! The report's SVG plots (plotters, SVG backend; text is SVG `<text>`, laid out by the
//! browser, so no font is needed here). Every function returns the SVG document as a string;
//! the same inputs give the same bytes.

use super::costs::CostTable;
use super::prediction::{Point, Prediction};
use crate::compare::classes::{self, ClassComparison, ClassState};
use crate::compare::{Comparison, ContrastKind, GroupMeans, PeriodComparison};
use anyhow::Result;
use plotters::chart::MeshStyle;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor;
use std::ops::Range;
use tdex_format::Snapshot;

pub(crate) const FONT: &str = "sans-serif";
pub(crate) const SIZE: (u32, u32) = (820, 520);
pub(crate) const HOT: RGBColor = RGBColor(200, 35, 35);
pub(crate) const COLD: RGBColor = RGBColor(35, 80, 200);
pub(crate) const GREY: RGBColor = RGBColor(120, 120, 120);

pub(crate) type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
/// A chart of the report's plots with coordinates `X` and `Y`.
pub(crate) type ChartOf<'a, 'b, X, Y> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>;
/// The points of one line.
type Line = Vec<(f64, f64)>;

/// Draws onto a white `size` SVG canvas and returns the document.
pub(crate) fn render(size: (u32, u32), draw: impl FnOnce(&Area) -> Result<()>) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    Ok(svg)
}

/// A chart on `area` in the report's style: the title, margins and label areas of every
/// single-panel plot.
pub(crate) fn chart<'a, 'b, X: AsRangedCoord, Y: AsRangedCoord>(
    area: &'a Area<'b>,
    title: &str,
    x: X,
    y: Y,
) -> Result<ChartOf<'a, 'b, X::CoordDescType, Y::CoordDescType>> {
    framed(area, title, x, y, (20, 48, 70))
}

/// A chart on `area` with a `title` of `caption` px and label areas of `x_labels` and
/// `y_labels` px.
fn framed<'a, 'b, X: AsRangedCoord, Y: AsRangedCoord>(
    area: &'a Area<'b>,
    title: &str,
    x: X,
    y: Y,
    (caption, x_labels, y_labels): (u32, u32, u32),
) -> Result<ChartOf<'a, 'b, X::CoordDescType, Y::CoordDescType>> {
    Ok(ChartBuilder::on(area)
        .caption(title, (FONT, caption))
        .margin(12)
        .x_label_area_size(x_labels)
        .y_label_area_size(y_labels)
        .build_cartesian_2d(x, y)?)
}

/// The mesh in the report's style with its axis descriptions; the caller adds label
/// formatters and draws it.
pub(crate) fn axes<'c, 'a, 'b, X, Y>(
    chart: &'c mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>,
    x_desc: &str,
    y_desc: &str,
) -> MeshStyle<'a, 'c, X, Y, SVGBackend<'b>>
where
    X: Ranged + ValueFormatter<X::ValueType>,
    Y: Ranged + ValueFormatter<Y::ValueType>,
{
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(x_desc)
        .y_desc(y_desc)
        .axis_desc_style((FONT, 15))
        .label_style((FONT, 13))
        .light_line_style(RGBColor(235, 235, 235));
    mesh
}

/// A padded axis range over the finite `values` (and `include`); never empty.
pub(crate) fn span(values: impl IntoIterator<Item = f64>, include: &[f64], pad: f64) -> Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().chain(include.iter().copied()) {
        if v.is_finite() {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if lo > hi {
        return 0.0..1.0;
    }
    if hi - lo <= f64::EPSILON * hi.abs().max(lo.abs()).max(1e-300) {
        let d = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
        return lo - d..hi + d;
    }
    let d = pad * (hi - lo);
    lo - d..hi + d
}

/// Tick labels without trailing zeros: `2`, `0.25`, `1.5e-5`.
pub(crate) fn tick(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e6).contains(&a) {
        return format!("{v:.1e}");
    }
    crate::fmt::trim_zeros(format!("{v:.4}"))
}

/// Tick labels for an axis spanning `r`: values within 1e-9 of the span from zero are 0
/// (the key points are multiples of a step, with round-off).
fn ticks(r: &Range<f64>) -> impl Fn(&f64) -> String {
    let eps = 1e-9 * (r.end - r.start).abs();
    move |v| if v.abs() <= eps { "0".into() } else { tick(*v) }
}

/// Labels only at whole numbers (for the period index k).
fn integer_tick(v: f64) -> String {
    if (v - v.round()).abs() < 1e-6 {
        format!("{}", v.round() as i64)
    } else {
        String::new()
    }
}

pub(crate) fn message(area: &Area, text: &str) -> Result<()> {
    let (w, h) = area.dim_in_pixel();
    let style = TextStyle::from((FONT, 18).into_font())
        .color(&GREY)
        .pos(text_anchor::Pos::new(
            text_anchor::HPos::Center,
            text_anchor::VPos::Center,
        ));
    area.draw_text(text, &style, (w as i32 / 2, h as i32 / 2))?;
    Ok(())
}

fn solid(color: RGBColor) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
}

fn dashed(
    color: RGBColor,
) -> impl Fn((i32, i32)) -> DashedPathElement<std::vec::IntoIter<(i32, i32)>, i32> {
    move |(x, y)| DashedPathElement::new(vec![(x, y), (x + 20, y)], 6, 3, color.stroke_width(2))
}

/// The DEM reference's colour where one line stands for the bed (the extrapolation's is
/// black); the group plots draw the DEM in darker shades of the groups' colours.
const DEM: RGBColor = RGBColor(20, 140, 70);
const DEM_HOT: RGBColor = RGBColor(120, 10, 10);
const DEM_COLD: RGBColor = RGBColor(10, 30, 120);
/// Series of at most this many points get markers at every point.
const MARKERS_UP_TO: usize = 40;

type Chart<'a, 'b> = ChartOf<'a, 'b, RangedCoordf64, RangedCoordf64>;

/// How a line is drawn: the extrapolation (the prediction: a solid line, markers on short
/// series), the DEM reference (dots on a thin line) or a further DEM run, twin or `--dem-run`
/// (hollow dots on a faint line).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Extrapolated,
    Dem,
    Run,
}

/// Draws `points` as a line of `kind` in `color`; in the legend when `label` is given.
fn line<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    points: &[(f64, f64)],
    kind: Kind,
    color: RGBColor,
    label: Option<String>,
) -> Result<()> {
    if points.is_empty() {
        return Ok(());
    }
    match kind {
        Kind::Extrapolated => {
            let s = chart.draw_series(LineSeries::new(
                points.iter().copied(),
                color.stroke_width(2),
            ))?;
            if let Some(l) = label {
                s.label(l).legend(solid(color));
            }
            if points.len() <= MARKERS_UP_TO {
                chart.draw_series(
                    points
                        .iter()
                        .map(|&p| TriangleMarker::new(p, 5, color.filled())),
                )?;
            }
        }
        Kind::Dem | Kind::Run => {
            let dem = kind == Kind::Dem;
            let stroke = if dem {
                color.stroke_width(1)
            } else {
                color.mix(0.5).stroke_width(1)
            };
            let s = chart.draw_series(LineSeries::new(points.iter().copied(), stroke))?;
            if let Some(l) = label {
                s.label(l).legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (20, 0)], stroke)
                        + Circle::new(
                            (10, 0),
                            if dem { 4 } else { 3 },
                            if dem {
                                color.filled()
                            } else {
                                color.stroke_width(1)
                            },
                        )
                });
            }
            chart.draw_series(points.iter().map(|&p| {
                if dem {
                    Circle::new(p, 4, color.filled())
                } else {
                    Circle::new(p, 3, color.stroke_width(1))
                }
            }))?;
        }
    }
    Ok(())
}

/// The further DEM runs as faint lines, the first one labelled for all.
fn runs<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    runs: &[Vec<(f64, f64)>],
    color: RGBColor,
    what: &str,
) -> Result<()> {
    let n = runs.iter().filter(|r| !r.is_empty()).count();
    let mut labelled = false;
    for r in runs.iter().filter(|r| !r.is_empty()) {
        let label = (!labelled).then(|| {
            if n == 1 {
                format!("DEM twin{what}")
            } else {
                format!("{n} DEM twins{what}")
            }
        });
        labelled = true;
        line(chart, r, Kind::Run, color, label)?;
    }
    Ok(())
}

/// The legend box in the corner (or the middle of a side) of the plot that the `series`
/// (each a line through its points) cross least.
pub(crate) fn legend<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    series: &[&[(f64, f64)]],
) -> Result<()> {
    let (x, y) = (chart.x_range(), chart.y_range());
    let (w, h) = (x.end - x.start, y.end - y.start);
    // boxes of 45 % of the width and 30 % of the height, in order of preference: the
    // corners, then the middles of the sides
    let corners = [
        (SeriesLabelPosition::UpperRight, (0.55, 1.0), (0.7, 1.0)),
        (SeriesLabelPosition::UpperLeft, (0.0, 0.45), (0.7, 1.0)),
        (SeriesLabelPosition::LowerRight, (0.55, 1.0), (0.0, 0.3)),
        (SeriesLabelPosition::LowerLeft, (0.0, 0.45), (0.0, 0.3)),
        (SeriesLabelPosition::MiddleRight, (0.55, 1.0), (0.35, 0.65)),
        (SeriesLabelPosition::MiddleLeft, (0.0, 0.45), (0.35, 0.65)),
        (SeriesLabelPosition::UpperMiddle, (0.275, 0.725), (0.7, 1.0)),
        (SeriesLabelPosition::LowerMiddle, (0.275, 0.725), (0.0, 0.3)),
    ];
    let mut hits = [0usize; 8];
    for s in series {
        // each segment sampled at 8 points, so that a line crossing a corner counts
        let samples = s.windows(2).flat_map(|seg| {
            (0..8).map(move |i| {
                let f = i as f64 / 8.0;
                (
                    seg[0].0 + f * (seg[1].0 - seg[0].0),
                    seg[0].1 + f * (seg[1].1 - seg[0].1),
                )
            })
        });
        for (px, py) in samples.chain(s.last().copied()) {
            let (fx, fy) = ((px - x.start) / w, (py - y.start) / h);
            for (i, (_, bx, by)) in corners.iter().enumerate() {
                if (bx.0..=bx.1).contains(&fx) && (by.0..=by.1).contains(&fy) {
                    hits[i] += 1;
                }
            }
        }
    }
    let best = (0..corners.len()).min_by_key(|&i| hits[i]).unwrap_or(0);
    chart
        .configure_series_labels()
        .position(corners[best].0.clone())
        .background_style(WHITE.mix(0.85))
        .border_style(GREY)
        .label_font((FONT, 14))
        .draw()?;
    Ok(())
}

/// The series `lines` and every series of each of `more`, as slices.
fn series_of<'s>(
    lines: &[&'s [(f64, f64)]],
    more: &[&'s [Vec<(f64, f64)>]],
) -> Vec<&'s [(f64, f64)]> {
    lines
        .iter()
        .copied()
        .chain(more.iter().flat_map(|m| m.iter().map(Vec::as_slice)))
        .collect()
}

/// A dashed line (6 px on, 4 off) through `points` in `color`; in the legend when `label`
/// is given.
fn dashed_line<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    points: Line,
    color: RGBColor,
    label: Option<String>,
) -> Result<()> {
    let s = chart.draw_series(DashedLineSeries::new(points, 6, 4, color.stroke_width(1)))?;
    if let Some(l) = label {
        s.label(l).legend(dashed(color));
    }
    Ok(())
}

/// The polygon through `points` filled with `fill`, in the legend as a filled box.
fn filled<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    points: Line,
    fill: RGBAColor,
    label: impl Into<String>,
) -> Result<()> {
    chart
        .draw_series(std::iter::once(Polygon::new(points, fill.filled())))?
        .label(label)
        .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 20, y + 6)], fill.filled()));
    Ok(())
}

/// A dashed grey vertical line at `x` over `y`, labelled `text` at the height `text_y`.
fn vmark<'a, 'b: 'a, X: Ranged<ValueType = f64>>(
    chart: &mut ChartOf<'a, 'b, X, RangedCoordf64>,
    x: f64,
    y: &Range<f64>,
    text: &str,
    text_y: f64,
) -> Result<()> {
    chart.draw_series(DashedLineSeries::new(
        vec![(x, y.start), (x, y.end)],
        4,
        4,
        GREY.stroke_width(1),
    ))?;
    chart.draw_series(std::iter::once(Text::new(
        text.to_string(),
        (x, text_y),
        TextStyle::from((FONT, 13).into_font()).color(&GREY),
    )))?;
    Ok(())
}

/// The `t1` of `p` marked over `y` (where the extrapolation starts from the DEM state).
fn t1_mark<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>, p: &Prediction, y: &Range<f64>) -> Result<()> {
    vmark(chart, t1_of(p), y, "t1", y.end)
}

/// A dashed horizontal line at `y` in `color` labelled `text` at the right end, above it.
fn hmark<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    y: f64,
    x: &Range<f64>,
    color: RGBColor,
    text: &str,
) -> Result<()> {
    dashed_line(chart, vec![(x.start, y), (x.end, y)], color, None)?;
    chart.draw_series(std::iter::once(
        EmptyElement::at((x.end, y))
            + Text::new(
                text.to_string(),
                (-6, -4),
                TextStyle::from((FONT, 13).into_font())
                    .color(&color)
                    .pos(text_anchor::Pos::new(
                        text_anchor::HPos::Right,
                        text_anchor::VPos::Bottom,
                    )),
            ),
    ))?;
    Ok(())
}

/// A chart on one panel of a multi-panel plot (smaller caption).
fn panel<'a, 'b>(
    area: &'a Area<'b>,
    title: &str,
    x: Range<f64>,
    y: Range<f64>,
) -> Result<Chart<'a, 'b>> {
    framed(area, title, x, y, (18, 42, 78))
}

/// The mesh with its axis descriptions and tidy tick labels (see [`ticks`]), drawn.
fn draw_axes<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>, x_desc: &str, y_desc: &str) -> Result<()> {
    let (fx, fy) = (ticks(&chart.x_range()), ticks(&chart.y_range()));
    axes(chart, x_desc, y_desc)
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .draw()?;
    Ok(())
}

/// The axis description of the plots over time.
const TIME: &str = "time t (s)";

/// The `t1` of a prediction (where the extrapolation starts from the DEM state).
fn t1_of(p: &Prediction) -> f64 {
    p.first().t
}

/// The time axis over the prediction and every `series` drawn with it.
fn time_axis(p: &Prediction, series: &[&[(f64, f64)]]) -> Range<f64> {
    span(
        p.points
            .iter()
            .map(|q| q.t)
            .chain(series.iter().flat_map(|s| s.iter().map(|q| q.0))),
        &[],
        0.02,
    )
}

/// A padded axis range over the values of every point of the `series` (and `include`).
fn value_span(series: &[&[(f64, f64)]], include: &[f64], pad: f64) -> Range<f64> {
    span(
        series.iter().flat_map(|s| s.iter().map(|q| q.1)),
        include,
        pad,
    )
}

/// `(t, f(point))` of the `points` where `f` has a value.
fn over_time(points: &[Point], f: impl Fn(&Point) -> Option<f64>) -> Line {
    points.iter().filter_map(|q| Some((q.t, f(q)?))).collect()
}

/// The extrapolated `extra` in `color`, then the DEM reference `dem` and the further DEM
/// runs `others` in `dem_color`, labelled `extrapolated{what}`, `DEM reference{what}` and
/// `DEM twin{what}`.
fn with_dem<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    extra: &[(f64, f64)],
    (dem, others): (&[(f64, f64)], &[Line]),
    (color, dem_color): (RGBColor, RGBColor),
    what: &str,
) -> Result<()> {
    line(
        chart,
        extra,
        Kind::Extrapolated,
        color,
        Some(format!("extrapolated{what}")),
    )?;
    line(
        chart,
        dem,
        Kind::Dem,
        dem_color,
        Some(format!("DEM reference{what}")),
    )?;
    runs(chart, others, dem_color, what)
}

/// `(t, value)` of every group-means entry of the comparison's DEM reference and runs.
type DemSeries = (Line, Vec<Line>);

/// `of` each of the comparison's DEM series: the reference, then the further runs.
fn dem_series_of(c: Option<&Comparison>, of: impl Fn(&[GroupMeans]) -> Line) -> DemSeries {
    match c {
        Some(c) => (
            of(&c.dem_series),
            c.dem_runs_series.iter().map(|s| of(s)).collect(),
        ),
        None => (Vec::new(), Vec::new()),
    }
}

fn dem_series(c: Option<&Comparison>, pick: impl Fn(&GroupMeans) -> Option<f64>) -> DemSeries {
    dem_series_of(c, |s| {
        s.iter().filter_map(|g| Some((g.t, pick(g)?))).collect()
    })
}

/// The bed mean over all extrapolated periods, with the wall temperature it heads for and
/// the DEM runs where the recording has them.
pub fn bed_mean(p: &Prediction, c: Option<&Comparison>) -> Result<String> {
    render(SIZE, |root| {
        let extra = over_time(&p.points, |q| Some(q.bed));
        let (dem, others) = dem_series(c, |g| Some(g.bed));
        let x = time_axis(p, &series_of(&[&dem], &[&others]));
        let wall: Vec<f64> = p.wall_temperature.into_iter().collect();
        let y = value_span(&series_of(&[&extra, &dem], &[&others]), &wall, 0.08);
        let mut chart = chart(root, "Bed mean temperature", x.clone(), y.clone())?;
        draw_axes(&mut chart, TIME, "bed mean, volume-weighted (K)")?;
        let wall_line: Line = p
            .wall_temperature
            .map_or(Vec::new(), |w| vec![(x.start, w), (x.end, w)]);
        if let Some(w) = p.wall_temperature {
            let label = format!("wall temperature {} K", tick(w));
            dashed_line(&mut chart, wall_line.clone(), HOT, Some(label))?;
        }
        t1_mark(&mut chart, p, &y)?;
        with_dem(&mut chart, &extra, (&dem, &others), (BLACK, DEM), "")?;
        legend(
            &mut chart,
            &series_of(&[&extra, &dem, &wall_line], &[&others]),
        )
    })
}

/// The means of the initially hot and cold particles over all extrapolated periods (the
/// paper's Figure 7 where the recording has a DEM reference).
pub fn group_means(p: &Prediction, c: Option<&Comparison>) -> Result<String> {
    render(SIZE, |root| {
        let (hot, cold) = (
            over_time(&p.points, |q| q.hot),
            over_time(&p.points, |q| q.cold),
        );
        let (dem_hot, runs_hot) = dem_series(c, |g| g.hot);
        let (dem_cold, runs_cold) = dem_series(c, |g| g.cold);
        let x = time_axis(
            p,
            &series_of(&[&dem_hot, &dem_cold], &[&runs_hot, &runs_cold]),
        );
        let all = series_of(
            &[&hot, &cold, &dem_hot, &dem_cold],
            &[&runs_hot, &runs_cold],
        );
        let y = value_span(&all, &[], 0.08);
        let mut chart = chart(
            root,
            "Mean temperature of the initially hot and cold particles",
            x,
            y.clone(),
        )?;
        draw_axes(&mut chart, TIME, "group mean temperature (K)")?;
        if !p.has_groups() {
            return message(
                root,
                "the bed started uniform: no initially hot and cold groups",
            );
        }
        t1_mark(&mut chart, p, &y)?;
        let lines = [
            ("hot", &hot, &dem_hot, &runs_hot, HOT, DEM_HOT),
            ("cold", &cold, &dem_cold, &runs_cold, COLD, DEM_COLD),
        ];
        for (name, extra, dem, others, color, dem_color) in lines {
            with_dem(
                &mut chart,
                extra,
                (dem, others),
                (color, dem_color),
                &format!(", {name}"),
            )?;
        }
        legend(&mut chart, &all)
    })
}

/// The heat the walls gave: per period (above) and in total since `t1` (below), J.
pub fn wall_heat(p: &Prediction, c: Option<&Comparison>) -> Result<String> {
    render((SIZE.0, 700), |root| {
        let per: Vec<(f64, f64)> = p
            .wall_heat()
            .unwrap_or_default()
            .iter()
            .map(|&(_, t, q)| (t, q))
            .collect();
        let mut total = vec![(t1_of(p), 0.0)];
        let mut sum = 0.0;
        for &(t, q) in &per {
            sum += q;
            total.push((t, sum));
        }
        // the DEM's from its bed means: Σ C_i T_i = C · T̄_bed with one material
        let cap = p.capacity;
        let (dem, others) = dem_series(c, |g| Some(g.bed));
        let base = c.and_then(|c| c.dem_series.iter().find(|g| g.k == 1).map(|g| g.bed));
        let dem_k: Vec<&GroupMeans> = c.map_or(Vec::new(), |c| c.dem_series.iter().collect());
        let bed_at = |k: u32| dem_k.iter().find(|g| g.k == k).map(|g| g.bed);
        let per_of = |s: &[GroupMeans]| -> Vec<(f64, f64)> {
            s.iter()
                .filter(|g| g.k >= 2)
                .filter_map(|g| {
                    let before = s
                        .iter()
                        .find(|h| h.k + 1 == g.k)
                        .map(|h| h.bed)
                        .or_else(|| bed_at(g.k - 1))?;
                    Some((g.t, cap * (g.bed - before)))
                })
                .collect()
        };
        let total_of = |s: &[(f64, f64)]| -> Vec<(f64, f64)> {
            base.map_or(Vec::new(), |b| {
                s.iter()
                    .filter(|q| q.0 >= t1_of(p) - 1e-12)
                    .map(|&(t, bed)| (t, cap * (bed - b)))
                    .collect()
            })
        };
        let (dem_per, runs_per) = dem_series_of(c, per_of);
        let dem_total = total_of(&dem);
        let runs_total: Vec<Vec<(f64, f64)>> = others.iter().map(|s| total_of(s)).collect();

        let panels = root.split_evenly((2, 1));
        let per_all = series_of(&[&per, &dem_per], &[&runs_per]);
        let total_all = series_of(&[&total, &dem_total], &[&runs_total]);
        let x = span(
            per_all
                .iter()
                .chain(&total_all)
                .flat_map(|s| s.iter().map(|q| q.0)),
            &[t1_of(p)],
            0.02,
        );
        let y = value_span(&per_all, &[0.0], 0.1);
        let mut top = panel(
            &panels[0],
            "Heat the walls gave in each period t_(k−1) → t_k",
            x.clone(),
            y,
        )?;
        draw_axes(&mut top, "time t_k (s)", "heat per period (J)")?;
        with_dem(&mut top, &per, (&dem_per, &runs_per), (HOT, DEM), "")?;
        legend(&mut top, &per_all)?;

        let y = value_span(&total_all, &[0.0], 0.08);
        let mut bottom = panel(&panels[1], "Heat the walls gave since t1", x, y)?;
        draw_axes(&mut bottom, TIME, "heat since t1 (J)")?;
        with_dem(
            &mut bottom,
            &total,
            (&dem_total, &runs_total),
            (HOT, DEM),
            "",
        )?;
        legend(&mut bottom, &total_all)
    })
}

/// The `(t, f(point))` of DEM points: the reference first, then the twins.
fn dem_points(dem: &[Vec<Point>], f: impl Fn(&Point) -> Option<f64>) -> DemSeries {
    let of = |s: &Vec<Point>| over_time(s, &f);
    match dem.split_first() {
        Some((reference, twins)) => (of(reference), twins.iter().map(of).collect()),
        None => (Vec::new(), Vec::new()),
    }
}

/// The spread of the bed's temperatures: the 5–95 % band of the bed's volume around the bed
/// mean (above) and the standard deviation (below). `dem`: the DEM reference's points, then
/// its twins' (empty without a reference).
pub fn spread(p: &Prediction, dem: &[Vec<Point>]) -> Result<String> {
    render((SIZE.0, 700), |root| {
        let panels = root.split_evenly((2, 1));
        let lo = over_time(&p.points, |q| Some(q.p05));
        let hi = over_time(&p.points, |q| Some(q.p95));
        let bed = over_time(&p.points, |q| Some(q.bed));
        let (dem_lo, runs_lo) = dem_points(dem, |q| Some(q.p05));
        let (dem_hi, runs_hi) = dem_points(dem, |q| Some(q.p95));
        let x = time_axis(p, &series_of(&[&dem_lo], &[&runs_lo]));
        let y = value_span(
            &series_of(&[&lo, &hi, &dem_lo, &dem_hi], &[&runs_lo, &runs_hi]),
            &[],
            0.06,
        );
        let mut top = panel(
            &panels[0],
            "Temperatures of the bed: 5–95 % of its volume",
            x.clone(),
            y.clone(),
        )?;
        draw_axes(&mut top, TIME, "temperature (K)")?;
        let band: Line = lo.iter().chain(hi.iter().rev()).copied().collect();
        filled(&mut top, band, HOT.mix(0.18), "extrapolated, 5–95 % band")?;
        line(
            &mut top,
            &bed,
            Kind::Extrapolated,
            BLACK,
            Some("extrapolated, bed mean".into()),
        )?;
        line(
            &mut top,
            &dem_lo,
            Kind::Dem,
            DEM,
            Some("DEM reference, 5 % and 95 %".into()),
        )?;
        line(&mut top, &dem_hi, Kind::Dem, DEM, None)?;
        runs(&mut top, &runs_lo, DEM, ", 5 % and 95 %")?;
        for r in &runs_hi {
            line(&mut top, r, Kind::Run, DEM, None)?;
        }
        t1_mark(&mut top, p, &y)?;
        let mid: Vec<(f64, f64)> = lo
            .iter()
            .zip(&hi)
            .map(|(a, b)| (a.0, 0.5 * (a.1 + b.1)))
            .collect();
        legend(
            &mut top,
            &series_of(&[&lo, &hi, &mid, &dem_lo, &dem_hi], &[&runs_lo, &runs_hi]),
        )?;

        let std = over_time(&p.points, |q| Some(q.std));
        let (dem_std, runs_std) = dem_points(dem, |q| Some(q.std));
        let std_all = series_of(&[&std, &dem_std], &[&runs_std]);
        let y = value_span(&std_all, &[0.0], 0.08);
        let mut bottom = panel(
            &panels[1],
            "Standard deviation of the temperature over the bed's volume",
            x,
            y,
        )?;
        draw_axes(&mut bottom, TIME, "standard deviation (K)")?;
        with_dem(&mut bottom, &std, (&dem_std, &runs_std), (BLACK, DEM), "")?;
        legend(&mut bottom, &std_all)
    })
}

/// The Lacey index of the hot and cold labels over the Voronoi cells (see
/// [`super::prediction::lacey`]); `dem` as for [`spread`].
pub fn lacey(p: &Prediction, dem: &[Vec<Point>]) -> Result<String> {
    render(SIZE, |root| {
        let extra = over_time(&p.points, |q| q.lacey);
        let (dem_m, runs_m) = dem_points(dem, |q| q.lacey);
        let x = time_axis(p, &series_of(&[&dem_m], &[&runs_m]));
        let y = value_span(&series_of(&[&extra, &dem_m], &[&runs_m]), &[0.0, 1.0], 0.06);
        let mut chart = chart(
            root,
            &format!(
                "Mixing of the initially hot and cold particles (Lacey index, {} cells)",
                p.lacey_cells.unwrap_or(0)
            ),
            x.clone(),
            y.clone(),
        )?;
        draw_axes(&mut chart, TIME, "Lacey index M")?;
        if extra.is_empty() && dem_m.is_empty() {
            return message(root, "the Lacey index is undefined here");
        }
        hmark(&mut chart, 1.0, &x, GREY, "randomly mixed")?;
        hmark(&mut chart, 0.0, &x, GREY, "segregated")?;
        t1_mark(&mut chart, p, &y)?;
        with_dem(&mut chart, &extra, (&dem_m, &runs_m), (BLACK, DEM), "")?;
        let marks: [Line; 2] = [
            vec![(x.start, 0.0), (x.end, 0.0)],
            vec![(x.start, 1.0), (x.end, 1.0)],
        ];
        legend(
            &mut chart,
            &series_of(&[&extra, &dem_m, &marks[0], &marks[1]], &[&runs_m]),
        )
    })
}

/// What `eps_rel` divides by, in words.
fn contrast_label(c: &Comparison) -> &'static str {
    match c.contrast {
        ContrastKind::HotCold => "|T̄_hot − T̄_cold| of the DEM",
        ContrastKind::WallBed => "|T_wall − T̄_bed| of the DEM",
        ContrastKind::None => "none",
    }
}

/// A panel of [`errors`] over the extrapolation steps `x` (labels at whole `k` only, at
/// most `n_labels`) and `y`, its axes drawn.
fn k_panel<'a, 'b>(
    area: &'a Area<'b>,
    title: &str,
    x: Range<f64>,
    y: Range<f64>,
    y_desc: &str,
    n_labels: usize,
) -> Result<Chart<'a, 'b>> {
    let fy = ticks(&y);
    let mut chart = panel(area, title, x, y)?;
    axes(&mut chart, "extrapolation step k (t_k)", y_desc)
        .x_labels(n_labels)
        .x_label_formatter(&|v| integer_tick(*v))
        .y_label_formatter(&fy)
        .draw()?;
    Ok(chart)
}

/// The errors per compared `t_k`: ε_abs with the DEM runs' own spread as a band (above),
/// ε_rel and the Eq. 10 error (middle) and the contrast ε_rel divides by (below), so that
/// a growing ε_rel can be read against a decaying contrast.
pub fn errors(c: &Comparison) -> Result<String> {
    let has_contrast = c.periods.iter().any(|p| p.contrast.is_some());
    let rows = if has_contrast { 3 } else { 2 };
    render((SIZE.0, 300 * rows + 20), |root| {
        let panels = root.split_evenly((rows as usize, 1));
        let ks: Vec<f64> = c.periods.iter().map(|p| p.k as f64).collect();
        let x = span(ks.iter().copied(), &[], 0.0);
        let axis = KAxis {
            x: x.start - 0.5..x.end + 0.5,
            n_labels: ks.len().clamp(2, 12),
        };
        absolute_errors(&panels[0], c, &axis)?;
        relative_errors(&panels[1], c, &axis)?;
        if has_contrast {
            let contrast = by_k(c, |p| p.contrast);
            let y = value_span(&[&contrast], &[0.0], 0.1);
            let mut bottom = k_panel(
                &panels[2],
                &format!("What ε_rel divides by: {}", contrast_label(c)),
                axis.x,
                y,
                "contrast (K)",
                axis.n_labels,
            )?;
            line(&mut bottom, &contrast, Kind::Dem, GREY, None)?;
        }
        Ok(())
    })
}

/// The compared `t_k` as the errors' panels share them: their span and how many labels.
struct KAxis {
    x: Range<f64>,
    n_labels: usize,
}

/// `(k, f(period))` of the compared periods where `f` has a value.
fn by_k(c: &Comparison, f: fn(&PeriodComparison) -> Option<f64>) -> Line {
    c.periods
        .iter()
        .filter_map(|p| Some((p.k as f64, f(p)?)))
        .collect()
}

/// ε_abs to the reference and to the DEM runs, with the DEM runs' own spread as a band.
fn absolute_errors(area: &Area, c: &Comparison, axis: &KAxis) -> Result<()> {
    let abs = by_k(c, |p| Some(p.eps_abs));
    let to_runs = by_k(c, |p| p.eps_abs_to_dem_runs);
    // with two DEM runs there is one distance between them, no range: the band is then
    // from 0 up to that distance (a point above it is a ratio above 1 there, which the
    // verdict allows at some t_k: with one twin its median decides)
    let one_pair = c.dem_runs == 2;
    let band: Vec<(f64, f64, f64)> = c
        .periods
        .iter()
        .filter_map(|p| {
            let low = if one_pair { 0.0 } else { p.floor_eps_abs_min? };
            Some((p.k as f64, low, p.floor_eps_abs_max?))
        })
        .collect();
    let floor_mean = by_k(c, |p| p.floor_eps_abs);
    let y = span(
        abs.iter()
            .chain(&to_runs)
            .map(|q| q.1)
            .chain(band.iter().flat_map(|b| [b.1, b.2])),
        &[0.0],
        0.1,
    );
    let mut top = k_panel(
        area,
        "Absolute error over the Voronoi cells",
        axis.x.clone(),
        y,
        "ε_abs (K)",
        axis.n_labels,
    )?;
    if !band.is_empty() {
        // one k alone is drawn as a bar a third of a step wide
        let w = if band.len() == 1 { 0.15 } else { 0.0 };
        let mut poly: Vec<(f64, f64)> = Vec::new();
        if let (Some(first), Some(last)) = (band.first(), band.last()) {
            poly.push((first.0 - w, first.1));
            poly.extend(band.iter().map(|b| (b.0, b.1)));
            poly.push((last.0 + w, last.1));
            poly.push((last.0 + w, last.2));
            poly.extend(band.iter().rev().map(|b| (b.0, b.2)));
            poly.push((first.0 - w, first.2));
        }
        let label = if one_pair {
            "within the floor: up to ε_abs between the 2 DEM runs".to_string()
        } else {
            format!("floor: ε_abs between the {} DEM runs, min–max", c.dem_runs)
        };
        filled(&mut top, poly, DEM.mix(0.2), label)?;
        dashed_line(
            &mut top,
            floor_mean.clone(),
            DEM,
            Some("floor, mean".into()),
        )?;
    }
    line(
        &mut top,
        &abs,
        Kind::Dem,
        BLACK,
        Some("extrapolated to the DEM reference".into()),
    )?;
    line(
        &mut top,
        &to_runs,
        Kind::Extrapolated,
        HOT,
        Some("extrapolated to the DEM runs, mean".into()),
    )?;
    let (lows, highs): (Line, Line) = band.iter().map(|b| ((b.0, b.1), (b.0, b.2))).unzip();
    legend(&mut top, &[&abs, &to_runs, &lows, &highs, &floor_mean])?;

    Ok(())
}

/// ε_rel and the Eq. 10 energy-transfer error, with the floor's ε_rel.
fn relative_errors(area: &Area, c: &Comparison, axis: &KAxis) -> Result<()> {
    let rel = by_k(c, |p| Some(100.0 * p.eps_rel?));
    let floor_rel = by_k(c, |p| Some(100.0 * p.floor_eps_rel?));
    let energy = by_k(c, |p| Some(100.0 * p.energy_error?));
    let y = value_span(&[&rel, &energy, &floor_rel], &[0.0], 0.1);
    let mut mid = k_panel(
        area,
        "Relative and energy-transfer errors",
        axis.x.clone(),
        y,
        "error (%)",
        axis.n_labels,
    )?;
    if rel.is_empty() && energy.is_empty() {
        message(area, "ε_rel and the Eq. 10 error are undefined here")?;
    } else {
        line(
            &mut mid,
            &rel,
            Kind::Dem,
            HOT,
            Some(format!("ε_rel = ε_abs / {}", contrast_label(c))),
        )?;
        if !floor_rel.is_empty() {
            let label = "floor ε_rel (mean between DEM runs)";
            dashed_line(&mut mid, floor_rel.clone(), DEM, Some(label.into()))?;
        }
        if !energy.is_empty() {
            mid.draw_series(DashedLineSeries::new(
                energy.clone(),
                8,
                5,
                COLD.stroke_width(2),
            ))?
            .label("Eq. 10 energy-transfer error")
            .legend(dashed(COLD));
            mid.draw_series(
                energy
                    .iter()
                    .map(|&p| TriangleMarker::new(p, 6, COLD.filled())),
            )?;
        }
        legend(&mut mid, &[&rel, &floor_rel, &energy])?;
    }

    Ok(())
}

/// ε_rel at every compared `t_k` against the speedup of reaching `t_k` (ε_abs in K when
/// the bed has no hot and cold groups).
pub fn error_vs_speedup(c: &Comparison, costs: &CostTable) -> Result<String> {
    render(SIZE, |root| {
        let use_rel = c.periods.iter().any(|p| p.eps_rel.is_some());
        let points: Vec<(u32, f64, f64)> = c
            .periods
            .iter()
            .filter_map(|p| {
                let m = p.k.saturating_sub(1) as f64;
                let e = if use_rel {
                    100.0 * p.eps_rel?
                } else {
                    p.eps_abs
                };
                Some((p.k, costs.speedup(m)?, e))
            })
            .collect();
        let x = span(points.iter().map(|p| p.1), &[1.0], 0.08);
        let y = span(points.iter().map(|p| p.2), &[0.0], 0.12);
        let mut chart = chart(
            root,
            "Error against speedup at each compared t_k",
            x,
            y.clone(),
        )?;
        draw_axes(
            &mut chart,
            "speedup of reaching t_k (complete DEM s / extrapolated DEM s)",
            if use_rel { "ε_rel (%)" } else { "ε_abs (K)" },
        )?;
        vmark(&mut chart, 1.0, &y, " break-even", y.end)?;
        if points.is_empty() {
            return message(root, "no speedup: the extrapolation's costs are zero");
        }
        chart.draw_series(LineSeries::new(
            points.iter().map(|p| (p.1, p.2)),
            HOT.stroke_width(1),
        ))?;
        chart.draw_series(points.iter().map(|&(k, s, e)| {
            EmptyElement::at((s, e))
                + Circle::new((0, 0), 5, HOT.filled())
                + Text::new(format!("t{k}"), (7, -16), (FONT, 13).into_font())
        }))?;
        Ok(())
    })
}

/// Figure 9: the cumulative distribution of collision durations. `histogram[s]` counts the
/// collisions seen at `s` consecutive samples, i.e. lasting about `s·n` steps.
pub fn duration_cdf(histogram: &[u64], n: u32, dtc_max_steps: u32) -> Result<String> {
    render(SIZE, |root| {
        let n = n.max(1) as f64;
        let total: u64 = histogram.iter().sum();
        let mut cdf = Vec::new();
        let mut seen = 0u64;
        for (s, &count) in histogram.iter().enumerate() {
            if count == 0 || total == 0 {
                continue;
            }
            seen += count;
            cdf.push(((s as f64 * n).max(1.0), seen as f64 / total as f64));
        }
        let x_max = cdf
            .last()
            .map_or(10.0 * n, |p| p.0)
            .max(dtc_max_steps as f64)
            * 1.3;
        let x_min = cdf.first().map_or(n, |p| p.0).min(n) / 1.3;
        let mut chart = chart(
            root,
            "Cumulative distribution of collision durations",
            (x_min.max(0.5)..x_max).log_scale(),
            0.0..1.02,
        )?;
        axes(
            &mut chart,
            "collision duration (DEM steps, s·n for s consecutive samples)",
            "fraction of collisions lasting ≤ x",
        )
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .draw()?;
        if cdf.is_empty() {
            return message(root, "no collisions were recorded");
        }
        let dtc = dtc_max_steps as f64;
        if dtc > 0.0 {
            let text = format!(" Δt_c^max = {dtc_max_steps} steps");
            vmark(&mut chart, dtc, &(0.0..1.02), &text, 0.06)?;
        }
        // A step function: the fraction jumps at each observed duration.
        let mut steps = vec![(x_min.max(0.5), 0.0)];
        let mut last = 0.0;
        for &(x, f) in &cdf {
            steps.push((x, last));
            steps.push((x, f));
            last = f;
        }
        steps.push((x_max, last));
        chart.draw_series(LineSeries::new(steps, COLD.stroke_width(2)))?;
        if cdf.len() <= 80 {
            chart.draw_series(cdf.iter().map(|&p| Circle::new(p, 3, COLD.filled())))?;
        }
        Ok(())
    })
}

/// A blue–white–red scale (after matplotlib's coolwarm) at `f` in [0, 1].
pub fn colour(f: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [59.0, 76.0, 192.0]),
        (0.25, [124.0, 159.0, 249.0]),
        (0.5, [221.0, 220.0, 220.0]),
        (0.75, [246.0, 152.0, 122.0]),
        (1.0, [180.0, 4.0, 38.0]),
    ];
    let f = if f.is_finite() {
        f.clamp(0.0, 1.0)
    } else {
        0.5
    };
    let i = STOPS.iter().rposition(|s| s.0 <= f).unwrap_or(0).min(3);
    let (f0, a) = STOPS[i];
    let (f1, b) = STOPS[i + 1];
    let w = (f - f0) / (f1 - f0);
    let mix = |j: usize| (a[j] + w * (b[j] - a[j])).round() as u8;
    RGBColor(mix(0), mix(1), mix(2))
}

/// The particles seen along +y (nearest first wins): indices of those that show at least
/// one grid cell of `cell` m, farthest first (drawing order).
fn visible(snap: &Snapshot, origin: (f64, f64), cell: f64, dims: (usize, usize)) -> Vec<usize> {
    let mut order: Vec<usize> = (0..snap.len())
        .filter(|&i| {
            let p = snap.pos[i];
            p.iter().all(|v| v.is_finite()) && snap.radius[i].is_finite() && snap.radius[i] > 0.0
        })
        .collect();
    order.sort_by(|&a, &b| snap.pos[a][1].total_cmp(&snap.pos[b][1]).then(a.cmp(&b)));
    let (nx, nz) = dims;
    let mut covered = vec![false; nx * nz];
    let mut keep = Vec::new();
    for i in order {
        let [x, _, z] = snap.pos[i];
        let r = snap.radius[i];
        let to_cell =
            |v: f64, o: f64, n: usize| ((v - o) / cell).floor().clamp(0.0, n as f64 - 1.0) as usize;
        let (ix0, ix1) = (to_cell(x - r, origin.0, nx), to_cell(x + r, origin.0, nx));
        let (iz0, iz1) = (to_cell(z - r, origin.1, nz), to_cell(z + r, origin.1, nz));
        let mut shows = false;
        for ix in ix0..=ix1 {
            let cx = origin.0 + (ix as f64 + 0.5) * cell;
            for iz in iz0..=iz1 {
                let cz = origin.1 + (iz as f64 + 0.5) * cell;
                if (cx - x).powi(2) + (cz - z).powi(2) <= r * r {
                    let c = &mut covered[ix * nz + iz];
                    shows |= !*c;
                    *c = true;
                }
            }
        }
        if shows {
            keep.push(i);
        }
    }
    keep.reverse();
    keep
}

/// The temperature field at one `t_k` seen along the drum axis (y): DEM and extrapolated
/// side by side on one colour scale, in the drum's outline when its radius is known.
pub fn field(dem: &Snapshot, extra: &Snapshot, k: u32, drum_radius: Option<f64>) -> Result<String> {
    fields(
        &[
            (dem, format!("DEM at t{k} (t = {} s)", tick(dem.time))),
            (
                extra,
                format!("extrapolated at t{k} (t = {} s)", tick(extra.time)),
            ),
        ],
        drum_radius,
    )
}

/// Temperature fields seen along the drum axis (y), x across and z up, one panel per
/// `(snapshot, title)` on one colour scale; the drum's cross-section (a circle of
/// `drum_radius` about the axis) is drawn when known. Only the particles visible from the
/// end of the drum are drawn.
pub fn fields(snaps: &[(&Snapshot, String)], drum_radius: Option<f64>) -> Result<String> {
    let n = snaps.len().max(1) as u32;
    render((n * FIELD_PANEL.0 + FIELD_BAR, FIELD_PANEL.1), |root| {
        let temps = snaps.iter().flat_map(|(s, _)| s.temp.iter().copied());
        let t_range = span(temps, &[], 0.0);
        let view = FieldView::of(snaps, drum_radius);
        let (panels, bar) = root.split_horizontally(n * FIELD_PANEL.0);
        let parts = panels.split_evenly((1, n as usize));
        for ((snap, title), part) in snaps.iter().zip(&parts) {
            field_panel(part, snap, title, &view, &t_range, drum_radius)?;
        }
        colour_bar(&bar, &t_range)
    })
}

/// A field panel's size, the colour bar's width, and their margins (pixels).
const FIELD_PANEL: (u32, u32) = (470, 540);
const FIELD_BAR: u32 = 150;
const FIELD_TITLE: u32 = 40;
const FIELD_MARGIN: u32 = 12;
const FIELD_X_LABELS: u32 = 45;
const FIELD_Y_LABELS: u32 = 70;

/// The window every field panel shows: square-scaled so that a sphere is round, holding every
/// field and the drum, with the cell size of the visibility test.
struct FieldView {
    x: Range<f64>,
    z: Range<f64>,
    /// Pixels per metre.
    scale: f64,
    /// The visibility test's cell (m): half the smallest radius, at most 2 000 across.
    cell: f64,
}

impl FieldView {
    fn of(snaps: &[(&Snapshot, String)], drum_radius: Option<f64>) -> FieldView {
        let all = || snaps.iter().flat_map(|(s, _)| s.pos.iter().zip(&s.radius));
        let drum: Vec<f64> = drum_radius.map_or(Vec::new(), |r| vec![-r, r]);
        let xs = span(all().flat_map(|(p, r)| [p[0] - r, p[0] + r]), &drum, 0.04);
        let zs = span(all().flat_map(|(p, r)| [p[2] - r, p[2] + r]), &drum, 0.04);
        let plot_w = (FIELD_PANEL.0 - 2 * FIELD_MARGIN - FIELD_Y_LABELS) as f64;
        let plot_h = (FIELD_PANEL.1 - FIELD_TITLE - 2 * FIELD_MARGIN - FIELD_X_LABELS) as f64;
        let scale = (plot_w / (xs.end - xs.start)).min(plot_h / (zs.end - zs.start));
        let (cx, cz) = ((xs.start + xs.end) / 2.0, (zs.start + zs.end) / 2.0);
        let (hw, hh) = (plot_w / scale / 2.0, plot_h / scale / 2.0);
        let x = cx - hw..cx + hw;
        let z = cz - hh..cz + hh;
        let r_min = all()
            .map(|(_, r)| *r)
            .filter(|r| r.is_finite() && *r > 0.0)
            .fold(f64::INFINITY, f64::min);
        let cell = (r_min / 2.0).max((x.end - x.start) / 2000.0);
        FieldView { x, z, scale, cell }
    }
}

/// One snapshot's panel: its title, the axes, the drum's outline and the visible spheres
/// coloured by temperature on `t_range`.
fn field_panel(
    part: &Area,
    snap: &Snapshot,
    title: &str,
    view: &FieldView,
    t_range: &Range<f64>,
    drum_radius: Option<f64>,
) -> Result<()> {
    let (x, z) = (&view.x, &view.z);
    let (head, body) = part.split_vertically(FIELD_TITLE);
    let style = TextStyle::from((FONT, 18).into_font()).pos(text_anchor::Pos::new(
        text_anchor::HPos::Center,
        text_anchor::VPos::Center,
    ));
    let head_w = head.dim_in_pixel().0 as i32;
    let labels = (FIELD_MARGIN + FIELD_Y_LABELS) as i32;
    head.draw_text(
        title,
        &style,
        (labels + (head_w - labels) / 2, FIELD_TITLE as i32 / 2),
    )?;
    let mut chart = ChartBuilder::on(&body)
        .margin(FIELD_MARGIN)
        .x_label_area_size(FIELD_X_LABELS)
        .y_label_area_size(FIELD_Y_LABELS)
        .build_cartesian_2d(x.clone(), z.clone())?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("x (m)")
        .y_desc("z (m)")
        .axis_desc_style((FONT, 15))
        .label_style((FONT, 13))
        .x_labels(6)
        .y_labels(6)
        .x_label_formatter(&ticks(x))
        .y_label_formatter(&ticks(z))
        .draw()?;
    if let Some(r) = drum_radius {
        const SIDES: usize = 180;
        let circle = (0..=SIDES).map(|i| {
            let a = std::f64::consts::TAU * i as f64 / SIDES as f64;
            (r * a.cos(), r * a.sin())
        });
        chart.draw_series(std::iter::once(PathElement::new(
            circle.collect::<Vec<_>>(),
            GREY.stroke_width(2),
        )))?;
    }
    let dims = (
        ((x.end - x.start) / view.cell).ceil().max(1.0) as usize,
        ((z.end - z.start) / view.cell).ceil().max(1.0) as usize,
    );
    let frac = |t: f64| (t - t_range.start) / (t_range.end - t_range.start);
    let shown = visible(snap, (x.start, z.start), view.cell, dims);
    chart.draw_series(shown.into_iter().map(|i| {
        let [px, _, pz] = snap.pos[i];
        let r = ((snap.radius[i] * view.scale).round() as i32).max(1);
        Circle::new((px, pz), r, colour(frac(snap.temp[i])).filled())
    }))?;
    Ok(())
}

/// The temperature colour bar beside the field panels.
fn colour_bar(bar: &Area, t_range: &Range<f64>) -> Result<()> {
    let (t_lo, t_hi) = (t_range.start, t_range.end);
    let (_, bar_body) = bar.split_vertically(FIELD_TITLE);
    let mut chart = ChartBuilder::on(&bar_body)
        .margin(FIELD_MARGIN)
        .margin_left(4)
        .margin_right(24)
        .x_label_area_size(FIELD_X_LABELS)
        .y_label_area_size(64)
        .build_cartesian_2d(0.0..1.0, t_lo..t_hi)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(0)
        .y_desc("temperature T (K)")
        .axis_desc_style((FONT, 15))
        .label_style((FONT, 13))
        .y_label_formatter(&ticks(t_range))
        .draw()?;
    const STEPS: usize = 64;
    chart.draw_series((0..STEPS).map(|i| {
        let (a, b) = (i as f64 / STEPS as f64, (i + 1) as f64 / STEPS as f64);
        let t = |f: f64| t_lo + f * (t_hi - t_lo);
        // Each band overlaps the next by half a band: no seams between them.
        let top = (b + 0.5 / STEPS as f64).min(1.0);
        Rectangle::new([(0.0, t(a)), (1.0, t(top))], colour((a + b) / 2.0).filled())
    }))?;
    Ok(())
}

/// The size classes' colours, smallest radius first (cycled past six classes).
const CLASS_COLOURS: [RGBColor; 6] = [
    RGBColor(35, 80, 200),
    RGBColor(20, 140, 70),
    RGBColor(230, 140, 20),
    RGBColor(200, 35, 35),
    RGBColor(130, 60, 170),
    RGBColor(120, 80, 40),
];

/// `(t, f(state))` of the class states where `f` is a number.
fn class_line(states: &[ClassState], f: impl Fn(&ClassState) -> f64) -> Line {
    states
        .iter()
        .map(|s| (s.t, f(s)))
        .filter(|p| p.1.is_finite())
        .collect()
}

/// `f` of the reference's, the further DEM runs' and the extrapolation's class states.
fn class_lines(c: &ClassComparison, f: impl Fn(&ClassState) -> f64) -> (Line, Vec<Line>, Line) {
    (
        class_line(&c.dem_series, &f),
        c.dem_runs_series
            .iter()
            .map(|s| class_line(s, &f))
            .collect(),
        class_line(&c.extra_series, &f),
    )
}

/// The mean temperature of each size class over time: the DEM reference, its further runs
/// and the extrapolation at the compared `t_k`.
pub fn class_means(c: &ClassComparison) -> Result<String> {
    render(SIZE, |root| {
        let lines: Vec<(Line, Vec<Line>, Line)> = (0..c.radii.len())
            .map(|class| class_lines(c, |s| s.mean_temperature[class]))
            .collect();
        let all: Vec<&[(f64, f64)]> = lines
            .iter()
            .flat_map(|(dem, runs, extra)| {
                [dem.as_slice(), extra.as_slice()]
                    .into_iter()
                    .chain(runs.iter().map(Vec::as_slice))
            })
            .collect();
        let x = span(all.iter().flat_map(|s| s.iter().map(|q| q.0)), &[], 0.02);
        let y = value_span(&all, &[], 0.08);
        let mut chart = chart(root, "Mean temperature of each particle size", x, y)?;
        draw_axes(&mut chart, TIME, "mean temperature of the class (K)")?;
        for (class, (dem, runs, extra)) in lines.iter().enumerate() {
            let colour = CLASS_COLOURS[class % CLASS_COLOURS.len()];
            let what = format!(", r = {} mm", classes::millimetres(c.radii[class]));
            with_dem(&mut chart, extra, (dem, runs), (colour, colour), &what)?;
        }
        legend(&mut chart, &all)
    })
}

/// The radial segregation index over time: the DEM reference, its further runs and the
/// extrapolation at the compared `t_k`.
pub fn segregation(c: &ClassComparison) -> Result<String> {
    render(SIZE, |root| {
        let (dem, runs, extra) = class_lines(c, |s| s.segregation.index);
        let all = series_of(&[&dem, &extra], &[&runs]);
        let x = span(all.iter().flat_map(|s| s.iter().map(|q| q.0)), &[], 0.02);
        let y = value_span(&all, &[0.0], 0.08);
        let mut chart = chart(root, "Radial segregation of the particle sizes", x, y)?;
        draw_axes(
            &mut chart,
            TIME,
            "segregation index (largest − smallest class)",
        )?;
        with_dem(&mut chart, &extra, (&dem, &runs), (BLACK, DEM), "")?;
        legend(&mut chart, &all)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_and_spans_are_tidy() {
        assert_eq!(tick(2.0), "2");
        assert_eq!(tick(0.25), "0.25");
        assert_eq!(tick(-0.0), "0");
        assert_eq!(tick(1.5e-5), "1.5e-5");
        assert_eq!(integer_tick(3.0000001), "3");
        assert_eq!(integer_tick(2.5), "");
        assert_eq!(span([], &[], 0.1), 0.0..1.0);
        assert_eq!(span([f64::NAN, 2.0], &[], 0.0), 1.9..2.1);
        let r = span([1.0, 3.0], &[0.0], 0.5);
        assert_eq!(r, -1.5..4.5);
    }

    #[test]
    fn the_colour_scale_runs_blue_to_red() {
        assert_eq!(colour(0.0), RGBColor(59, 76, 192));
        assert_eq!(colour(1.0), RGBColor(180, 4, 38));
        assert_eq!(colour(f64::NAN), RGBColor(221, 220, 220));
        assert_eq!(colour(2.0), colour(1.0));
    }

    #[test]
    fn hidden_particles_are_not_drawn() {
        let snap = Snapshot {
            pos: vec![[0.0, 1.0, 0.0], [0.0, 0.0, 0.0], [0.5, 2.0, 0.0]],
            radius: vec![0.1, 0.1, 0.1],
            temp: vec![1.0; 3],
            id: vec![0, 1, 2],
            vel: vec![[0.0; 3]; 3],
            ..Default::default()
        };
        // Particle 0 sits exactly behind particle 1; particle 2 is beside them.
        let shown = visible(&snap, (-1.0, -1.0), 0.05, (40, 40));
        assert_eq!(shown, vec![2, 1]);
    }
}
