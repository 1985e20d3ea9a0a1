//! SVG plots: time responses and Bode diagrams.

use msp::study::RunOutput;

use super::fmt_sig;

/// The series colours of every plot, in order.
const PALETTE: [plotters::style::RGBColor; 10] = [
    plotters::style::RGBColor(0, 0, 255),
    plotters::style::RGBColor(255, 0, 0),
    plotters::style::RGBColor(0, 255, 0),
    plotters::style::RGBColor(255, 0, 255),
    plotters::style::RGBColor(0, 255, 255),
    plotters::style::RGBColor(255, 140, 0),
    plotters::style::RGBColor(128, 0, 128),
    plotters::style::RGBColor(90, 90, 90),
    plotters::style::RGBColor(0, 128, 128),
    plotters::style::RGBColor(160, 82, 45),
];

/// A time series as plot points: at most ~2000 of them (the picture is the
/// same, the file small), always ending at the last sample.
/// The span of the finite values of `vs`, padded by 8 % (−1…1 for none).
fn range(vs: &[&Vec<f64>]) -> (f64, f64) {
    let (lo, hi) = vs
        .iter()
        .flat_map(|v| v.iter())
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(*x), b.max(*x))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = ((hi - lo) * 0.08).max(1e-9);
    (lo - pad, hi + pad)
}

fn points(t: &[f64], v: &[f64]) -> Vec<(f64, f64)> {
    let stride = (t.len() / 2000).max(1);
    t.iter()
        .copied()
        .zip(v.iter().copied())
        .step_by(stride)
        .chain(t.last().copied().zip(v.last().copied()))
        .collect()
}

/// Data traces with sub-pixel coordinates. plotters maps every point to
/// whole pixels (enlarged, a smooth curve is a staircase), so a trace is
/// drawn there as a two-point placeholder in a colour of its own, which
/// keeps its place among the plot's elements and its legend entry, and
/// [`Fine::apply`] puts the trace in its place with coordinates to a
/// hundredth of a pixel, clipped to the panel.
#[derive(Default)]
struct Fine {
    swaps: Vec<(String, String)>,
}

impl Fine {
    /// Draws `pts` on chart `c` in `style`, dashed `(on, off)` pixels if
    /// asked; returns the series for its label and legend.
    fn line<'c, 'a, DB, X, Y>(
        &mut self,
        c: &'c mut plotters::prelude::ChartContext<'a, DB, plotters::prelude::Cartesian2d<X, Y>>,
        pts: &[(f64, f64)],
        style: plotters::style::ShapeStyle,
        dash: Option<(u32, u32)>,
    ) -> Result<
        &'c mut plotters::chart::SeriesAnno<'a, DB>,
        plotters::drawing::DrawingAreaErrorKind<DB::ErrorType>,
    >
    where
        DB: plotters::prelude::DrawingBackend + 'a,
        X: plotters::coord::ranged1d::Ranged<ValueType = f64>,
        Y: plotters::coord::ranged1d::Ranged<ValueType = f64>,
    {
        use plotters::style::Color;
        const RES: i32 = 1 << 24;
        let id = u8::try_from(self.swaps.len() % 250).unwrap_or(0);
        let holder = plotters::style::RGBColor(1, 2, id);
        let at = pts.first().copied().unwrap_or((0.0, 0.0));
        let (xr, yr) = (
            c.as_coord_spec().get_x_range(),
            c.as_coord_spec().get_y_range(),
        );
        let (x0, y0) = c.backend_coord(&(xr.start, yr.start));
        let (x1, y1) = c.backend_coord(&(xr.end, yr.end));
        let spec = c.as_coord_spec();
        let frac = |m: i32| f64::from(m) / f64::from(RES);
        let px =
            |x: f64| f64::from(x0) + frac(spec.x_spec().map(&x, (0, RES))) * f64::from(x1 - x0);
        let py =
            |y: f64| f64::from(y0) + frac(spec.y_spec().map(&y, (0, RES))) * f64::from(y1 - y0);
        let (r, g, b) = style.color.rgb();
        let mut attrs = format!(
            r##"fill="none" stroke="#{r:02X}{g:02X}{b:02X}" stroke-width="{}""##,
            style.stroke_width
        );
        if style.color.alpha() < 1.0 {
            attrs.push_str(&format!(r#" stroke-opacity="{}""#, style.color.alpha()));
        }
        if let Some((on, off)) = dash {
            attrs.push_str(&format!(r#" stroke-dasharray="{on},{off}""#));
        }
        // a break at every non-finite point
        let mut lines = String::new();
        for seg in pts.split(|(x, y)| !(x.is_finite() && y.is_finite())) {
            if seg.is_empty() {
                continue;
            }
            let coords: Vec<String> = seg
                .iter()
                .map(|(x, y)| format!("{:.2},{:.2}", px(*x), py(*y)))
                .collect();
            lines.push_str(&format!(
                r#"<polyline {attrs} points="{}"/>"#,
                coords.join(" ")
            ));
        }
        let clip = format!("fine{}", self.swaps.len());
        let (left, top) = (x0.min(x1), y0.min(y1));
        let element = format!(
            r#"<g clip-path="url(#{clip})"><clipPath id="{clip}"><rect x="{left}" y="{top}" width="{}" height="{}"/></clipPath>{lines}</g>"#,
            (x1 - x0).abs() + 1,
            (y1 - y0).abs() + 1
        );
        self.swaps
            .push((format!(r##"stroke="#0102{id:02X}""##), element));
        c.draw_series(plotters::prelude::LineSeries::new(
            [at, at],
            holder.stroke_width(1),
        ))
    }

    /// Puts every trace in place of its placeholder in the SVG text `svg`.
    fn apply(self, svg: &mut String) {
        for (key, element) in self.swaps {
            let Some(k) = svg.find(&key) else { continue };
            let Some(start) = svg.get(..k).and_then(|s| s.rfind('<')) else {
                continue;
            };
            let Some(len) = svg.get(k..).and_then(|s| s.find("/>")) else {
                continue;
            };
            svg.replace_range(start..k + len + 2, &element);
        }
    }
}

/// A legend's mark: a short line in the series' color.
fn mark<C: plotters::style::Color + Copy>(
    col: C,
) -> impl Fn((i32, i32)) -> plotters::element::PathElement<(i32, i32)> {
    move |(x, y)| plotters::element::PathElement::new(vec![(x, y), (x + 20, y)], col)
}

/// A legend's mark for a dashed series: two dashes, as the line is drawn
/// (a macro: the composed element's type names the drawing backend).
macro_rules! dashed_mark {
    ($col:expr) => {{
        let col = $col;
        move |(x, y): (i32, i32)| {
            plotters::element::EmptyElement::at((x, y))
                + plotters::element::PathElement::new(vec![(0, 0), (8, 0)], col.stroke_width(2))
                + plotters::element::PathElement::new(vec![(12, 0), (20, 0)], col.stroke_width(2))
        }
    }};
}

/// The chart's legend at `at`, on a white veil of opacity `veil`, framed.
fn legend<'a, DB, CT>(
    c: &mut plotters::prelude::ChartContext<'a, DB, CT>,
    at: plotters::prelude::SeriesLabelPosition,
    veil: f64,
) -> Result<(), plotters::drawing::DrawingAreaErrorKind<DB::ErrorType>>
where
    DB: plotters::prelude::DrawingBackend + 'a,
    CT: plotters::coord::CoordTranslate,
{
    use plotters::style::Color;
    c.configure_series_labels()
        .position(at)
        .background_style(plotters::style::WHITE.mix(veil))
        .border_style(plotters::style::BLACK)
        .draw()
}

/// The corner of a panel where the legend covers the fewest points of the
/// traces (`series`, in data coordinates over the ranges `x`, `y`): each
/// corner's box taken as the legend's size, `w`×`h` fractions of the panel.
fn legend_spot(
    series: &[&[(f64, f64)]],
    x: (f64, f64),
    y: (f64, f64),
    (w, h): (f64, f64),
) -> plotters::prelude::SeriesLabelPosition {
    use plotters::prelude::SeriesLabelPosition as P;
    let (dx, dy) = (x.1 - x.0, y.1 - y.0);
    let boxes = [
        (P::UpperRight, (1.0 - w, 1.0 - h)),
        (P::LowerRight, (1.0 - w, 0.0)),
        (P::UpperLeft, (0.0, 1.0 - h)),
        (P::LowerLeft, (0.0, 0.0)),
        (P::MiddleRight, (1.0 - w, 0.5 - h / 2.0)),
    ];
    let covered = |(fx, fy): (f64, f64)| {
        series
            .iter()
            .flat_map(|s| s.iter())
            .filter(|(px, py)| {
                let (u, v) = ((px - x.0) / dx, (py - y.0) / dy);
                u >= fx && u <= fx + w && v >= fy && v <= fy + h
            })
            .count()
    };
    boxes
        .into_iter()
        .min_by_key(|(_, corner)| covered(*corner))
        .map_or(P::UpperRight, |(p, _)| p)
}

/// What happens at a time of the run, as a plot's marker says it.
struct Marker {
    at: f64,
    text: String,
}

/// The markers of a run: its set-point steps after the start, its loads
/// (input and output) and its operator events; and the periods the
/// controller was in manual or tracking (start, end).
fn markers(out: &RunOutput) -> (Vec<Marker>, Vec<(f64, f64)>) {
    use msp::sim::{Action, PlantParameter};
    use msp::study::Event;
    let end = out.result.t.last().copied().unwrap_or(0.0);
    let mut m = Vec::new();
    for e in &out.events {
        match e {
            Event::Setpoint(s) if s.at > 0.0 => m.push(Marker {
                at: s.at,
                text: format!("r → {}", fmt_sig(s.value)),
            }),
            Event::Disturbance(d) => m.push(Marker {
                at: d.at,
                text: format!("{} load {}", d.location.name(), fmt_sig(d.value)),
            }),
            Event::Setpoint(_) => {}
        }
    }
    let mut held: Vec<(f64, f64)> = Vec::new();
    let mut since: Option<f64> = None;
    let mut ops = out.scenario.events.clone();
    ops.sort_by(|a, b| a.at.total_cmp(&b.at));
    for op in &ops {
        let text = match op.action {
            Action::Manual(v) => format!("manual {}", fmt_sig(v)),
            Action::Track(v) => format!("track {}", fmt_sig(v)),
            Action::Auto => "auto".to_string(),
            Action::DeadTime(d) => format!("model θ = {} s", fmt_sig(d)),
            Action::DeadTimeRamp(d, _) => format!("model θ → {} s", fmt_sig(d)),
            Action::PlantDeadTime(d) => format!("plant θ = {} s", fmt_sig(d)),
            Action::PlantGain(k) => format!("plant K = {}", fmt_sig(k)),
            Action::PlantLag(t) => format!("plant τ = {} s", fmt_sig(t)),
            Action::PlantDrift(what, x, _) => match what {
                PlantParameter::DeadTime => format!("plant θ → {} s", fmt_sig(x)),
                PlantParameter::Gain => format!("plant K → {}", fmt_sig(x)),
                PlantParameter::Lag => format!("plant τ → {} s", fmt_sig(x)),
            },
            Action::Adapt(on) => (if on { "adapt on" } else { "adapt frozen" }).to_string(),
            Action::Retune(g, v) => format!("{} = {}", g.name(), fmt_sig(v)),
        };
        match op.action {
            Action::Manual(_) | Action::Track(_) => {
                since.get_or_insert(op.at);
            }
            Action::Auto => {
                if let Some(a) = since.take() {
                    held.push((a, op.at));
                }
            }
            _ => {}
        }
        m.push(Marker { at: op.at, text });
    }
    if let Some(a) = since {
        held.push((a, end));
    }
    m.retain(|x| x.at.is_finite() && x.at <= end);
    (m, held)
}

/// An SVG with r and every run's y on top and u below.
pub(crate) fn plot_svg(runs: &[&RunOutput]) -> Result<String, Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let Some(first) = runs.first() else {
        return Ok(String::new());
    };
    let color = |i: usize| PALETTE.get(i % PALETTE.len()).copied().unwrap_or(BLUE);
    let t_end = first.result.t.last().copied().unwrap_or(1.0).max(1e-9);
    let pts = |t: &Vec<f64>, v: &Vec<f64>| points(t, v);
    // each run's color and label: `one` (in `one_color`) for a single run,
    // the signal's name with the controller's for several
    let style = |i: usize, one: &str, one_color: RGBColor, name: &str| {
        if runs.len() == 1 {
            (one.to_string(), one_color)
        } else {
            let who = runs.get(i).map_or("", |r| r.controller);
            (format!("{name} {who}"), color(i))
        }
    };
    // the axes are the loops' that stayed bounded: a diverged one's swings
    // (to the simulator's bound) would flatten every other curve; its own
    // is clipped to the panel, and its label says it diverged
    let calm: Vec<&&RunOutput> = runs
        .iter()
        .filter(|r| r.result.diverged_at.is_none())
        .collect();
    let scaled: Vec<&&RunOutput> = if calm.is_empty() {
        runs.iter().collect()
    } else {
        calm
    };
    let mut ys: Vec<&Vec<f64>> = scaled.iter().map(|r| &r.result.y).collect();
    ys.push(&first.result.r);
    let mut us: Vec<&Vec<f64>> = scaled.iter().map(|r| &r.result.u).collect();
    // the loads, drawn with u when there are any: at the input and at the output
    let d = &first.result.d;
    let has_d = d.iter().any(|v| *v != 0.0);
    if has_d {
        us.push(d);
    }
    let d_out = &first.result.d_out;
    let has_d_out = d_out.iter().any(|v| *v != 0.0);
    if has_d_out {
        us.push(d_out);
    }
    let (marks, held) = markers(first);
    // an adaptive run's estimates and model in use, each over the first model
    let signal = |name: &str| {
        first
            .result
            .signals
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v)
    };
    let adapt: Vec<(&str, &Vec<f64>, bool)> = [
        ("K", "k_hat", false),
        ("τ", "tau_hat", false),
        ("θ", "theta_hat", false),
        ("K", "k_model", true),
        ("τ", "tau_model", true),
        ("θ", "theta_model", true),
    ]
    .into_iter()
    .filter_map(|(sym, name, model)| signal(name).map(|v| (sym, v, model)))
    .collect();
    let mut svg = String::new();
    let mut fine = Fine::default();
    {
        let height = if adapt.is_empty() { 600 } else { 820 };
        let root = SVGBackend::with_string(&mut svg, (900, height)).into_drawing_area();
        root.fill(&WHITE)?;
        let (top, rest) = root.split_vertically(360);
        let (bottom, third) = if adapt.is_empty() {
            (rest, None)
        } else {
            let (b, t) = rest.split_vertically(240);
            (b, Some(t))
        };
        let (ylo, yhi) = range(&ys);
        let title = if runs.len() == 1 {
            let key: Vec<String> = first
                .params
                .iter()
                .filter(|(k, v)| ["kp", "ti", "td", "lambda"].contains(k) && v.is_finite())
                .map(|(k, v)| format!("{k} = {}", fmt_sig(v)))
                .collect();
            format!(
                "{} ({}) on {}",
                first.controller,
                key.join(", "),
                first.plant
            )
        } else {
            format!("{}", first.plant)
        };
        let mut c = ChartBuilder::on(&top)
            .caption(title, ("sans-serif", 16))
            .margin(12)
            .margin_right(24)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..t_end, ylo..yhi)?;
        c.configure_mesh().y_desc("set point r, output y").draw()?;
        // manual or tracking periods shaded, events marked (on both panels)
        let shade = RGBColor(255, 200, 120).mix(0.25);
        c.draw_series(
            held.iter()
                .map(|(a, b)| Rectangle::new([(*a, ylo), (*b, yhi)], shade.filled())),
        )?;
        let marker = RGBColor(110, 110, 110);
        for (i, mk) in marks.iter().enumerate() {
            c.draw_series(DashedLineSeries::new(
                [(mk.at, ylo), (mk.at, yhi)],
                3,
                3,
                marker.stroke_width(1),
            ))?;
            // labels staggered down the panel so that close events stay readable
            #[allow(clippy::cast_precision_loss)] // a handful of markers
            let y = yhi - (yhi - ylo) * (0.04 + 0.07 * (i % 4) as f64);
            c.draw_series(std::iter::once(Text::new(
                format!(" {}", mk.text),
                (mk.at, y),
                ("sans-serif", 12).into_font().color(&marker),
            )))?;
        }
        // the set point dashed, so that it shows under an output on it
        fine.line(
            &mut c,
            &pts(&first.result.t, &first.result.r),
            BLACK.stroke_width(2),
            Some((8, 5)),
        )?
        .label("r (set point)")
        .legend(dashed_mark!(BLACK));
        let mut drawn: Vec<Vec<(f64, f64)>> = vec![pts(&first.result.t, &first.result.r)];
        for (i, r) in runs.iter().enumerate() {
            let (label, col) = style(i, "y", color(0), "y");
            let label = match r.result.diverged_at {
                Some(at) => format!("{label} (diverged at {} s)", fmt_sig(at)),
                None => label,
            };
            let p = pts(&r.result.t, &r.result.y);
            drawn.push(p.clone());
            fine.line(&mut c, &p, col.stroke_width(1), None)?
                .label(label)
                .legend(mark(col));
        }
        let refs: Vec<&[(f64, f64)]> = drawn.iter().map(Vec::as_slice).collect();
        #[allow(clippy::cast_precision_loss)] // a few runs
        let size = (0.2, 0.07 * (runs.len() + 1) as f64 + 0.05);
        legend(
            &mut c,
            legend_spot(&refs, (0.0, t_end), (ylo, yhi), size),
            0.8,
        )?;
        let (ulo, uhi) = range(&us);
        let mut c2 = ChartBuilder::on(&bottom)
            .margin(12)
            .margin_right(24)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..t_end, ulo..uhi)?;
        c2.configure_mesh()
            .x_desc("time t (s)")
            .y_desc(if has_d || has_d_out {
                "control u, loads"
            } else {
                "control u"
            })
            .draw()?;
        c2.draw_series(
            held.iter()
                .map(|(a, b)| Rectangle::new([(*a, ulo), (*b, uhi)], shade.filled())),
        )?;
        for mk in &marks {
            c2.draw_series(DashedLineSeries::new(
                [(mk.at, ulo), (mk.at, uhi)],
                3,
                3,
                marker.stroke_width(1),
            ))?;
        }
        let mut drawn2: Vec<Vec<(f64, f64)>> = Vec::new();
        for (i, r) in runs.iter().enumerate() {
            let (label, col) = style(i, "u (control)", RED, "u");
            let p = pts(&r.result.t, &r.result.u);
            drawn2.push(p.clone());
            fine.line(&mut c2, &p, col.stroke_width(1), None)?
                .label(label)
                .legend(mark(col));
        }
        // the loads dashed, at the input and at the output
        for (shown, signal, label, col) in [
            (has_d, d, "d (input load)", RGBColor(90, 90, 90)),
            (
                has_d_out,
                d_out,
                "d_out (output load)",
                RGBColor(160, 82, 45),
            ),
        ] {
            if !shown {
                continue;
            }
            let p = pts(&first.result.t, signal);
            drawn2.push(p.clone());
            fine.line(&mut c2, &p, col.stroke_width(2), Some((6, 4)))?
                .label(label)
                .legend(dashed_mark!(col));
        }
        let refs2: Vec<&[(f64, f64)]> = drawn2.iter().map(Vec::as_slice).collect();
        #[allow(clippy::cast_precision_loss)] // a few series
        let size2 = (0.2, 0.1 * drawn2.len() as f64 + 0.06);
        legend(
            &mut c2,
            legend_spot(&refs2, (0.0, t_end), (ulo, uhi), size2),
            0.8,
        )?;
        if let Some(third) = third {
            // each estimate (dashed) and the model in use (solid) over the
            // model the run started with
            let ratio = |v: &Vec<f64>, sym: &str| -> Vec<f64> {
                let first_model = adapt
                    .iter()
                    .find(|(s, _, m)| *s == sym && *m)
                    .and_then(|(_, v, _)| v.first().copied())
                    .unwrap_or(1.0);
                v.iter().map(|x| x / first_model).collect()
            };
            let series: Vec<(String, Vec<f64>, bool, RGBColor)> = adapt
                .iter()
                .map(|(sym, v, model)| {
                    let col = match *sym {
                        "K" => RGBColor(0, 114, 178),
                        "τ" => RGBColor(213, 94, 0),
                        _ => RGBColor(0, 158, 115),
                    };
                    let label = (*sym).to_string();
                    (label, ratio(v, sym), *model, col)
                })
                .collect();
            // the axis spans what lies within a factor 4 of the first model:
            // an estimate's first samples, before it means anything, do not
            // set the scale (they are clipped)
            let near: Vec<Vec<f64>> = series
                .iter()
                .map(|s| {
                    s.1.iter()
                        .copied()
                        .filter(|x| (0.25..=4.0).contains(x))
                        .collect()
                })
                .collect();
            let vs: Vec<&Vec<f64>> = near.iter().collect();
            let (alo, ahi) = range(&vs);
            let mut c3 = ChartBuilder::on(&third)
                .margin(12)
                .margin_right(24)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(0.0..t_end, alo..ahi)?;
            c3.configure_mesh()
                .x_desc("time t (s)")
                .y_desc("model, estimate (- -) / first")
                .draw()?;
            let mut drawn3: Vec<Vec<(f64, f64)>> = Vec::new();
            for (label, v, model, col) in &series {
                let p = pts(&first.result.t, v);
                drawn3.push(p.clone());
                // one legend entry per quantity (its model's line); the
                // axis says the estimate is dashed
                if *model {
                    fine.line(&mut c3, &p, col.stroke_width(2), None)?
                        .label(label.as_str())
                        .legend(mark(*col));
                } else {
                    fine.line(&mut c3, &p, col.stroke_width(1), Some((4, 3)))?;
                }
            }
            let refs3: Vec<&[(f64, f64)]> = drawn3.iter().map(Vec::as_slice).collect();
            legend(
                &mut c3,
                legend_spot(&refs3, (0.0, t_end), (alo, ahi), (0.08, 0.32)),
                0.8,
            )?;
        }
        root.present()?;
    }
    fine.apply(&mut svg);
    Ok(svg)
}

/// The open-loop step response, with its final value dashed.
pub(crate) fn step_svg(
    s: &msp::analysis::OpenLoopStep,
) -> Result<String, Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let t_end = s.t.last().copied().unwrap_or(1.0).max(1e-9);
    let finite = s.y.iter().copied().filter(|v| v.is_finite());
    let (lo, hi) = finite
        .chain(s.dc_gain)
        .chain([0.0])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    let pad = ((hi - lo) * 0.08).max(1e-9);
    let pts = points(&s.t, &s.y);
    let mut svg = String::new();
    let mut fine = Fine::default();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 450)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut c = ChartBuilder::on(&root)
            .caption(format!("step response — {}", s.plant), ("sans-serif", 18))
            .margin(15)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..t_end, (lo - pad)..(hi + pad))?;
        c.configure_mesh().x_desc("t (s)").y_desc("y").draw()?;
        if let Some(k) = s.dc_gain {
            c.draw_series(DashedLineSeries::new(
                [(0.0, k), (t_end, k)],
                6,
                4,
                BLACK.stroke_width(1),
            ))?
            .label(format!("final value {}", fmt_sig(k)))
            .legend(dashed_mark!(BLACK));
        }
        fine.line(&mut c, &pts, BLUE.stroke_width(1), None)?
            .label("y (unit step at t = 0)")
            .legend(mark(BLUE));
        // the final value's line as points along it (the legend's place counts points)
        let level: Vec<(f64, f64)> = s.dc_gain.map_or_else(Vec::new, |k| {
            (0..=50).map(|i| (t_end * f64::from(i) / 50.0, k)).collect()
        });
        let spot = legend_spot(
            &[&pts, &level],
            (0.0, t_end),
            (lo - pad, hi + pad),
            (0.3, 0.16),
        );
        legend(&mut c, spot, 0.8)?;
        root.present()?;
    }
    fine.apply(&mut svg);
    Ok(svg)
}

// after the macros above, which they use
mod frequency;
mod mimo;
mod tradeoff;
pub(crate) use frequency::{bode_svg, nyquist_svg};
pub(crate) use mimo::mimo_svg;
pub(crate) use tradeoff::tradeoff_svg;
