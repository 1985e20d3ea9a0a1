use super::*;

#[test]
fn pole_placement_gives_uma_example_1() -> Result<(), Error> {
    // Gm = 1/((2s + 1)(20s − 1)), λ = 5: kp 4.6571, ki 0.1829, kd 12.2857, τ 2.8571
    let gm = TransferFunction::new(&[1.0], &mul(&[2.0, 1.0], &[20.0, -1.0]), 6.0)?;
    let [kp, ki, kd, tau] = pole_placement(&gm, 5.0)?;
    for (v, w) in [(kp, 4.6571), (ki, 0.1829), (kd, 12.2857), (tau, 2.8571)] {
        assert!((v - w).abs() / w < 1e-3, "{v} vs {w}");
    }
    Ok(())
}

#[test]
fn series_pid_equals_the_series_form() -> Result<(), Error> {
    // the continuous limit: responses of Gcs and of the parallel form agree
    let (kp, ki, kd, tau, eps) = (4.6571, 0.1829, 12.2857, 2.8571, 0.3);
    let cfg = series_pid(kp, ki, kd, tau, eps, 1e-4)?;
    let pid = crate::pid::Pid::new(cfg)?;
    for w in [0.01, 0.1, 1.0] {
        let theta = w * 1e-4;
        let (cr, cy) = pid.response(theta);
        let s = Complex::new(0.0, w);
        let one = Complex::real(1.0);
        let lag = one / (s.scale(tau) + one);
        let gy = (Complex::real(kp) + Complex::real(ki) / s + s.scale(kd)) * lag;
        let gr = (Complex::real(eps * kp) + Complex::real(ki) / s) * lag;
        assert!((cy - gy).abs() / gy.abs() < 1e-3, "{w}");
        assert!((cr - gr).abs() / gr.abs() < 1e-3, "{w}");
    }
    Ok(())
}

#[test]
fn matched_discretization_of_garcia_filters() -> Result<(), Error> {
    let dc = |l: &Lti<f64, 4>| l.response(1e-12).re;
    // García et al. (2010) Example 1: γ1 = e^{−T/0.144} = 0.2494, ρ1 = e^{−T/3} = 0.9355
    let lead: Lti<f64, 4> = Lti::from_tf(&[3.0, 1.0], &[0.144, 1.0], 0.2, Discretization::Matched)?;
    let (n, d) = crate::dtc::fsp::model_tf(&lead);
    let (n, d) = (n.as_slice(), d.as_slice());
    assert!(
        (n[1] / n[0] + 0.9355).abs() < 1e-4 && (d[1] + 0.2494).abs() < 1e-4,
        "{n:?} {d:?}"
    );
    assert!((dc(&lead) - 1.0).abs() < 1e-9);
    // an improper PD gets a pole at the origin and keeps its DC gain
    let pd: Lti<f64, 4> = Lti::from_tf(&[0.5, 1.0], &[1.0], 0.1, Discretization::Matched)?;
    let (_, d) = crate::dtc::fsp::model_tf(&pd);
    assert_eq!(d.as_slice(), &[1.0, 0.0]);
    assert!((dc(&pd) - 1.0).abs() < 1e-9);
    // an integrator 2/s becomes 2·Ts/(z − 1): at θ → 0 it tends to 2/(jθ/Ts)
    let int: Lti<f64, 4> = Lti::from_tf(&[2.0], &[1.0, 0.0], 0.1, Discretization::Matched)?;
    let (n, d) = crate::dtc::fsp::model_tf(&int);
    assert!(
        (n.as_slice()[1] - 0.2).abs() < 1e-12 && d.as_slice() == [1.0, -1.0],
        "{n:?} {d:?}"
    );
    Ok(())
}
