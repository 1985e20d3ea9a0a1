use super::*;

/// The interleaved Horner sum is the polynomial's value, for every
/// length around the chains' multiple of four: against the sum of
/// `p_k·e^{−jkθ}` from each term's own sine and cosine.
#[test]
fn taps_at_is_the_polynomial() {
    for n in 0..11usize {
        let p: std::vec::Vec<f64> = (0..n).map(|k| 1.0 + 0.37 * k as f64).collect();
        for theta in [0.0, 0.3, 1.7, 3.1] {
            let got = taps_at(&p, Complex::cis(-theta));
            let want = p.iter().enumerate().fold(Complex::default(), |a, (k, b)| {
                a + Complex::cis(-theta * k as f64).scale(*b)
            });
            let err = (got - want).abs();
            // a few roundings per term of a sum of magnitude below 25
            assert!(err < 1e-13, "n {n}, θ {theta}: {err:e}");
        }
    }
}
