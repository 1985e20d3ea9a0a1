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
    use msp::sim::Action;
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
    let range = |vs: &[&Vec<f64>]| {
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
    };
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
    let mut ys: Vec<&Vec<f64>> = runs.iter().map(|r| &r.result.y).collect();
    ys.push(&first.result.r);
    let mut us: Vec<&Vec<f64>> = runs.iter().map(|r| &r.result.u).collect();
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

/// The frequencies a Bode plot shows: the grid's, up to ten times the
/// highest crossover (beyond it the exact delay only turns the phase), as
/// MATLAB's `bode` frames the dynamics.
pub(crate) fn bode_range(an: &msp::analysis::Analysis) -> usize {
    let m = &an.margins;
    let wc = [m.wcg, m.wcp]
        .into_iter()
        .filter(|w| w.is_finite() && *w > 0.0)
        .fold(f64::NAN, f64::max);
    let r = &an.response;
    if wc.is_finite() {
        r.w.iter().position(|w| *w > 10.0 * wc).unwrap_or(r.w.len())
    } else {
        r.w.len()
    }
}

/// Bode magnitude and phase and the Nyquist plot of the loop at the plant input.
///
/// The phase is unwrapped (`LoopResponse::phase_unwrapped`: continuous, the
/// plant's dead time exact), as MATLAB's `bode` draws it, on a log-frequency
/// axis up to ten times the highest crossover ([`bode_range`]). The gain
/// margin is marked at the phase crossover `wcg` on the magnitude, the
/// phase margin at the gain crossover `wcp` on the phase (from the −180°
/// line of the phase's own turn).
pub(crate) fn bode_svg(an: &msp::analysis::Analysis) -> Result<String, Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let r = &an.response;
    let n = bode_range(an);
    let mag: Vec<(f64, f64)> =
        r.w.iter()
            .zip(&r.l)
            .take(n)
            .map(|(w, l)| (*w, 20.0 * l.abs().log10()))
            .collect();
    let unwrapped = r.phase_unwrapped(an.plant.delay);
    let phase: Vec<(f64, f64)> =
        r.w.iter()
            .copied()
            .zip(unwrapped.iter().copied())
            .take(n)
            .collect();
    let finite = |v: &[(f64, f64)]| {
        v.iter()
            .map(|p| p.1)
            .filter(|x| x.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            })
    };
    let (w0, w1) = (
        r.w.first().copied().unwrap_or(1e-3),
        r.w.get(n.saturating_sub(1)).copied().unwrap_or(1.0),
    );
    // the phase at the grid point nearest `w`
    let at = |w: f64| {
        phase
            .iter()
            .min_by(|a, b| (a.0 - w).abs().total_cmp(&(b.0 - w).abs()))
            .map_or(-180.0, |p| p.1)
    };
    let m = &an.margins;
    let mut svg = String::new();
    let mut fine = Fine::default();
    {
        // the Nyquist panel square, beside the two Bode panels
        let root = SVGBackend::with_string(&mut svg, (1200, 600)).into_drawing_area();
        root.fill(&WHITE)?;
        let (left, right) = root.split_horizontally(620);
        let (top, bottom) = left.split_vertically(300);
        let (mlo, mhi) = finite(&mag);
        let mut c = ChartBuilder::on(&top)
            .caption(
                format!(
                    "{} on {}: gm {} dB at {} rad/s, pm {}° at {} rad/s",
                    an.controller,
                    an.plant,
                    fmt_sig(m.gm_db),
                    fmt_sig(m.wcg),
                    fmt_sig(m.pm),
                    fmt_sig(m.wcp)
                ),
                ("sans-serif", 14),
            )
            .margin(10)
            .margin_right(20)
            .x_label_area_size(25)
            .y_label_area_size(55)
            .build_cartesian_2d((w0..w1).log_scale(), (mlo.max(-120.0) - 5.0)..(mhi + 5.0))?;
        c.configure_mesh().y_desc("|L| (dB)").draw()?;
        fine.line(&mut c, &mag, BLUE.stroke_width(1), None)?;
        c.draw_series(LineSeries::new([(w0, 0.0), (w1, 0.0)], &BLACK.mix(0.4)))?;
        if m.wcg.is_finite() && m.gm_db.is_finite() {
            c.draw_series(LineSeries::new(
                [(m.wcg, 0.0), (m.wcg, -m.gm_db)],
                RGBColor(0, 140, 0).stroke_width(3),
            ))?;
            c.draw_series(std::iter::once(Text::new(
                format!("gm {} dB", fmt_sig(m.gm_db)),
                (m.wcg, -m.gm_db),
                ("sans-serif", 13).into_font().color(&RGBColor(0, 110, 0)),
            )))?;
        }
        let (plo, phi) = finite(&phase);
        let (plo, phi) = if plo.is_finite() {
            (plo - 10.0, phi + 10.0)
        } else {
            (-370.0, 10.0)
        };
        let mut c2 = ChartBuilder::on(&bottom)
            .margin(10)
            .margin_right(20)
            .x_label_area_size(35)
            .y_label_area_size(55)
            .build_cartesian_2d((w0..w1).log_scale(), plo..phi)?;
        c2.configure_mesh()
            .x_desc("ω (rad/s)")
            .y_desc("arg L (deg)")
            .y_labels(9)
            .draw()?;
        fine.line(&mut c2, &phase, RED.stroke_width(1), None)?;
        if m.wcp.is_finite() && m.pm.is_finite() {
            // the −180° (mod 360°) line the margin is measured from
            let p = at(m.wcp);
            let line = p - m.pm;
            c2.draw_series(LineSeries::new([(w0, line), (w1, line)], &BLACK.mix(0.4)))?;
            c2.draw_series(LineSeries::new(
                [(m.wcp, line), (m.wcp, p)],
                RGBColor(0, 140, 0).stroke_width(3),
            ))?;
            c2.draw_series(std::iter::once(Text::new(
                format!("pm {}°", fmt_sig(m.pm)),
                (m.wcp, p),
                ("sans-serif", 13).into_font().color(&RGBColor(0, 110, 0)),
            )))?;
        }
        nyquist_panel(&right, an, n, &mut fine)?;
        root.present()?;
    }
    fine.apply(&mut svg);
    Ok(svg)
}

/// The Nyquist plot alone (`msp margins --nyquist`).
pub(crate) fn nyquist_svg(
    an: &msp::analysis::Analysis,
) -> Result<String, Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let mut svg = String::new();
    let mut fine = Fine::default();
    {
        let root = SVGBackend::with_string(&mut svg, (620, 640)).into_drawing_area();
        root.fill(&WHITE)?;
        nyquist_panel(&root, an, an.response.l.len(), &mut fine)?;
        root.present()?;
    }
    fine.apply(&mut svg);
    Ok(svg)
}

/// The loop's Nyquist curve near the critical point, with the unit circle
/// (gain crossings) and the Ms circle (centre −1, radius 1/Ms: the curve's
/// closest approach to −1).
fn nyquist_panel<DB: plotters::prelude::DrawingBackend>(
    area: &plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    an: &msp::analysis::Analysis,
    points: usize,
    fine: &mut Fine,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    use plotters::prelude::*;
    let (x0, x1, y0, y1) = (-2.5, 1.5, -2.5, 1.5);
    let inside = |l: &msp::Complex<f64>| {
        l.re.is_finite() && l.im.is_finite() && l.re > x0 && l.re < x1 && l.im > y0 && l.im < y1
    };
    // the curve as segments inside the window (a line to a point outside it
    // would be drawn along the border)
    let mut segs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for l in an.response.l.iter().take(points) {
        if inside(l) {
            if let Some(s) = segs.last_mut() {
                s.push((l.re, l.im));
            }
        } else if segs.last().is_some_and(|s| !s.is_empty()) {
            segs.push(Vec::new());
        }
    }
    let mut c = ChartBuilder::on(area)
        .caption(
            format!("Nyquist: Ms = {}", fmt_sig(an.margins.ms)),
            ("sans-serif", 15),
        )
        .margin(10)
        .margin_right(20)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    c.configure_mesh().x_desc("Re L").y_desc("Im L").draw()?;
    let circle = |cx: f64, r: f64| -> Vec<(f64, f64)> {
        (0..=240)
            .map(|i| {
                let a = std::f64::consts::TAU * f64::from(i) / 240.0;
                (cx + r * a.cos(), r * a.sin())
            })
            .collect()
    };
    let grey = RGBColor(120, 120, 120);
    fine.line(
        &mut c,
        &circle(0.0, 1.0),
        grey.stroke_width(1),
        Some((5, 4)),
    )?
    .label("unit circle")
    .legend(dashed_mark!(grey));
    if an.margins.ms.is_finite() && an.margins.ms > 0.0 {
        let green = RGBColor(0, 140, 0);
        fine.line(
            &mut c,
            &circle(-1.0, 1.0 / an.margins.ms),
            green.stroke_width(1),
            None,
        )?
        .label(format!(
            "Ms circle (radius 1/Ms = {})",
            fmt_sig(1.0 / an.margins.ms)
        ))
        .legend(mark(green));
    }
    let unit = circle(0.0, 1.0);
    let ms_circle = if an.margins.ms.is_finite() && an.margins.ms > 0.0 {
        circle(-1.0, 1.0 / an.margins.ms)
    } else {
        Vec::new()
    };
    let mut traced: Vec<&[(f64, f64)]> = segs.iter().map(Vec::as_slice).collect();
    traced.push(&unit);
    traced.push(&ms_circle);
    let spot = legend_spot(&traced, (x0, x1), (y0, y1), (0.55, 0.16));
    let mut first = true;
    for seg in segs.into_iter().filter(|s| s.len() > 1) {
        let series = fine.line(&mut c, &seg, BLUE.stroke_width(1), None)?;
        if first {
            series.label("L(jω), ω > 0").legend(mark(BLUE));
            first = false;
        }
    }
    c.draw_series(std::iter::once(Circle::new((-1.0, 0.0), 4, RED.filled())))?;
    legend(&mut c, spot, 0.85)?;
    Ok(())
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

/// The trade-off picture: for every scheme, `Ms` (robustness, x) against the
/// IAE of a unit input load (left) and of a unit set-point step (right, log
/// scale), a line through its `λ` sweep, its own tuning marked by a ring.
pub(crate) fn tradeoff_svg(t: &msp::study::Tradeoff) -> Result<String, Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let ok: Vec<&msp::study::TradeoffPoint> = t
        .points
        .iter()
        .filter(|p| p.stable == Some(true) && p.ms.is_finite())
        .collect();
    let mut schemes: Vec<&str> = Vec::new();
    for p in &ok {
        if !schemes.contains(&p.scheme) {
            schemes.push(p.scheme);
        }
    }
    // Ms from 1 to the 95th percentile (a nearly unstable point would squash the rest), at most 4
    let mut ms: Vec<f64> = ok.iter().map(|p| p.ms).collect();
    ms.sort_by(f64::total_cmp);
    let idx = (ms.len() * 95 / 100).min(ms.len().saturating_sub(1));
    let ms_hi = ms.get(idx).copied().unwrap_or(2.0).clamp(1.2, 4.0) * 1.05;
    let mut svg = String::new();
    let mut fine = Fine::default();
    {
        let root = SVGBackend::with_string(&mut svg, (1100, 520)).into_drawing_area();
        root.fill(&WHITE)?;
        let root = root.titled(
            &format!("robustness against performance: {}", t.plant),
            ("sans-serif", 18),
        )?;
        let (left, right) = root.split_horizontally(550);
        for (area, what, pick) in [
            (&left, "IAE, unit input load", 0usize),
            (&right, "IAE, unit set-point step", 1usize),
        ] {
            let value = |p: &msp::study::TradeoffPoint| {
                if pick == 0 {
                    p.iae_load
                } else {
                    p.iae_setpoint
                }
            };
            let vals: Vec<f64> = ok
                .iter()
                .filter(|p| p.ms <= ms_hi)
                .map(|p| value(p))
                .filter(|v| v.is_finite() && *v > 0.0)
                .collect();
            let lo = vals.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = vals.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let (lo, hi) = if lo.is_finite() && hi > lo {
                (lo / 1.2, hi * 1.2)
            } else {
                (0.1, 10.0)
            };
            let mut c = ChartBuilder::on(area)
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(70)
                .build_cartesian_2d(1.0..ms_hi, (lo..hi).log_scale())?;
            c.configure_mesh()
                .x_desc("Ms (robustness: smaller is more robust)")
                .y_desc(what)
                .draw()?;
            // the curves on the log axis, for the legend's place
            let mut logged: Vec<Vec<(f64, f64)>> = Vec::new();
            for (i, name) in schemes.iter().enumerate() {
                let col = PALETTE.get(i % PALETTE.len()).copied().unwrap_or(BLUE);
                let pts: Vec<(f64, f64)> = ok
                    .iter()
                    .filter(|p| p.scheme == *name && p.ms <= ms_hi)
                    .map(|p| (p.ms, value(p)))
                    .filter(|(_, v)| v.is_finite() && *v > 0.0)
                    .collect();
                logged.push(pts.iter().map(|(m, v)| (*m, v.ln())).collect());
                fine.line(&mut c, &pts, col.stroke_width(2), None)?
                    .label(name.to_string())
                    .legend(mark(col));
                c.draw_series(pts.iter().map(|p| Circle::new(*p, 2, col.filled())))?;
                let own = ok
                    .iter()
                    .filter(|p| p.scheme == *name && p.default && p.ms <= ms_hi)
                    .map(|p| (p.ms, value(p)));
                c.draw_series(own.map(|p| Circle::new(p, 6, col.stroke_width(2))))?;
            }
            let refs: Vec<&[(f64, f64)]> = logged.iter().map(Vec::as_slice).collect();
            #[allow(clippy::cast_precision_loss)] // a dozen schemes
            let size = (0.32, 0.055 * schemes.len() as f64 + 0.04);
            let at = legend_spot(&refs, (1.0, ms_hi), (lo.ln(), hi.ln()), size);
            legend(&mut c, at, 0.85)?;
        }
        root.present()?;
    }
    fine.apply(&mut svg);
    Ok(svg)
}
