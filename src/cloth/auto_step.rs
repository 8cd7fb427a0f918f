//! The automatic step: the largest substep the cloth as it is can take, and how a frame is
//! split when `max_substep` is [`AUTO`].
//!
//! **The estimate.** Each particle is read as a damped oscillator along its softest direction
//! (its own mass and the water it carries in every direction; the normal added mass only ever
//! slows motion): `omega^2` from the springs and contacts that touch it (Gershgorin's bound on the
//! stiffness matrix's row, `2 sum k / m`), `gamma` from everything that damps it (its springs'
//! damping, `2 sum c / m`, the drags' rates at the velocities it has now, contact damping), and
//! `rho`, the rate of the carried water's turning forces (`m_a A |v| / (m l)`, quadratic in the
//! velocity, explicit in every integrator). Then, per integrator:
//! - symplectic Euler: `h < (sqrt(gamma^2 + 4 omega^2) - gamma) / omega^2` (its exact bound on a
//!   damped oscillator: `2 / omega` undamped, `2 / gamma` overdamped);
//! - explicit Euler: the same, and `h < gamma_s / omega_s^2` for damping in proportion to the
//!   springs (`c / k` per family; for fractional springs, whose current-rate weight is
//!   `w0 = h^{1/2} / Gamma(3/2)`, `h < (k_d / (Gamma(3/2) k))^2`): explicit Euler gains energy on
//!   any undamped oscillator, and only the springs' own damping holds it;
//! - the extrapolated (second-order) steps as the step they extrapolate;
//! - implicit Euler: no bound from springs, drags or contacts; the turning forces' `2 / rho`.
//!   And an accuracy bound (implicit Euler only, not its extrapolated form): its own damping
//!   takes about `pi omega h` of a motion's amplitude a period, so the substep is kept to
//!   `h <= `[`ACCURACY`]` / omega`, `omega` the cloth's motion frequency as it moves
//!   (`motion.rs`), but never below [`ACCURACY_FLOOR`] (0.7) of the step symplectic Euler would
//!   take on the same cloth.
//!
//! And pins: no pin travels more than one spring rest length in a substep.
//!
//! **The safety factor** ([`safety`]: [`SAFETY_SYMPLECTIC`] for symplectic Euler and its
//! extrapolated form, [`SAFETY`] otherwise) times the smallest bound over particles is the
//! substep; it is measured on the stability map of every preset, mesh kind and size
//! (`docs/stability.md`, `cargo run --release --example auto_step_map`).
//!
//! **A frame never fails for want of substeps.** A frame is split into as few equal substeps as
//! the estimate allows; a frame whose substep is refused is rolled back to its start (the call
//! is atomic) and retried with twice the substeps, at most [`MAX_RETRIES`] times.

use crate::forces::{damping_rate, DampingRate, Inertia};
use crate::integrate::Integrator;
use crate::math::Vec3;
use crate::model::Model;

use super::Cloth;

/// `max_substep` that asks for the automatic step (any negative value does).
pub const AUTO: f64 = -1.0;

/// Fraction of the estimated bound the automatic step takes with explicit Euler and the
/// implicit integrators (measured: `docs/stability.md`; the smallest measured bound over the
/// estimate was 1.22 when the factor was chosen, 1.24 now, so the step stays at 0.66
/// of the measured bound or below).
pub const SAFETY: f64 = 0.8;

/// The same with symplectic Euler and its extrapolated form: their estimate is more conservative
/// (the smallest measured bound over the estimate was 1.68), so the same margin (0.65 of the
/// measured bound) is 1.1 times the estimate.
pub const SAFETY_SYMPLECTIC: f64 = 1.1;

/// The fraction of the estimate the automatic step takes with `integrator`.
pub fn safety(integrator: Integrator) -> f64 {
    match integrator.base() {
        Integrator::SymplecticEuler | Integrator::Xpbd => SAFETY_SYMPLECTIC,
        _ => SAFETY,
    }
}

/// Implicit Euler's accuracy bound: `omega h` at most this, `omega` the motion's frequency as
/// `motion.rs` reads it (frame-rate accelerations against velocities: on the 4 cm swing of
/// 61 x 41 it reads 2-3.5 times the drive's frequency, the cloth's ripples included). Measured
/// there in 12 s bakes (docs/underwater.md): at 1 Hz implicit Euler's free edge swung
/// 0.090 of the drive at its stable step against symplectic Euler's 0.217, and 0.171 with this
/// bound (25 substeps a frame), the depth of the motion within 12 % of symplectic Euler's from
/// 0.25 to 1.5 Hz; a bound of 0.025 took 17 substeps a frame at 1 Hz and gave 0.149.
pub const ACCURACY: f64 = 0.016;

/// The shortest substep the accuracy bound may ask of implicit Euler, as a fraction of the step
/// symplectic Euler takes on the same cloth. Measured on the 61 x 41 swing, 12 s bakes
/// (docs/underwater.md): at 2 Hz the bound asks for less than symplectic Euler's step.
/// With the floor at 1 (symplectic Euler's step) implicit Euler read 5.61 half-waves against
/// symplectic Euler's 6.89 (-19 %); at 0.7, 6.02 (-13 %) for 42 substeps a frame instead of 30;
/// at 0.5, 6.06 for 52.
pub const ACCURACY_FLOOR: f64 = 0.7;

/// Times a refused frame is retried with twice the substeps (so up to 16 times the estimate's).
pub const MAX_RETRIES: u32 = 4;

/// Gamma(3/2) = sqrt(pi) / 2: `w0 = h^{1/2} / Gamma(3/2)` for the half-derivative's current rate.
const GAMMA_3_2: f64 = 0.886_226_925_452_758;

/// What the last call to `step` did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepStats {
    /// Substeps the last call took (the successful attempt's; the pieces of a substep
    /// self-collision split counted one by one, `cloth/split.rs`).
    pub substeps: u32,
    /// Attempts refused and retried with twice the substeps (automatic step only).
    pub retries: u32,
    /// The automatic step's substep estimate for the last call, s (0 with a fixed step).
    pub estimate: f64,
}

/// The bound of symplectic Euler on `x'' + gamma x' + omega^2 x = 0`.
fn symplectic_bound(omega2: f64, gamma: f64) -> f64 {
    if omega2 <= 0.0 {
        return if gamma > 0.0 { 2.0 / gamma } else { f64::INFINITY };
    }
    ((gamma * gamma + 4.0 * omega2).sqrt() - gamma) / omega2
}

/// Explicit Euler's bound from damping in proportion to the springs (`c / k` per family), on
/// a cloth of spacing `spacing`.
fn explicit_bound(m: &Model, spacing: f64) -> f64 {
    use crate::topology::SpringKind::*;
    let mut bound = f64::INFINITY;
    for kind in [Stretch, Shear, Bend] {
        let (k, c) = (m.stiffness(kind, spacing), m.spring_damping_of(kind));
        // Undamped springs give no bound of this kind (explicit Euler then gains energy at any
        // step, slowly: half symplectic Euler's bound holds it for the shot's length).
        if k <= 0.0 || c <= 0.0 {
            continue;
        }
        let b = match damping_rate(m) {
            DampingRate::Velocity => c / k,
            DampingRate::HalfDerivative => (c / (GAMMA_3_2 * k)).powi(2),
            DampingRate::None => f64::INFINITY,
        };
        bound = bound.min(b);
    }
    bound
}

/// The sums over the springs of particle `i` the estimate reads: stiffness (N/m), damping
/// (N s/m; fractional damping at the current-rate weight `w0`) and the shortest rest length
/// (m). XPBD (`constrained`): its constrained springs' stiffness bounds nothing, and neither
/// does velocity damping, which its constraints carry.
fn spring_sums(
    m: &Model,
    t: &crate::topology::Topology,
    i: usize,
    w0: f64,
    constrained: bool,
) -> (f64, f64, f64) {
    let free = |kind| !(constrained && super::constrained::constrained(kind));
    let carried = constrained && m.spring_damping_mode == crate::model::SpringDamping::Velocity;
    let rate = damping_rate(m);
    let (mut k, mut c, mut shortest) = (0.0, 0.0, f64::INFINITY);
    for &e in t.vertex_springs.row(i) {
        let s = &t.springs[(e / 2) as usize];
        shortest = shortest.min(s.rest);
        if free(s.kind) {
            k += m.stiffness(s.kind, t.spacing);
        }
        if carried {
            continue;
        }
        c += match rate {
            DampingRate::Velocity => m.spring_damping_of(s.kind),
            DampingRate::HalfDerivative => w0 * m.spring_damping_of(s.kind),
            DampingRate::None => 0.0,
        };
    }
    (k, c, shortest)
}

/// The terms' damping rate (1/s) of a particle of isotropic mass `mass` (kg) and `area` (m^2)
/// at `speed` (m/s) relative to the water, as each term says (each in its own direction; the
/// largest is what limits). XPBD (`constrained`): a term along the normal acts on the water
/// carried there too.
fn drag_rate(m: &Model, area: f64, speed: f64, w0: f64, mass: f64, constrained: bool) -> f64 {
    let terms = &crate::forces::terms::TERMS;
    let rate = |t: &crate::forces::terms::Term| (t.rate)(m, area, speed, w0);
    if constrained {
        let normal_mass = mass + m.water.added_mass * area;
        let along = |normal| terms.iter().filter(move |t| t.along_normal == normal);
        (along(false).map(rate).sum::<f64>() / mass).max(along(true).map(rate).sum::<f64>() / normal_mass)
    } else {
        terms.iter().map(rate).sum::<f64>() / mass
    }
}

/// Every particle's [`spring_sums`] for the model and integrator they were summed for: they
/// change only when those do, and summing them was most of the estimate's work. Kept only
/// where they do not depend on the step (no fractional spring damping).
#[derive(Clone, Debug, Default)]
pub(super) struct SpringSums {
    key: Option<(Model, Integrator)>,
    sums: Vec<(f64, f64, f64)>,
}

impl SpringSums {
    /// The sums for `m` and `integrator`, if kept.
    fn get(&self, m: &Model, integrator: Integrator) -> Option<&[(f64, f64, f64)]> {
        (self.key == Some((*m, integrator))).then_some(&self.sums[..])
    }
}

impl Cloth {
    /// Sums the springs of every particle again ([`SpringSums`]) when the model or the
    /// integrator changed; fails with out-of-memory when the room cannot be had.
    fn refresh_spring_sums(&mut self) -> Result<(), crate::error::Error> {
        let (m, integrator) = (self.config.model, self.config.integrator.base());
        let kept = &mut self.scratch.spring_sums;
        if damping_rate(&m) == DampingRate::HalfDerivative || kept.get(&m, integrator).is_some() {
            return Ok(());
        }
        kept.key = None;
        kept.sums.clear();
        let n = self.topology.vertex_count();
        kept.sums.try_reserve_exact(n).map_err(|_| {
            crate::error::Error::out_of_memory("automatic step: no room for the springs' sums")
        })?;
        let t = &self.topology;
        let constrained = integrator.is_constrained();
        kept.sums
            .extend((0..n).map(|i| spring_sums(&m, t, i, 0.0, constrained)));
        kept.key = Some((m, integrator));
        Ok(())
    }

    /// Advances by `dt` with the automatic step (module docs).
    pub(super) fn step_auto(&mut self, dt: f64) -> Result<(), crate::error::Error> {
        use crate::error::ErrorKind;
        self.measure_contact_weights()?;
        self.refresh_spring_sums()?;
        let h = self.auto_substep(dt);
        let tracks = self.tracks_motion();
        if tracks {
            let start = &mut self.scratch.motion_v;
            start.clear();
            start.extend_from_slice(&self.state.v);
        }
        let limit = f64::from(super::MAX_SUBSTEPS);
        let mut n = if h > 0.0 {
            (dt / h).ceil().clamp(1.0, limit)
        } else {
            limit
        };
        let mut retries = 0;
        loop {
            let substeps = n as u32;
            let stepped = self.call(dt, substeps, true);
            match stepped {
                Ok(()) => {
                    if tracks {
                        let t = &self.topology;
                        let (start, end) = (&self.scratch.motion_v, &self.state.v);
                        self.state
                            .motion
                            .update(&t.masses, &self.pins.pinned, start, end, dt);
                    }
                    self.step_stats = StepStats {
                        // Self-collision may have split some (`split.rs`).
                        substeps: self.step_stats.substeps,
                        retries,
                        estimate: h,
                    };
                    return Ok(());
                }
                Err(e)
                    if retries < MAX_RETRIES
                        && n < limit
                        && matches!(e.kind, ErrorKind::Unstable | ErrorKind::NotConverged) =>
                {
                    retries += 1;
                    n = (2.0 * n).min(limit);
                }
                Err(mut e) => {
                    e.message = format!(
                        "{} (automatic step: the estimate was {h:.3e} s; refused with {substeps} substeps after {retries} retries with twice as many)",
                        e.message
                    );
                    return Err(e);
                }
            }
        }
    }

    /// The automatic step's substep for a call of `dt` seconds whose pins end at their
    /// targets: [`safety`] times the smallest bound (module docs), never above `dt`, with the
    /// mesh contacts measured as the last automatic step began.
    pub fn auto_substep(&self, dt: f64) -> f64 {
        let weight = &self.scratch.contact_weight;
        // Fractional damping's current-rate weight grows as h^{1/2}: the bound at the bound.
        let (mut h, mut floor) = self.substep_bound(dt, 0.0, weight);
        if self.fractional_damping() {
            for _ in 0..3 {
                (h, floor) = self.substep_bound(dt, h, weight);
            }
        }
        let mut h = safety(self.config.integrator) * h;
        let omega = self.state.motion.omega();
        if self.tracks_motion() && omega > 0.0 {
            h = h.min((ACCURACY / omega).max(ACCURACY_FLOOR * SAFETY_SYMPLECTIC * floor));
        }
        h.min(dt)
    }

    /// Whether the automatic step bounds implicit Euler's damping of the motion (module docs).
    fn tracks_motion(&self) -> bool {
        self.config.integrator == Integrator::ImplicitEuler && self.config.max_substep < 0.0
    }

    /// The motion's averaged frequency the automatic step reads, rad/s (0: none yet, or not
    /// tracked: implicit Euler at the automatic step only).
    pub fn motion_frequency(&self) -> f64 {
        self.state.motion.omega()
    }

    /// Whether the springs or drags damp on D^{1/2} (their damping depends on the step).
    fn fractional_damping(&self) -> bool {
        let m = &self.config.model;
        damping_rate(m) == DampingRate::HalfDerivative || m.history_drag > 0.0 || m.water.history_drag > 0.0
    }

    /// The smallest bound over the particles and pins (module docs); `h` the step at which the
    /// half-derivative's current-rate weight `h^{1/2} / Gamma(3/2)` is taken (0: none);
    /// `weight` each vertex's contact weight (`Cloth::measure_contact_weights`; empty: none).
    /// Also symplectic Euler's bound on the same oscillators (implicit Euler's accuracy floor).
    fn substep_bound(&self, dt: f64, h: f64, weight: &[f64]) -> (f64, f64) {
        let w0 = h.sqrt() / GAMMA_3_2;
        let m = &self.config.model;
        let t = &self.topology;
        let integrator = self.config.integrator.base();
        let implicit = integrator == Integrator::ImplicitEuler;
        let explicit = integrator == Integrator::ExplicitEuler;
        // Explicit Euler: half symplectic Euler's bound (measured: docs/stability.md), and the
        // springs' damping bound.
        let mut bound = if explicit {
            explicit_bound(m, t.spacing)
        } else {
            f64::INFINITY
        };
        let oscillator = if explicit { 0.5 } else { 1.0 };
        let constrained = integrator.is_constrained();
        let ma = m.water.added_mass;
        let mut floor = f64::INFINITY;
        let kept = self.scratch.spring_sums.get(m, integrator);
        for i in 0..self.state.x.len() {
            if self.pins.pinned[i] {
                continue;
            }
            let inertia = Inertia::of(m, t.masses[i], t.areas[i], Vec3::z(), 0.0);
            let mass = inertia.isotropic();
            let (k, c, shortest) = match kept {
                Some(sums) => sums[i],
                None => spring_sums(m, t, i, w0, constrained),
            };
            let area = t.areas[i];
            let speed = (self.state.v[i] - m.current).norm();
            let drag = drag_rate(m, area, speed, w0, mass, constrained);
            let mut omega2 = 2.0 * k / mass;
            let mut gamma = 2.0 * c / mass + drag;
            // Contacts: every vertex may touch an analytic collider; the mesh colliders' by
            // their weight where the call begins (self-collision's are left to the retries).
            let touch =
                f64::from(u8::from(!self.colliders.is_empty())) + weight.get(i).copied().unwrap_or(0.0);
            if touch > 0.0 {
                omega2 += touch * m.collision_stiffness / mass;
                gamma += touch * m.collision_damping / mass;
            }
            let oscillator_bound = symplectic_bound(omega2, gamma);
            floor = floor.min(oscillator_bound);
            if !implicit {
                bound = bound.min(oscillator * oscillator_bound);
            }
            // The carried water's turning forces, explicit in every integrator.
            if ma > 0.0 && shortest.is_finite() && shortest > 0.0 {
                let rho = ma * area * speed / (mass * shortest);
                if rho > 0.0 {
                    bound = bound.min(2.0 / rho);
                }
            }
        }
        // Pins travel at most one rest length of their springs per substep.
        for &p in &self.pins.list {
            let p = p as usize;
            let travel = (self.pins.target[p] - self.state.x[p]).norm();
            let shortest = t
                .vertex_springs
                .row(p)
                .iter()
                .map(|&e| t.springs[(e / 2) as usize].rest)
                .fold(f64::INFINITY, f64::min);
            if travel > 0.0 && shortest.is_finite() {
                bound = bound.min(dt * shortest / travel / safety(integrator));
            }
        }
        (bound, floor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symplectic_bound_is_the_damped_oscillators() {
        // Undamped: 2 / omega; overdamped without stiffness: 2 / gamma; and on the boundary
        // the amplification of symplectic Euler has modulus 1.
        assert!((symplectic_bound(100.0, 0.0) - 0.2).abs() < 1e-15);
        assert!((symplectic_bound(0.0, 50.0) - 0.04).abs() < 1e-15);
        let (w2, g) = (1.0e6, 1800.0);
        let h = symplectic_bound(w2, g);
        // v' = v + h(-w2 x - g v), x' = x + h v': on (x, v) the step matrix is
        // [[1 - h^2 w2, h (1 - h g)], [-h w2, 1 - h g]]; stable iff |det| <= 1 and
        // |tr| <= 1 + det, and the bound sits where tr = -(1 + det).
        let tr = (1.0 - h * h * w2) + (1.0 - h * g);
        let det = (1.0 - h * h * w2) * (1.0 - h * g) + h * w2 * h * (1.0 - h * g);
        assert!((tr + 1.0 + det).abs() < 1e-9, "tr {tr} det {det}");
        assert!(h > 8.9e-4 && h < 8.92e-4, "{h}");
    }

    #[test]
    fn undamped_springs_leave_explicit_euler_a_finite_step() {
        let mut m = Model::regular(crate::model::RegularDrag::Normal);
        m.spring_damping = 0.0;
        assert_eq!(explicit_bound(&m, 0.01), f64::INFINITY);
        m.spring_damping_mode = crate::model::SpringDamping::None;
        assert_eq!(explicit_bound(&m, 0.01), f64::INFINITY);
    }

    #[test]
    fn explicit_eulers_bound_for_the_papers_springs_is_its_measured_one() {
        // Eq. 5 springs, k_d 0.35, k 10: (k_d / (Gamma(3/2) k))^2 = 1.56 ms; the stability
        // map measured 1.3-1.7 ms on the swing (docs/stability.md).
        let b = explicit_bound(&Model::fractional(), 0.01);
        assert!((b - 1.56e-3).abs() < 0.01e-3, "{b}");
    }
}
