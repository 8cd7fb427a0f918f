//! Independent reference mathematics for the accuracy tests: composite Gauss-Legendre
//! quadrature, Fresnel integrals, Dawson's function, and numerical inverse Laplace
//! transforms (fixed Talbot). None of it shares code with the library.
#![allow(dead_code)]

use nalgebra::Complex;

type C64 = Complex<f64>;

const GL8_X: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
const GL8_W: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

/// Composite 8-point Gauss-Legendre over [a, b] with `panels` panels.
pub fn integrate<F: Fn(f64) -> T, T>(f: F, a: f64, b: f64, panels: usize) -> T
where
    T: std::ops::Add<Output = T> + std::ops::Mul<f64, Output = T> + Copy + Default,
{
    let h = (b - a) / panels as f64;
    let mut sum = T::default();
    for p in 0..panels {
        let mid = a + (p as f64 + 0.5) * h;
        for k in 0..4 {
            let dx = 0.5 * h * GL8_X[k];
            sum = sum + (f(mid - dx) + f(mid + dx)) * (0.5 * h * GL8_W[k]);
        }
    }
    sum
}

/// Fresnel integrals (C(z), S(z)) = integral_0^z (cos, sin)(pi s^2 / 2) ds.
pub fn fresnel(z: f64) -> (f64, f64) {
    let panels = 64 + (z * z * 8.0) as usize;
    let c = integrate(|s| (std::f64::consts::FRAC_PI_2 * s * s).cos(), 0.0, z, panels);
    let s = integrate(|s| (std::f64::consts::FRAC_PI_2 * s * s).sin(), 0.0, z, panels);
    (c, s)
}

/// Dawson's function F(y) = e^{-y^2} integral_0^y e^{s^2} ds.
pub fn dawson(y: f64) -> f64 {
    integrate(|s| (s * s - y * y).exp(), 0.0, y, 64)
}

/// Numerical inverse Laplace transform at t > 0 by the fixed Talbot method
/// (Abate & Valko 2004) with M nodes.
pub fn talbot(f: impl Fn(C64) -> C64, t: f64, m: usize) -> f64 {
    let r = 2.0 * m as f64 / (5.0 * t);
    let mut sum = 0.5 * (f(C64::new(r, 0.0)) * (r * t).exp()).re;
    for k in 1..m {
        let th = k as f64 * std::f64::consts::PI / m as f64;
        let cot = th.cos() / th.sin();
        let s = C64::new(r * th * cot, r * th);
        let sigma = th + (th * cot - 1.0) * cot;
        sum += ((s * t).exp() * f(s) * C64::new(1.0, sigma)).re;
    }
    r / m as f64 * sum
}

/// e^{z^2} erfc(z) for complex z with Re z >= 0, from
/// `(2/sqrt(pi)) integral_0^inf exp(-s^2 - 2 z s) ds`.
pub fn erfcx_complex(z: C64) -> C64 {
    let f = |s: f64| (C64::new(-s * s, 0.0) - z * (2.0 * s)).exp();
    let v = integrate(f, 0.0, 12.0, 400);
    v * (2.0 / std::f64::consts::PI.sqrt())
}

#[cfg(test)]
mod tests {}
