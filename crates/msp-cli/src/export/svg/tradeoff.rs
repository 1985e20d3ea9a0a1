//! The trade-off picture: each scheme's load and set-point IAE against
//! its robustness (Ms), the current design marked.

use super::*;

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
