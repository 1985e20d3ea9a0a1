//! Plant expressions parse to the right transfer function; bad ones name the column.
mod common;
use msp::syntax::parse_plant;

fn check(expr: &str, num: &[f64], den: &[f64], delay: f64) {
    let tf = parse_plant(expr).unwrap_or_else(|e| panic!("{expr}: {e}"));
    // compare as rational functions: num·den' = num'·den at several points
    for x in [0.3, 1.7, -2.1, 4.0] {
        let a = msp::poly::eval(&tf.num, x) * msp::poly::eval(den, x);
        let b = msp::poly::eval(num, x) * msp::poly::eval(&tf.den, x);
        assert!(
            common::close(a, b, 1e-12, 1e-12),
            "{expr}: at {x}: {a} vs {b} ({tf:?})"
        );
    }
    assert!(
        (tf.delay - delay).abs() < 1e-12,
        "{expr}: delay {}",
        tf.delay
    );
    // canonical form parses back to the same function
    let again = parse_plant(&tf.to_string()).unwrap_or_else(|e| panic!("{}: {e}", tf));
    assert!((again.delay - tf.delay).abs() < 1e-12);
    for x in [0.3, 1.7] {
        let a = msp::poly::eval(&again.num, x) / msp::poly::eval(&again.den, x);
        let b = msp::poly::eval(&tf.num, x) / msp::poly::eval(&tf.den, x);
        assert!(common::close(a, b, 1e-9, 1e-12), "round trip of {tf}");
    }
}

#[test]
fn expressions_of_the_sources() {
    check("0.2/s*e^-7.4s", &[0.2], &[1.0, 0.0], 7.4);
    check("0.05/s*e^(-6s)", &[0.05], &[1.0, 0.0], 6.0);
    check("5.6*e^-93.9s/(40.2s+1)", &[5.6], &[40.2, 1.0], 93.9);
    check("exp(-93.9*s)*5.6/(40.2*s+1)", &[5.6], &[40.2, 1.0], 93.9);
    check("e^-10s/((17s+1)(6s+1))", &[1.0], &[102.0, 23.0, 1.0], 10.0);
    check("e^-10s/(s+1)^2", &[1.0], &[1.0, 2.0, 1.0], 10.0);
    check("5/(100s-1)*e^-6s", &[5.0], &[100.0, -1.0], 6.0);
    check(
        "(0.1251s+1)*e^-0.8s/(2.828s-1)",
        &[0.1251, 1.0],
        &[2.828, -1.0],
        0.8,
    );
    check(
        "e^-5s/(s(0.9s+1)(0.5s+1)(0.3s+1)(0.1s+1))",
        &[1.0],
        &msp::poly::mul(
            &msp::poly::mul(&msp::poly::mul(&[0.9, 1.0, 0.0], &[0.5, 1.0]), &[0.3, 1.0]),
            &[0.1, 1.0],
        ),
        5.0,
    );
    check("2*e^-2s/s", &[2.0], &[1.0, 0.0], 2.0);
    check("(1-0.5s)/(s^2+1.4s+1)", &[-0.5, 1.0], &[1.0, 1.4, 1.0], 0.0);
    check("1e-3/(s + .5)", &[1e-3], &[1.0, 0.5], 0.0);
    check("e^-1s*e^-2s/(s+1)", &[1.0], &[1.0, 1.0], 3.0);
    check(" 2 e^-2 s / s ", &[2.0], &[1.0, 0.0], 2.0);
    // signs before a power and in the delay's exponent
    check("1/(s+1)^+2", &[1.0], &[1.0, 2.0, 1.0], 0.0);
    check("s^-1*e^(-2s)", &[1.0], &[1.0, 0.0], 2.0);
}

/// The schedules' `VALUE[@TIME]`: the time 0 when absent, never negative.
#[test]
fn schedules_read_value_at_time() {
    use msp::sim::{Disturbance, SetpointStep};
    let step: SetpointStep = "2@10".parse().unwrap();
    assert_eq!((step.value, step.at), (2.0, 10.0));
    let d: Disturbance = "input:-0.1".parse().unwrap();
    assert_eq!((d.value, d.at), (-0.1, 0.0));
    let e = "1@-2".parse::<SetpointStep>().unwrap_err();
    assert_eq!(e, "the set point time must not be negative");
    let e = "output:0.5@-1".parse::<Disturbance>().unwrap_err();
    assert_eq!(e, "the disturbance time must not be negative");
}

fn bad(expr: &str, col: usize, words: &str) {
    let e = parse_plant(expr).expect_err(expr);
    assert_eq!(e.column, col, "{expr}: {e}");
    assert!(
        e.message.contains(words),
        "{expr}: '{}' lacks '{words}'",
        e.message
    );
    assert!(e.to_string().contains('^'));
}

/// The refused expressions of `tests/data/bad_expressions.tsv` (text,
/// column, words of the message), and the empty ones.
#[test]
fn bad_expressions_name_the_problem_and_column() {
    let table = include_str!("data/bad_expressions.tsv");
    let rows: Vec<Vec<&str>> = table
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split('\t').collect())
        .collect();
    assert!(rows.len() >= 10, "{rows:?}");
    for row in rows {
        let [expr, col, words] = row[..] else {
            panic!("a row of three fields: {row:?}");
        };
        bad(expr, col.parse().unwrap(), words);
    }
    bad("", 1, "empty");
    bad("   ", 1, "empty");
}

#[test]
fn fuzz_findings_stay_fixed() {
    // a canonical form with a power above the old limit of 64 must parse back
    // (found with `s4` for `s*4`, which is now refused: see below)
    let tf = parse_plant("ssss^\u{c}-31s*4ss^\u{c}-31sss^\u{c}-31s*4ss*4s*4s^4s*4").unwrap();
    let again = parse_plant(&tf.to_string()).unwrap();
    assert_eq!(again.to_string(), tf.to_string());
    // powers that would build enormous polynomials are refused, not computed
    let e = parse_plant("((s+1)^200)^200").unwrap_err();
    assert!(e.message.contains("degree above 256"), "{e}");
}

#[test]
fn sums_cannot_build_polynomials_beyond_the_limit_either() {
    let big = (0..30)
        .map(|i| format!("1/(s^{})", 10 + i))
        .collect::<Vec<_>>()
        .join("+");
    match parse_plant(&big) {
        Ok(tf) => assert!(parse_plant(&tf.to_string()).is_ok()),
        Err(e) => assert!(e.message.contains("degree above 256"), "{e}"),
    }
}

#[test]
fn deep_and_long_inputs_are_refused_not_crashed() {
    use msp::syntax::expr::{MAX_DEPTH, MAX_INPUT};
    // as deep as allowed parses; one level more is an error at that parenthesis
    let ok = format!("{}1{}/(s+1)", "(".repeat(MAX_DEPTH), ")".repeat(MAX_DEPTH));
    assert!(parse_plant(&ok).is_ok(), "{ok}");
    let deep = format!("{}1{}", "(".repeat(2000), ")".repeat(2000));
    let e = parse_plant(&deep).unwrap_err();
    assert!(e.message.contains("nested more than"), "{e}");
    assert_eq!(e.column, MAX_DEPTH + 1);
    // a huge input is refused by its length, and the error shows a window of it
    let long = format!("1/(s+1){}", "+0".repeat(25_000_000));
    let e = parse_plant(&long).unwrap_err();
    assert!(e.message.contains("the limit is"), "{}", e.message);
    assert!(e.to_string().len() < 300, "{} bytes", e.to_string().len());
    // a long but valid-length input with an error far in: the caret is under it
    let far = format!("{}x", "1*".repeat(1000));
    let e = parse_plant(&far).unwrap_err();
    let shown = e.to_string();
    let lines: Vec<&str> = shown.lines().collect();
    let caret = lines[2].find('^').unwrap();
    assert_eq!(lines[1].chars().nth(caret), Some('x'), "{shown}");
    assert!(shown.len() < 300);
    assert!(deep.len() < MAX_INPUT);
}

/// A plant prints as an engineer factors it (time-constant form, repeated
/// factors as powers, integrators as `s^m`), and the printed form parses
/// back to the same coefficients; a polynomial without a clean factorization
/// stays expanded.
#[test]
fn plants_print_factored_and_parse_back() {
    for (expr, shown) in [
        ("2*e^-5s/(10s+1)^4", "2*e^(-5s)/(10s + 1)^4"),
        ("e^-1.5s/(s*(s+1))", "e^(-1.5s)/(s(s + 1))"),
        ("0.2/s^2*e^-1s/(s+1)", "0.2*e^(-s)/(s^2(s + 1))"),
        ("1/(s^2+3s+2)", "0.5/((s + 1)(0.5s + 1))"),
        ("(2s+1)^2/((s+1)^3(5s+1))", "(2s + 1)^2/((5s + 1)(s + 1)^3)"),
        ("1/(s^2+s+1)^2", "1/(s^2 + s + 1)^2"),
        ("-1/((s-1)(2s+1))", "-1/((2s + 1)(s - 1))"),
        ("1/(s+1)^8", "1/(s + 1)^8"),
        ("1/((s+1)(1.001s+1))", "1/((1.001s + 1)(s + 1))"),
        (
            "1/(s^2+2.3456789s+1.1)",
            "0.909090909091/(0.909090909091s^2 + 2.13243536364s + 1)",
        ),
        ("5.6*e^-93.9s/(40.2s+1)", "5.6*e^(-93.9s)/(40.2s + 1)"),
        ("e^-1e-6s/(1e-9s+1)", "e^(-1e-6s)/(1e-9s + 1)"),
    ] {
        let tf = parse_plant(expr).unwrap();
        assert_eq!(tf.to_string(), shown, "{expr}");
        let again = parse_plant(shown).unwrap();
        // the same coefficients, both normalised by their largest denominator one
        let big = |p: &[f64]| p.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        let (a, b) = (big(&again.den), big(&tf.den));
        for (p, q) in again
            .den
            .iter()
            .zip(&tf.den)
            .chain(again.num.iter().zip(&tf.num))
        {
            assert!(
                (p / a - q / b).abs() <= 1e-11,
                "{expr}: {again:?} vs {tf:?}"
            );
        }
        assert_eq!(again.delay, tf.delay);
    }
}

/// Coefficients handed in directly (Python's `msp.Plant(num, den)`, a
/// scenario's lists) are bounded as the grammar bounds an expression: a
/// degree of 256 is a plant, one above it an error that says the bound.
#[test]
fn a_transfer_function_made_from_coefficients_has_the_grammars_degree_bound() {
    use msp::poly::TransferFunction;
    assert!(TransferFunction::new(&[1.0], &[1.0; 257], 0.0).is_ok());
    let e = TransferFunction::new(&[1.0], &[1.0; 2001], 0.0).unwrap_err();
    assert!(e.to_string().contains("256"), "{e}");
    // the grammar's own bound is the same number
    let deep = format!("1/(s+1)^{}", 257);
    assert!(deep.parse::<TransferFunction>().is_err());
    assert!("1/(s+1)^256".parse::<TransferFunction>().is_ok());
}

/// A squared delay is written with parentheses, and means what it says.
#[test]
fn a_delay_raised_to_a_power_in_parentheses() {
    use msp::poly::TransferFunction;
    let t: TransferFunction = "(e^-5s)^2/(s+1)".parse().unwrap();
    assert_eq!(t.delay, 10.0);
}
