//! A multivariable run's figure: a panel per output (its set point dashed,
//! each scheme's output), then a panel per input.

use super::{fmt_sig, legend, legend_spot, mark, points, range, Fine, PALETTE};

/// The figure of `outs` (one scheme or several on the same scenario).
pub(crate) fn mimo_svg(
    outs: &[msp::study::MimoOutput],
) -> Result<String, Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let Some(first) = outs.first() else {
        return Ok(String::new());
    };
    let n = first.run.y.len();
    let t = &first.run.t;
    let t_end = t.last().copied().unwrap_or(1.0).max(1e-9);
    let color = |i: usize| PALETTE.get(i % PALETTE.len()).copied().unwrap_or(BLUE);
    let panel = 190u32;
    let height = 44 + panel * 2 * u32::try_from(n).unwrap_or(1);
    let mut svg = String::new();
    let mut fine = Fine::default();
    {
        let root = SVGBackend::with_string(&mut svg, (900, height)).into_drawing_area();
        root.fill(&WHITE)?;
        let (head, body) = root.split_vertically(44);
        let schemes: Vec<String> = outs
            .iter()
            .map(|o| {
                format!(
                    "{} (F = {})",
                    o.report.design.scheme,
                    fmt_sig(o.report.design.f)
                )
            })
            .collect();
        let (line1, line2) = head.split_vertically(22);
        line1.titled(&schemes.join(" vs "), ("sans-serif", 15))?;
        line2.titled(&first.report.plant, ("sans-serif", 11))?;
        let areas = body.split_evenly((2 * n, 1));
        for (p, area) in areas.iter().enumerate() {
            let (input, i) = (p >= n, p % n);
            let series: Vec<&Vec<f64>> = outs
                .iter()
                .filter_map(|o| {
                    if input {
                        o.run.u.get(i)
                    } else {
                        o.run.y.get(i)
                    }
                })
                .chain(if input { None } else { first.run.r.get(i) })
                .collect();
            let (lo, hi) = range(&series);
            let mut c = ChartBuilder::on(area)
                .margin(6)
                .margin_right(24)
                .x_label_area_size(if p + 1 == 2 * n { 30 } else { 18 })
                .y_label_area_size(60)
                .build_cartesian_2d(0.0..t_end, lo..hi)?;
            let what = if input {
                format!("input u{}", i + 1)
            } else {
                format!("r{0}, y{0}", i + 1)
            };
            if p + 1 == 2 * n {
                c.configure_mesh().y_desc(what).x_desc("t (s)").draw()?;
            } else {
                c.configure_mesh().y_desc(what).draw()?;
            }
            let mut drawn: Vec<Vec<(f64, f64)>> = Vec::new();
            if !input {
                if let Some(r) = first.run.r.get(i) {
                    let pts = points(t, r);
                    fine.line(&mut c, &pts, BLACK.stroke_width(1), Some((6, 4)))?
                        .label(format!("r{}", i + 1))
                        .legend(mark(BLACK));
                    drawn.push(pts);
                }
            }
            for (k, o) in outs.iter().enumerate() {
                let v = if input {
                    o.run.u.get(i)
                } else {
                    o.run.y.get(i)
                };
                let Some(v) = v else { continue };
                let pts = points(t, v);
                let name = if input { "u" } else { "y" };
                fine.line(&mut c, &pts, color(k).stroke_width(1), None)?
                    .label(format!("{name}{} {}", i + 1, o.report.design.scheme))
                    .legend(mark(color(k)));
                drawn.push(pts);
            }
            let refs: Vec<&[(f64, f64)]> = drawn.iter().map(Vec::as_slice).collect();
            let spot = legend_spot(&refs, (0.0, t_end), (lo, hi), (0.25, 0.3));
            legend(&mut c, spot, 0.8)?;
        }
        root.present()?;
    }
    fine.apply(&mut svg);
    Ok(svg)
}
