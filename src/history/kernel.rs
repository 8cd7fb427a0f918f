//! Closed-form product-integration weights of the kernel `(t - s)^{-1/2} / sqrt(pi)`
//! against piecewise-linear velocity ("PI-trap").
//!
//! For one panel whose ends lie at distances `a < b` from the evaluation time
//! (distance σ = t - s), with the velocity linear between `v_near` (at σ = a) and
//! `v_far` (at σ = b):
//!
//! ```text
//! integral_a^b σ^{-1/2} v(σ) dσ / sqrt(pi) = w_near v_near + w_far v_far
//! w_near = 2 d^2 (2q + p) / (3 (b - a) sqrt(pi)),  w_far = 2 d^2 (q + 2p) / (3 (b - a) sqrt(pi))
//! ```
//!
//! with `p = sqrt(a)`, `q = sqrt(b)`, `d = q - p = (b - a)/(p + q)`. These forms have no
//! cancellation, unlike the textbook `A_k - k B_k`, so they stay accurate for panels far
//! in the past. For a uniform step h and a = k h they equal
//! `sqrt(h/pi) ((k+1) B_k - A_k)` and `sqrt(h/pi) (A_k - k B_k)`.

/// `(w_near, w_far)` for a panel spanning distances `[a, b]`, `0 <= a < b`.
pub fn panel_weights(a: f64, b: f64) -> (f64, f64) {
    let p = a.sqrt();
    let q = b.sqrt();
    let width = b - a;
    let d = width / (p + q);
    let c = 2.0 * d * d / (3.0 * width * std::f64::consts::PI.sqrt());
    (c * (2.0 * q + p), c * (q + 2.0 * p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_textbook_form_for_uniform_steps() {
        let h = 0.01f64;
        let sq = (h / std::f64::consts::PI).sqrt();
        for k in 0..50u32 {
            let kf = f64::from(k);
            let a_k = 2.0 / 3.0 * ((kf + 1.0).powf(1.5) - kf.powf(1.5));
            let b_k = 2.0 * ((kf + 1.0).sqrt() - kf.sqrt());
            let (near, far) = panel_weights(kf * h, (kf + 1.0) * h);
            approx::assert_relative_eq!(near, sq * ((kf + 1.0) * b_k - a_k), max_relative = 1e-10);
            approx::assert_relative_eq!(far, sq * (a_k - kf * b_k), max_relative = 1e-10);
        }
        // The current-velocity weight of the notes: 4/3 sqrt(h/pi).
        approx::assert_relative_eq!(panel_weights(0.0, h).0, 4.0 / 3.0 * sq, max_relative = 1e-15);
    }

    #[test]
    fn integrates_linear_velocity_exactly() {
        // v(σ) = 2 - 3σ on [a, b]: integral of σ^{-1/2}(2 - 3σ) = 4(q - p) - 2(q^3 - p^3).
        let (a, b) = (0.3f64, 0.7f64);
        let (near, far) = panel_weights(a, b);
        let exact =
            (4.0 * (b.sqrt() - a.sqrt()) - 2.0 * (b.powf(1.5) - a.powf(1.5))) / std::f64::consts::PI.sqrt();
        approx::assert_relative_eq!(
            near * (2.0 - 3.0 * a) + far * (2.0 - 3.0 * b),
            exact,
            max_relative = 1e-13
        );
    }
}
