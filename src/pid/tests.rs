use super::*;

#[test]
fn proportional_only() -> Result<(), Box<dyn std::error::Error>> {
    let mut c = Pid::new(PidConfig::isa(2.0, f64::INFINITY, 0.0, 0.1))?;
    assert_eq!(c.update(1.0, 0.25), 1.5);
    assert_eq!(c.update(1.0, 0.25), 1.5);
    Ok(())
}

#[test]
fn pi_integrates_forward_euler() -> Result<(), Box<dyn std::error::Error>> {
    let mut c = Pid::new(PidConfig::isa(1.0, 2.0, 0.0, 0.5))?;
    // I[0] = 0, I[1] = 0.5/2 * 1
    assert_eq!(c.update(1.0, 0.0), 1.0);
    assert_eq!(c.update(1.0, 0.0), 1.25);
    assert_eq!(c.update(1.0, 0.0), 1.5);
    Ok(())
}

#[test]
fn validation_names_the_field() -> Result<(), Box<dyn std::error::Error>> {
    let ok = PidConfig::isa(1.0, 2.0, 0.0, 0.1);
    assert_eq!(
        Pid::new(PidConfig { ts: 0.0, ..ok }).err(),
        Some(Error::NotPositive("ts"))
    );
    assert_eq!(
        Pid::new(PidConfig { kp: f64::NAN, ..ok }).err(),
        Some(Error::NonFinite("kp"))
    );
    assert_eq!(
        Pid::new(ok.with_limits(1.0, -1.0)).err(),
        Some(Error::InvalidLimits("u_min"))
    );
    Ok(())
}
