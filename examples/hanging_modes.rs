//! The hanging sheet's out-of-plane modes against the hanging chain's, per way of stepping.
//!
//! `cargo run --release --example hanging_modes -- [seconds=32] [size=61x41] [amp=0.005]`
//!
//! A sheet hanging from its top edge and moving out of its plane as a whole across its width is
//! a hanging chain (Bernoulli, Euler): with tension `T(x) = mu g_b x` at height `x` above the free
//! edge and inertia `mu + m_a` per area (the cloth's own and the water carried along the
//! normal), its modes are `y_n(x) = J0(alpha_n sqrt(x / L))` at
//! `f_n = (alpha_n / 4 pi) sqrt(g' / L)`, `alpha_n` the zeros of J0, `g_b = g (1 - rho_w / rho_c)`
//! the buoyancy-reduced gravity and `g' = g_b mu / (mu + m_a)`. Each mode is started alone
//! (its shape, 5 mm at the free edge, at rest), the underwater preset stepped in 60 Hz frames
//! with the automatic step, and the sheet's motion projected on the mode's shape down the
//! middle column; its frequency is read from the zero crossings. The bend springs and the
//! water's drags are in the model and not in the chain: what the table shows is how far the
//! preset's cloth is from a chain, and how far each integrator is from the other.

use fraccloth::topology::grid_index;
use fraccloth::{Cloth, ClothConfig, GridSpec, Integrator, Model};

/// The first five zeros of J0.
const ALPHA: [f64; 5] = [
    2.404_825_557_7,
    5.520_078_110_3,
    8.653_727_912_9,
    11.791_534_439_0,
    14.930_917_708_5,
];

/// Zero crossings read: three periods.
const CROSSINGS: usize = 7;

/// J0 by its power series (enough terms for |z| <= 16 in f64).
fn j0(z: f64) -> f64 {
    let q = -(z * z) / 4.0;
    let (mut term, mut sum) = (1.0, 1.0);
    for k in 1..60 {
        term *= q / (k as f64 * k as f64);
        sum += term;
    }
    sum
}

fn main() {
    let args = fraccloth_tools::args::Args::from_env();
    let num = |k: &str, d: f64| args.num(k, d);
    let (w, h) = args.size("size", (61, 41));
    let (seconds, amp) = (num("seconds", 32.0), num("amp", 0.005));
    let model = Model::underwater();
    let (spacing, mu) = (0.01, 1.0);
    let length = spacing * f64::from(h - 1);
    let g_b = 9.81 * (1.0 - model.water_density / model.cloth_density);
    let g_eff = g_b * mu / (mu + model.water.added_mass);
    println!(
        "# {w}x{h} at {spacing} m, L = {length} m, g_b = {g_b:.4} m/s^2, g' = {g_eff:.5} m/s^2, {seconds} s, {amp} m at the free edge"
    );
    println!("mode | chain Hz | symplectic Hz | deviation | xpbd Hz | deviation | xpbd against symplectic");
    for (n, &alpha) in ALPHA.iter().enumerate() {
        let chain = alpha / (4.0 * std::f64::consts::PI) * (g_eff / length).sqrt();
        let f: Vec<f64> = [Integrator::SymplecticEuler, Integrator::Xpbd]
            .iter()
            .map(|&i| frequency(i, (w, h, spacing, mu), alpha, amp, seconds))
            .collect();
        let dev = |x: f64, y: f64| 100.0 * (x / y - 1.0);
        println!(
            "{} | {chain:.4} | {:.4} | {:+.1} % | {:.4} | {:+.1} % | {:+.1} %",
            n + 1,
            f[0],
            dev(f[0], chain),
            f[1],
            dev(f[1], chain),
            dev(f[1], f[0])
        );
    }
}

/// The frequency (Hz) of the mode of J0's zero `alpha` on a `w` x `h` sheet of `spacing` (m)
/// and `mu` kg/m^2 stepped with `integrator`: from its first [`CROSSINGS`] zero crossings (three
/// periods, while the started mode still dominates the drags and the modes the bend springs mix
/// in; 0 when it crossed fewer than twice).
fn frequency(
    integrator: Integrator,
    (w, h, spacing, mu): (u32, u32, f64, f64),
    alpha: f64,
    amp: f64,
    seconds: f64,
) -> f64 {
    let t = GridSpec {
        width: w,
        height: h,
        spacing,
        total_mass: mu * spacing * spacing * f64::from(w * h),
    }
    .build()
    .expect("a grid");
    let config = ClothConfig {
        model: Model::underwater(),
        integrator,
        max_substep: fraccloth::cloth::AUTO,
        ..ClothConfig::default()
    };
    let mut c = Cloth::new(t, config).expect("a cloth");
    c.set_threads(1).expect("one thread");
    let top: Vec<u32> = (0..w).map(|i| grid_index(w, i, 0)).collect();
    c.set_pinned(&top).expect("pins");
    let length = spacing * f64::from(h - 1);
    // The mode's shape by row (row 0 the pinned top, x the height above the free edge).
    let shape: Vec<f64> = (0..h)
        .map(|j| j0(alpha * ((length - spacing * f64::from(j)) / length).max(0.0).sqrt()))
        .collect();
    let mut x = c.positions().to_vec();
    for j in 0..h {
        for i in 0..w {
            x[grid_index(w, i, j) as usize].z = amp * shape[j as usize];
        }
    }
    c.set_positions(&x).expect("positions");
    let norm: f64 = shape.iter().map(|s| s * s).sum();
    let column = w / 2;
    let amplitude = |c: &Cloth| {
        let p = c.positions();
        (0..h)
            .map(|j| p[grid_index(w, column, j) as usize].z * shape[j as usize])
            .sum::<f64>()
            / norm
    };
    let (mut crossings, mut last) = (Vec::new(), (0.0, amplitude(&c)));
    let dt = 1.0 / 60.0;
    for k in 1..=(seconds / dt) as usize {
        c.step(dt).expect("a frame");
        let (time, q) = (k as f64 * dt, amplitude(&c));
        if (q > 0.0) != (last.1 > 0.0) {
            crossings.push(last.0 + dt * last.1 / (last.1 - q));
            if crossings.len() == CROSSINGS {
                break;
            }
        }
        last = (time, q);
    }
    match crossings.len() {
        0 | 1 => 0.0,
        m => (m - 1) as f64 / (2.0 * (crossings[m - 1] - crossings[0])),
    }
}
