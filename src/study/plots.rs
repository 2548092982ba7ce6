//! The study's SVG plots, in the report's style (plotters' SVG backend, text as SVG
//! `<text>`, 820×520, sans-serif; the same inputs give the same bytes), with its axis
//! helpers.

use crate::report::plots::{
    axes, chart, legend, message, render, span, tick, COLD, FONT, GREY, HOT, SIZE,
};
use anyhow::Result;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

/// Labelled points `(x, y, label)`; a message instead when there are none.
pub fn scatter(
    title: &str,
    x_desc: &str,
    y_desc: &str,
    points: &[(f64, f64, String)],
) -> Result<String> {
    render(SIZE, |root| {
        let x = span(points.iter().map(|p| p.0), &[], 0.12);
        let y = span(points.iter().map(|p| p.1), &[0.0], 0.12);
        let mut chart = chart(root, title, x, y)?;
        axes(&mut chart, x_desc, y_desc)
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .draw()?;
        if points.is_empty() {
            message(root, "no run was extrapolated")?;
        }
        chart.draw_series(points.iter().map(|(x, y, label)| {
            EmptyElement::at((*x, *y))
                + Circle::new((0, 0), 5, HOT.filled())
                + Text::new(label.clone(), (7, -16), (FONT, 13).into_font())
        }))?;
        Ok(())
    })
}

/// One series of group means over time.
pub struct Series {
    pub label: String,
    /// `(t, hot, cold)`.
    pub points: Vec<(f64, f64, f64)>,
    /// The DEM (solid line) or an extrapolation (markers).
    pub dem: bool,
}

/// Figures 13–15: hot and cold group means over time, the DEM as lines and each
/// extrapolation as markers (one shape per series).
pub fn means(title: &str, series: &[Series]) -> Result<String> {
    render(SIZE, |root| {
        let all = || series.iter().flat_map(|s| s.points.iter());
        let x = span(all().map(|p| p.0), &[], 0.03);
        let y = span(all().flat_map(|p| [p.1, p.2]), &[], 0.08);
        let mut chart = chart(root, title, x, y)?;
        axes(&mut chart, "t (s)", "group mean temperature (K)")
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .draw()?;
        let mut marker = 0;
        for s in series {
            if s.dem {
                for (colour, pick) in [(HOT, 1usize), (COLD, 2)] {
                    let pts = s
                        .points
                        .iter()
                        .map(|p| (p.0, if pick == 1 { p.1 } else { p.2 }));
                    chart.draw_series(LineSeries::new(pts, colour.stroke_width(2)))?;
                }
                chart
                    .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?
                    .label(s.label.clone())
                    .legend(|(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2))
                    });
            } else {
                let m = marker;
                marker += 1;
                let shape = move |c: (f64, f64),
                                  colour: RGBColor|
                      -> DynElement<'static, SVGBackend, (f64, f64)> {
                    match m % 3 {
                        0 => Circle::new(c, 5, colour.filled()).into_dyn(),
                        1 => TriangleMarker::new(c, 6, colour.filled()).into_dyn(),
                        _ => Cross::new(c, 5, colour.stroke_width(2)).into_dyn(),
                    }
                };
                chart.draw_series(s.points.iter().map(|p| shape((p.0, p.1), HOT)))?;
                chart
                    .draw_series(s.points.iter().map(|p| shape((p.0, p.2), COLD)))?
                    .label(s.label.clone())
                    .legend(move |(x, y)| match m % 3 {
                        0 => Circle::new((x + 10, y), 5, GREY.filled()).into_dyn(),
                        1 => TriangleMarker::new((x + 10, y), 6, GREY.filled()).into_dyn(),
                        _ => Cross::new((x + 10, y), 5, GREY.stroke_width(2)).into_dyn(),
                    });
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(GREY)
            .label_font((FONT, 13))
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
        Ok(())
    })
}

/// One line of [`lines`]: `(x, y)` points joined in order.
pub struct Line {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub kind: LineKind,
}

/// How a line of [`lines`] is drawn: the DEM runs in black and grey, so that the
/// extrapolations' colours stand out against them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineKind {
    /// The DEM reference run: black.
    Dem,
    /// A further DEM run (a twin): grey.
    DemRun,
    /// Extrapolation number `n` (its hot and cold lines share it): the palette's `n`-th
    /// colour.
    Extrapolation(usize),
    /// Extrapolation number `n` through the drum's mirror image: the colour of
    /// [`LineKind::Extrapolation`]`(n)`, dashed, so that each variant sits beside its plain run.
    MirroredExtrapolation(usize),
}

/// Labelled lines, one colour each, with an optional dashed horizontal reference line
/// (e.g. a ratio of 1); a message instead when there is no point.
pub fn lines(
    title: &str,
    x_desc: &str,
    y_desc: &str,
    series: &[Line],
    reference: Option<(f64, &str)>,
) -> Result<String> {
    const PALETTE: [RGBColor; 6] = [
        HOT,
        COLD,
        RGBColor(30, 140, 60),
        RGBColor(150, 70, 170),
        RGBColor(210, 130, 20),
        RGBColor(0, 150, 160),
    ];
    render(SIZE, |root| {
        let all = || series.iter().flat_map(|s| s.points.iter());
        let x = span(all().map(|p| p.0), &[], 0.03);
        let include: Vec<f64> = reference.iter().map(|r| r.0).collect();
        let y = span(all().map(|p| p.1), &include, 0.08);
        let (x0, x1) = (x.start, x.end);
        let mut chart = chart(root, title, x, y)?;
        axes(&mut chart, x_desc, y_desc)
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .draw()?;
        if all().next().is_none() {
            message(root, "nothing to plot")?;
        }
        if let Some((level, label)) = reference {
            chart
                .draw_series(DashedLineSeries::new(
                    [(x0, level), (x1, level)],
                    6,
                    4,
                    BLACK.stroke_width(1),
                ))?
                .label(label.to_string())
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
        }
        for s in series {
            let (colour, dashed) = match s.kind {
                LineKind::Dem => (BLACK, false),
                LineKind::DemRun => (GREY, false),
                LineKind::Extrapolation(n) => (PALETTE[n % PALETTE.len()], false),
                LineKind::MirroredExtrapolation(n) => (PALETTE[n % PALETTE.len()], true),
            };
            let style = colour.stroke_width(2);
            let points = s.points.iter().copied();
            if dashed {
                chart
                    .draw_series(DashedLineSeries::new(points, 6, 3, style))?
                    .label(s.label.clone())
                    .legend(move |(x, y)| {
                        DashedPathElement::new(vec![(x, y), (x + 20, y)], 6, 3, style)
                    });
            } else {
                chart
                    .draw_series(LineSeries::new(points, style))?
                    .label(s.label.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            }
        }
        // the legend where the lines cross least, as in the report's plots
        let crossed: Vec<&[(f64, f64)]> = series.iter().map(|s| &s.points[..]).collect();
        legend(&mut chart, &crossed)?;
        Ok(())
    })
}
