//! The frequency pictures: Bode (with the exact delay, gm and pm marked)
//! and Nyquist (the unit and Ms circles).

use super::*;

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
pub(super) fn nyquist_panel<DB: plotters::prelude::DrawingBackend>(
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
