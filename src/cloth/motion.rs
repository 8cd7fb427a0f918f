//! The cloth's motion frequency, for implicit Euler's accuracy bound on the automatic step.
//!
//! Implicit Euler takes energy from every mode it steps: on an oscillator of frequency
//! `omega` its energy identity loses `1/2 (m |dv|^2 + k |dx|^2)`, about `omega^2 h E`, each
//! step, so the amplitude decays at `omega^2 h / 2` a second, `pi omega h` a period. At the
//! step its stability allows (a frame, or a few substeps) that is a large fraction of what the
//! water takes: measured at 1 Hz (4 cm, 61 x 41, underwater preset), implicit Euler's shot gave
//! 2.5-2.8 half-waves at 10-33 ms steps against 4.76 converged (docs/underwater.md;
//! counted as the look meter counted them before 0.9.23).
//!
//! The frequency is read from the cloth as it moves, once per call: the free particles'
//! mass-weighted mean square of `(v_end - v_start) / dt` over the call (frame-rate
//! differences: motion faster than the calls is not seen, as it is not seen in the frames)
//! against their mean square velocity. Both are averaged over calls with time constant
//! [`TIME_CONSTANT`] before their ratio is taken, so that a cloth swinging in phase (all its
//! velocity at its turnaround at once) reads its frequency, not `omega tan(omega t)`.
//! The averages are part of the cloth's state (snapshots keep them).

use crate::math::Vec3;

/// Seconds over which the averages forget (an exponential average's time constant).
pub const TIME_CONSTANT: f64 = 1.0;

/// The averaged mean squares (`Default`: nothing seen yet).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MotionRate {
    /// Mass-weighted sum of squared accelerations over a call, m^2 s^-4 kg.
    pub accel2: f64,
    /// Mass-weighted sum of squared velocities (both ends of a call), m^2 s^-2 kg.
    pub vel2: f64,
}

impl MotionRate {
    /// Folds one call of `dt` seconds in: `v_start` and `v_end` the velocities at its ends,
    /// `masses` and `skip` (pinned) per particle.
    pub fn update(&mut self, masses: &[f64], skip: &[bool], v_start: &[Vec3], v_end: &[Vec3], dt: f64) {
        if dt.is_nan() || dt <= 0.0 {
            return;
        }
        let (mut a2, mut v2) = (0.0, 0.0);
        for i in 0..masses.len().min(v_start.len()).min(v_end.len()) {
            if skip.get(i).copied().unwrap_or(false) {
                continue;
            }
            let m = masses[i];
            a2 += m * (v_end[i] - v_start[i]).norm_squared();
            v2 += 0.5 * m * (v_start[i].norm_squared() + v_end[i].norm_squared());
        }
        a2 /= dt * dt;
        if !(a2.is_finite() && v2.is_finite()) {
            return;
        }
        let alpha = (dt / TIME_CONSTANT).min(1.0);
        self.accel2 += alpha * (a2 - self.accel2);
        self.vel2 += alpha * (v2 - self.vel2);
    }

    /// The motion's angular frequency, rad/s (0 before any motion).
    pub fn omega(&self) -> f64 {
        if self.vel2 > 0.0 && self.accel2 > 0.0 {
            (self.accel2 / self.vel2).sqrt()
        } else {
            0.0
        }
    }

    /// Whether the values are sound (finite, not negative): what a snapshot may hold.
    pub fn is_sound(&self) -> bool {
        self.accel2.is_finite() && self.vel2.is_finite() && self.accel2 >= 0.0 && self.vel2 >= 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sinusoid's frequency is read at every phase once the averages have seen a period,
    /// though the ratio of one call's squares swings from 0 to infinity over it.
    #[test]
    fn a_sinusoids_frequency_is_read_whatever_its_phase() {
        let omega = 2.0 * std::f64::consts::PI;
        let dt = 1.0 / 30.0;
        let v = |t: f64| Vec3::new(0.1 * (omega * t).cos(), 0.0, 0.0);
        let mut rate = MotionRate::default();
        assert_eq!(rate.omega(), 0.0);
        let mut worst: f64 = 0.0;
        for k in 0..300 {
            let t = f64::from(k) * dt;
            rate.update(
                &[1.0, 5.0],
                &[false, true],
                &[v(t), Vec3::zeros()],
                &[v(t + dt), Vec3::new(9.0, 0.0, 0.0)],
                dt,
            );
            if t > 5.0 {
                // The frame difference reads 2 sin(omega dt / 2) / dt, 0.5 % under omega.
                worst = worst.max((rate.omega() / omega - 1.0).abs());
            }
        }
        assert!(worst < 0.12, "{worst}");
    }

    #[test]
    fn a_still_cloth_has_no_frequency_and_bad_calls_are_ignored() {
        let mut rate = MotionRate::default();
        rate.update(&[1.0], &[false], &[Vec3::zeros()], &[Vec3::zeros()], 0.1);
        assert_eq!(rate.omega(), 0.0);
        rate.update(
            &[1.0],
            &[false],
            &[Vec3::zeros()],
            &[Vec3::new(1.0, 0.0, 0.0)],
            0.0,
        );
        rate.update(
            &[1.0],
            &[false],
            &[Vec3::zeros()],
            &[Vec3::new(f64::NAN, 0.0, 0.0)],
            0.1,
        );
        assert_eq!(rate, MotionRate::default());
        assert!(rate.is_sound());
    }
}
