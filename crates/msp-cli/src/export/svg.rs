//! SVG plots: time responses and Bode diagrams.

use msp::study::RunOutput;

use super::fmt_sig;

/// An SVG with r and every run's y on top and u below.
pub(crate) fn plot_svg(runs: &[&RunOutput]) -> Result<String, Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let Some(first) = runs.first() else {
        return Ok(String::new());
    };
    let palette = [
        BLUE,
        RED,
        GREEN,
        MAGENTA,
        CYAN,
        RGBColor(255, 140, 0),
        RGBColor(128, 0, 128),
        RGBColor(90, 90, 90),
    ];
    let color = |i: usize| palette.get(i % palette.len()).copied().unwrap_or(BLUE);
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
    // at most ~2000 points per series: the picture is the same, the file small
    let pts = |t: &Vec<f64>, v: &Vec<f64>| -> Vec<(f64, f64)> {
        let stride = (t.len() / 2000).max(1);
        t.iter()
            .copied()
            .zip(v.iter().copied())
            .step_by(stride)
            .chain(t.last().copied().zip(v.last().copied()))
            .collect()
    };
    let mut ys: Vec<&Vec<f64>> = runs.iter().map(|r| &r.result.y).collect();
    ys.push(&first.result.r);
    let us: Vec<&Vec<f64>> = runs.iter().map(|r| &r.result.u).collect();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 600)).into_drawing_area();
        root.fill(&WHITE)?;
        let (top, bottom) = root.split_vertically(360);
        let (ylo, yhi) = range(&ys);
        let title = if runs.len() == 1 {
            format!("{} — {}", first.controller, first.plant)
        } else {
            format!("{}", first.plant)
        };
        let mut c = ChartBuilder::on(&top)
            .caption(title, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..t_end, ylo..yhi)?;
        c.configure_mesh().y_desc("r, y").draw()?;
        c.draw_series(LineSeries::new(
            pts(&first.result.t, &first.result.r),
            &BLACK,
        ))?
        .label("r")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
        for (i, r) in runs.iter().enumerate() {
            let col = color(i);
            let label = if runs.len() == 1 {
                "y".to_string()
            } else {
                format!("y {}", r.controller)
            };
            c.draw_series(LineSeries::new(pts(&r.result.t, &r.result.y), &col))?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col));
        }
        c.configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
        let (ulo, uhi) = range(&us);
        let mut c2 = ChartBuilder::on(&bottom)
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..t_end, ulo..uhi)?;
        c2.configure_mesh().x_desc("t (s)").y_desc("u").draw()?;
        for (i, r) in runs.iter().enumerate() {
            let col = if runs.len() == 1 { RED } else { color(i) };
            c2.draw_series(LineSeries::new(pts(&r.result.t, &r.result.u), &col))?;
        }
        root.present()?;
    }
    Ok(svg)
}

/// Bode magnitude and phase and the Nyquist plot of the loop at the plant input.
pub(crate) fn bode_svg(an: &msp::analysis::Analysis) -> Result<String, Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let r = &an.response;
    let mag: Vec<(f64, f64)> =
        r.w.iter()
            .zip(&r.l)
            .map(|(w, l)| (*w, 20.0 * l.abs().log10()))
            .collect();
    // unwrapped phase along the grid
    let mut phase = Vec::with_capacity(r.l.len());
    let mut prev = 0.0f64;
    let mut offset = 0.0;
    for (i, (w, l)) in r.w.iter().zip(&r.l).enumerate() {
        let p = l.arg().to_degrees();
        if i > 0 {
            if p - prev > 180.0 {
                offset -= 360.0;
            } else if p - prev < -180.0 {
                offset += 360.0;
            }
        }
        prev = p;
        phase.push((*w, p + offset));
    }
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
        r.w.last().copied().unwrap_or(1.0),
    );
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1000, 700)).into_drawing_area();
        root.fill(&WHITE)?;
        let (left, right) = root.split_horizontally(600);
        let (top, bottom) = left.split_vertically(350);
        let (mlo, mhi) = finite(&mag);
        let mut c = ChartBuilder::on(&top)
            .caption(
                format!(
                    "{} on {}: gm {} dB, pm {} deg",
                    an.controller,
                    an.plant,
                    fmt_sig(an.margins.gm_db),
                    fmt_sig(an.margins.pm)
                ),
                ("sans-serif", 15),
            )
            .margin(8)
            .x_label_area_size(25)
            .y_label_area_size(50)
            .build_cartesian_2d((w0..w1).log_scale(), (mlo.max(-120.0) - 5.0)..(mhi + 5.0))?;
        c.configure_mesh().y_desc("|L| (dB)").draw()?;
        c.draw_series(LineSeries::new(mag.iter().copied(), &BLUE))?;
        c.draw_series(LineSeries::new([(w0, 0.0), (w1, 0.0)], &BLACK.mix(0.4)))?;
        let (plo, phi) = finite(&phase);
        let mut c2 = ChartBuilder::on(&bottom)
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(
                (w0..w1).log_scale(),
                (plo.max(-3600.0) - 10.0)..(phi + 10.0),
            )?;
        c2.configure_mesh()
            .x_desc("ω (rad/s)")
            .y_desc("arg L (deg)")
            .draw()?;
        c2.draw_series(LineSeries::new(phase.iter().copied(), &RED))?;
        c2.draw_series(LineSeries::new(
            [(w0, -180.0), (w1, -180.0)],
            &BLACK.mix(0.4),
        ))?;
        let pts: Vec<(f64, f64)> =
            r.l.iter()
                .filter(|l| l.abs() < 10.0)
                .map(|l| (l.re, l.im))
                .collect();
        let mut c3 = ChartBuilder::on(&right)
            .caption("Nyquist (|L| < 10)", ("sans-serif", 15))
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(40)
            .build_cartesian_2d(-3.0..2.0, -3.0..2.0)?;
        c3.configure_mesh().x_desc("Re L").y_desc("Im L").draw()?;
        c3.draw_series(LineSeries::new(pts, &BLUE))?;
        c3.draw_series(std::iter::once(Circle::new((-1.0, 0.0), 4, RED.filled())))?;
        root.present()?;
    }
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
    let stride = (s.t.len() / 2000).max(1);
    let pts: Vec<(f64, f64)> =
        s.t.iter()
            .copied()
            .zip(s.y.iter().copied())
            .step_by(stride)
            .chain(s.t.last().copied().zip(s.y.last().copied()))
            .collect();
    let mut svg = String::new();
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
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
        }
        c.draw_series(LineSeries::new(pts, &BLUE))?
            .label("y (unit step at t = 0)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
        c.configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
        root.present()?;
    }
    Ok(svg)
}
