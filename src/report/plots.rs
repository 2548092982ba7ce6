//! The report's SVG plots (plotters, SVG backend; text is SVG `<text>`, laid out by the
//! browser, so no font is needed here). Every function returns the SVG document as a string;
//! the same inputs give the same bytes.

use super::costs::CostTable;
use crate::compare::Comparison;
use anyhow::Result;
use plotters::chart::MeshStyle;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor;
use recorder::format::Snapshot;
use std::ops::Range;

pub(crate) const FONT: &str = "sans-serif";
pub(crate) const SIZE: (u32, u32) = (820, 520);
pub(crate) const HOT: RGBColor = RGBColor(200, 35, 35);
const HOT_LIGHT: RGBColor = RGBColor(245, 140, 60);
pub(crate) const COLD: RGBColor = RGBColor(35, 80, 200);
const COLD_LIGHT: RGBColor = RGBColor(40, 170, 200);
pub(crate) const GREY: RGBColor = RGBColor(120, 120, 120);

pub(crate) type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

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
) -> Result<ChartContext<'a, SVGBackend<'b>, Cartesian2d<X::CoordDescType, Y::CoordDescType>>> {
    Ok(ChartBuilder::on(area)
        .caption(title, (FONT, 20))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(70)
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
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
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

/// Figure 7: hot and cold group means over time, DEM (k = 0, 1 and the reference) against
/// the extrapolation (from `t1`, where both are the DEM state).
pub fn means(c: &Comparison) -> Result<String> {
    render(SIZE, |root| {
        let dem: Vec<(f64, Option<f64>, Option<f64>)> =
            c.dem_series.iter().map(|g| (g.t, g.hot, g.cold)).collect();
        let mut extra: Vec<(f64, Option<f64>, Option<f64>)> = c
            .dem_series
            .iter()
            .filter(|g| g.k == 1)
            .map(|g| (g.t, g.hot, g.cold))
            .collect();
        extra.extend(
            c.periods
                .iter()
                .map(|p| (p.t, p.hot_mean_extra, p.cold_mean_extra)),
        );
        let temps = dem
            .iter()
            .chain(&extra)
            .flat_map(|&(_, h, c)| [h, c])
            .flatten();
        let has_groups = temps.clone().next().is_some();
        let x = span(dem.iter().chain(&extra).map(|p| p.0), &[], 0.03);
        let y = span(temps, &[], 0.08);
        let mut chart = chart(
            root,
            "Mean temperature of the initially hot and cold particles",
            x.clone(),
            y.clone(),
        )?;
        let (fx, fy) = (ticks(&x), ticks(&y));
        axes(&mut chart, "time t (s)", "mean temperature (K)")
            .x_label_formatter(&fx)
            .y_label_formatter(&fy)
            .draw()?;
        if !has_groups {
            return message(
                root,
                "the bed started uniform: no initially hot and cold groups",
            );
        }
        if let Some(t1) = c.dem_series.iter().find(|g| g.k == 1).map(|g| g.t) {
            chart.draw_series(DashedLineSeries::new(
                vec![(t1, y.start), (t1, y.end)],
                4,
                4,
                GREY.stroke_width(1),
            ))?;
            chart.draw_series(std::iter::once(Text::new(
                "t1",
                (t1, y.end),
                TextStyle::from((FONT, 13).into_font()).color(&GREY),
            )))?;
        }
        type Pick = fn(&(f64, Option<f64>, Option<f64>)) -> Option<f64>;
        let groups: [(&str, Pick, RGBColor, RGBColor); 2] = [
            ("hot", |p| p.1, HOT, HOT_LIGHT),
            ("cold", |p| p.2, COLD, COLD_LIGHT),
        ];
        for (name, pick, dem_color, extra_color) in groups {
            let d: Vec<(f64, f64)> = dem.iter().filter_map(|p| Some((p.0, pick(p)?))).collect();
            let e: Vec<(f64, f64)> = extra.iter().filter_map(|p| Some((p.0, pick(p)?))).collect();
            chart
                .draw_series(LineSeries::new(d.clone(), dem_color.stroke_width(2)))?
                .label(format!("DEM, {name}"))
                .legend(solid(dem_color));
            chart.draw_series(d.iter().map(|&p| Circle::new(p, 4, dem_color.filled())))?;
            chart
                .draw_series(DashedLineSeries::new(
                    e.clone(),
                    8,
                    5,
                    extra_color.stroke_width(2),
                ))?
                .label(format!("extrapolated, {name}"))
                .legend(dashed(extra_color));
            chart.draw_series(
                e.iter()
                    .map(|&p| TriangleMarker::new(p, 6, extra_color.filled())),
            )?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(GREY)
            .label_font((FONT, 14))
            .draw()?;
        Ok(())
    })
}

/// Table 5 and Eq. 10 per period: ε_rel and the energy error (%) above, ε_abs (K) below.
pub fn errors(c: &Comparison) -> Result<String> {
    render((SIZE.0, 640), |root| {
        let panels = root.split_evenly((2, 1));
        let ks: Vec<f64> = c.periods.iter().map(|p| p.k as f64).collect();
        let x = span(ks.iter().copied(), &[], 0.0);
        let x = x.start - 0.5..x.end + 0.5;
        let n_labels = ks.len().clamp(2, 12);

        let rel: Vec<(f64, f64)> = c
            .periods
            .iter()
            .filter_map(|p| Some((p.k as f64, 100.0 * p.eps_rel?)))
            .collect();
        let energy: Vec<(f64, f64)> = c
            .periods
            .iter()
            .filter_map(|p| Some((p.k as f64, 100.0 * p.energy_error?)))
            .collect();
        let y = span(rel.iter().chain(&energy).map(|p| p.1), &[0.0], 0.1);
        let fy = ticks(&y);
        let mut top = ChartBuilder::on(&panels[0])
            .caption("Relative and energy-transfer errors", (FONT, 19))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(70)
            .build_cartesian_2d(x.clone(), y)?;
        axes(&mut top, "extrapolation step k (t_k)", "error (%)")
            .x_labels(n_labels)
            .x_label_formatter(&|v| integer_tick(*v))
            .y_label_formatter(&fy)
            .draw()?;
        if rel.is_empty() && energy.is_empty() {
            message(&panels[0], "ε_rel and the Eq. 10 error are undefined here")?;
        }
        if !rel.is_empty() {
            top.draw_series(LineSeries::new(rel.clone(), HOT.stroke_width(2)))?
                .label("ε_rel = ε_abs / |T̄_hot − T̄_cold| (DEM)")
                .legend(solid(HOT));
            top.draw_series(rel.iter().map(|&p| Circle::new(p, 4, HOT.filled())))?;
        }
        if !energy.is_empty() {
            top.draw_series(DashedLineSeries::new(
                energy.clone(),
                8,
                5,
                COLD.stroke_width(2),
            ))?
            .label("Eq. 10 energy-transfer error")
            .legend(dashed(COLD));
            top.draw_series(
                energy
                    .iter()
                    .map(|&p| TriangleMarker::new(p, 6, COLD.filled())),
            )?;
        }
        if !rel.is_empty() || !energy.is_empty() {
            top.configure_series_labels()
                .position(SeriesLabelPosition::UpperLeft)
                .background_style(WHITE.mix(0.85))
                .border_style(GREY)
                .label_font((FONT, 14))
                .draw()?;
        }

        let abs: Vec<(f64, f64)> = c.periods.iter().map(|p| (p.k as f64, p.eps_abs)).collect();
        let y = span(abs.iter().map(|p| p.1), &[0.0], 0.1);
        let fy = ticks(&y);
        let mut bottom = ChartBuilder::on(&panels[1])
            .caption("Absolute error over the Voronoi cells", (FONT, 19))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(70)
            .build_cartesian_2d(x, y)?;
        axes(&mut bottom, "extrapolation step k (t_k)", "ε_abs (K)")
            .x_labels(n_labels)
            .x_label_formatter(&|v| integer_tick(*v))
            .y_label_formatter(&fy)
            .draw()?;
        bottom.draw_series(LineSeries::new(abs.clone(), BLACK.stroke_width(2)))?;
        bottom.draw_series(abs.iter().map(|&p| Circle::new(p, 4, BLACK.filled())))?;
        Ok(())
    })
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
        let (fx, fy) = (ticks(&x), ticks(&y));
        let mut chart = chart(
            root,
            "Error against speedup at each compared t_k",
            x,
            y.clone(),
        )?;
        axes(
            &mut chart,
            "speedup of reaching t_k (complete DEM s / extrapolated DEM s)",
            if use_rel { "ε_rel (%)" } else { "ε_abs (K)" },
        )
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .draw()?;
        chart.draw_series(DashedLineSeries::new(
            vec![(1.0, y.start), (1.0, y.end)],
            4,
            4,
            GREY.stroke_width(1),
        ))?;
        chart.draw_series(std::iter::once(Text::new(
            " break-even",
            (1.0, y.end),
            TextStyle::from((FONT, 13).into_font()).color(&GREY),
        )))?;
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
            chart.draw_series(DashedLineSeries::new(
                vec![(dtc, 0.0), (dtc, 1.02)],
                4,
                4,
                GREY.stroke_width(1),
            ))?;
            chart.draw_series(std::iter::once(Text::new(
                format!(" Δt_c^max = {dtc_max_steps} steps"),
                (dtc, 0.06),
                TextStyle::from((FONT, 13).into_font()).color(&GREY),
            )))?;
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
/// side by side on one colour scale.
pub fn field(dem: &Snapshot, extra: &Snapshot, k: u32) -> Result<String> {
    const PANEL: (u32, u32) = (470, 540);
    const BAR: u32 = 150;
    const TITLE: u32 = 40;
    const MARGIN: u32 = 12;
    const X_LABELS: u32 = 45;
    const Y_LABELS: u32 = 70;
    render((2 * PANEL.0 + BAR, PANEL.1), |root| {
        let temps = dem.temp.iter().chain(&extra.temp).copied();
        let t_range = span(temps, &[], 0.0);
        let (t_lo, t_hi) = (t_range.start, t_range.end);
        let ft = ticks(&t_range);
        let frac = |t: f64| (t - t_lo) / (t_hi - t_lo);

        // One square-scaled window holding both fields.
        let all = || {
            dem.pos
                .iter()
                .zip(&dem.radius)
                .chain(extra.pos.iter().zip(&extra.radius))
        };
        let xs = span(all().flat_map(|(p, r)| [p[0] - r, p[0] + r]), &[], 0.04);
        let zs = span(all().flat_map(|(p, r)| [p[2] - r, p[2] + r]), &[], 0.04);
        let plot_w = (PANEL.0 - 2 * MARGIN - Y_LABELS) as f64;
        let plot_h = (PANEL.1 - TITLE - 2 * MARGIN - X_LABELS) as f64;
        let scale = (plot_w / (xs.end - xs.start)).min(plot_h / (zs.end - zs.start));
        let (cx, cz) = ((xs.start + xs.end) / 2.0, (zs.start + zs.end) / 2.0);
        let (hw, hh) = (plot_w / scale / 2.0, plot_h / scale / 2.0);
        let x = cx - hw..cx + hw;
        let z = cz - hh..cz + hh;
        let (fx, fz) = (ticks(&x), ticks(&z));
        let r_min = all()
            .map(|(_, r)| *r)
            .filter(|r| r.is_finite() && *r > 0.0)
            .fold(f64::INFINITY, f64::min);
        let cell = (r_min / 2.0).max((x.end - x.start) / 2000.0);

        let (panels, bar) = root.split_horizontally(2 * PANEL.0);
        let halves = panels.split_evenly((1, 2));
        let snaps = [
            (dem, format!("DEM at t{k} (t = {} s)", tick(dem.time))),
            (
                extra,
                format!("extrapolated at t{k} (t = {} s)", tick(extra.time)),
            ),
        ];
        for ((snap, title), half) in snaps.iter().zip(&halves) {
            let (head, body) = half.split_vertically(TITLE);
            let style = TextStyle::from((FONT, 18).into_font()).pos(text_anchor::Pos::new(
                text_anchor::HPos::Center,
                text_anchor::VPos::Center,
            ));
            let head_w = head.dim_in_pixel().0 as i32;
            head.draw_text(
                title,
                &style,
                (
                    MARGIN as i32 + Y_LABELS as i32 + (head_w - (MARGIN + Y_LABELS) as i32) / 2,
                    TITLE as i32 / 2,
                ),
            )?;
            let mut chart = ChartBuilder::on(&body)
                .margin(MARGIN)
                .x_label_area_size(X_LABELS)
                .y_label_area_size(Y_LABELS)
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
                .x_label_formatter(&fx)
                .y_label_formatter(&fz)
                .draw()?;
            let dims = (
                ((x.end - x.start) / cell).ceil().max(1.0) as usize,
                ((z.end - z.start) / cell).ceil().max(1.0) as usize,
            );
            let shown = visible(snap, (x.start, z.start), cell, dims);
            chart.draw_series(shown.into_iter().map(|i| {
                let [px, _, pz] = snap.pos[i];
                let r = ((snap.radius[i] * scale).round() as i32).max(1);
                Circle::new((px, pz), r, colour(frac(snap.temp[i])).filled())
            }))?;
        }

        // The colour bar.
        let (_, bar_body) = bar.split_vertically(TITLE);
        let mut chart = ChartBuilder::on(&bar_body)
            .margin(MARGIN)
            .margin_left(4)
            .margin_right(24)
            .x_label_area_size(X_LABELS)
            .y_label_area_size(64)
            .build_cartesian_2d(0.0..1.0, t_lo..t_hi)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_labels(0)
            .y_desc("temperature T (K)")
            .axis_desc_style((FONT, 15))
            .label_style((FONT, 13))
            .y_label_formatter(&ft)
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
