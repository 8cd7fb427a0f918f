//! The reference mathematics used by the accuracy tests is itself checked here.

mod common;

use common::reference::*;
use nalgebra::Complex;

#[test]
fn talbot_inverts_known_transforms() {
    for &t in &[0.1f64, 1.0, 3.0] {
        let e = talbot(|s| Complex::new(1.0, 0.0) / (s + 1.0), t, 32);
        assert!((e - (-t).exp()).abs() < 1e-10, "t={t}: {e}");
        let sin = talbot(|s| Complex::new(1.0, 0.0) / (s * s + 1.0), t, 32);
        assert!((sin - t.sin()).abs() < 1e-9, "t={t}: {sin}");
        // 1/sqrt(s) -> 1/sqrt(pi t): a branch cut like the fractional oscillator's.
        let k = talbot(|s| Complex::new(1.0, 0.0) / s.sqrt(), t, 32);
        assert!(
            (k - 1.0 / (std::f64::consts::PI * t).sqrt()).abs() < 1e-9,
            "t={t}: {k}"
        );
    }
}

#[test]
fn special_functions_match_tabulated_values() {
    // Abramowitz & Stegun table 7.7 and 7.5.
    let (c, s) = fresnel(1.0);
    assert!((c - 0.779_893_400_376_823).abs() < 1e-12 && (s - 0.438_259_147_390_355).abs() < 1e-12);
    assert!((dawson(1.0) - 0.538_079_506_912_768).abs() < 1e-12);
    // e^{x^2} erfc(x) at x = 1: 0.427583576155807.
    let v = erfcx_complex(Complex::new(1.0, 0.0));
    assert!((v.re - 0.427_583_576_155_807).abs() < 1e-12 && v.im.abs() < 1e-15);
}
