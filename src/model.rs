//! Physical coefficients of the cloth and the water (paper, section 4.1).
//!
//! Units are SI throughout: metres, kilograms, seconds, newtons. Fractional
//! coefficients multiply a half-derivative of displacement, whose unit is
//! m s^{-1/2}, so `history_drag` and a fractional `spring_damping` are in N s^{1/2} / m.

use crate::error::{check_finite_vec, check_non_negative, check_positive, Error};
use crate::math::Vec3;
use crate::topology::SpringKind;

/// How a spring resists the rate of change of its length.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpringDamping {
    /// Purely elastic springs.
    None,
    /// Classic damped spring: `-k_d [(v_i - v_j) . l_hat] l_hat` (the paper's regular models).
    Velocity,
    /// Fractional viscoelastic element, Eq. 5: `-k_d [(D^{1/2}x_i - D^{1/2}x_j) . l_hat] l_hat`.
    Fractional,
    /// Rotation-invariant fractional element: `-k_d D^{1/2}(|l| - r) l_hat`, the half-derivative
    /// of the spring's elongation (zero for any rigid motion; `forces/strain.rs`). Not in the
    /// paper; `k_d` in the same unit as Eq. 5's, N s^{1/2}/m.
    FractionalStrain,
}

/// Every force coefficient. A coefficient of zero switches its term off and costs nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Model {
    /// Density of a wet cloth particle rho_c, kg/m^3 (> 0). Particle volume is `V_c = m / rho_c`.
    pub cloth_density: f64,
    /// Density of the water rho_w, kg/m^3 (>= 0; 0 means no buoyancy).
    pub water_density: f64,
    /// Gravitational acceleration, m/s^2.
    pub gravity: Vec3,
    /// Uniform velocity of the water, m/s; all drags act on the velocity relative to it.
    pub current: Vec3,
    /// Stretch spring constant k_s, N/m.
    pub stretch_stiffness: f64,
    /// Shear spring constant, N/m.
    pub shear_stiffness: f64,
    /// Bend spring constant, N/m, at the spacing [`Model::bend_reference_spacing`] (if set).
    pub bend_stiffness: f64,
    /// Spacing at which `bend_stiffness` holds, m (0: the paper's constant per spring at any
    /// spacing). The bending a bend spring gives grows with the spacing it spans: a curtain
    /// baked at 2 cm with the spring constant of 1 cm carries fewer, longer waves (measured,
    /// `docs/underwater.md`). With a reference, a cloth of spacing `h` ([`Topology::spacing`])
    /// takes `bend_stiffness (reference / h)^2` ([`Model::bend_scale`]), and looks the same at
    /// any resolution.
    ///
    /// [`Topology::spacing`]: crate::topology::Topology::spacing
    pub bend_reference_spacing: f64,
    /// Spring damping constant k_d: N s/m for [`SpringDamping::Velocity`], N s^{1/2}/m for fractional.
    pub spring_damping: f64,
    /// Which damping the springs carry.
    pub spring_damping_mode: SpringDamping,
    /// Multiplies `spring_damping` for each family: stretch, shear, bend (default 1, 1, 1; e.g.
    /// 0, 0, 1 damps the bend springs alone).
    pub spring_damping_scale: [f64; 3],
    /// Viscous drag k_vd, N s/m (Eq. 3).
    pub viscous_drag: f64,
    /// History (Basset) drag k_hd, N s^{1/2}/m (Eq. 4).
    pub history_drag: f64,
    /// Linear normal drag k_nd, N s/m: `-k_nd (v . n_hat) n_hat` (regular models of Fig. 7).
    pub normal_drag: f64,
    /// Penalty stiffness of the repulsive collision force, N/m.
    pub collision_stiffness: f64,
    /// Damping of the approach velocity inside the collision margin, N s/m.
    pub collision_damping: f64,
    /// Distance from a collider surface below which the repulsion acts, m.
    pub collision_margin: f64,
    /// Self-collision: the distance the cloth keeps from itself, m (0 = off, and costs
    /// nothing; off in [`Model::underwater`] too, docs/design-departures.md). Pairs nearer than 2.2 times this at rest (neighbours) are not tested
    /// (`collide/self_collision.rs`). A cloth refuses one past about 1.5 of its mean edge
    /// lengths (`collide::self_collision::PAIRS_PER_VERTEX`). No free vertex moves more than
    /// half of it in a substep (unless the proof of `collide/unfolded.rs` shows no pair within
    /// reach at any instant of it: then the substep is taken whole): a substep in
    /// which one would is taken in 2, 4, ... up to 32
    /// equal pieces instead (`cloth/split.rs`, an extrapolated integrator's half steps alike;
    /// [`crate::Cloth::step_stats`] counts them; at a
    /// host's fixed step no longer than the automatic step's stable substep, and up to 32
    /// times that many), and past that the fastest vertices are slowed (docs/collisions.md).
    pub self_collision_thickness: f64,
    /// Self-collision thickness in the cloth's spacings (dimensionless, >= 0; 0 adds nothing):
    /// adds `self_collision_relative * spacing` m to [`Model::self_collision_thickness`] when
    /// the cloth is built, `spacing` the cloth's ([`crate::Topology::spacing`]: a grid's own,
    /// for a mesh the side of a square of two of its triangles' mean area).
    /// [`crate::Cloth::model`] holds the sum and 0 here. One value then suits a cloth at any
    /// resolution, where a thickness in metres is too thin on a coarse mesh (its vertices slip
    /// through each other's gaps) and refused on a fine one; 0.4 is what the tests and the
    /// cost table use (`docs/collisions.md`).
    pub self_collision_relative: f64,
    /// Coulomb friction coefficient of the cloth against itself (>= 0).
    pub self_collision_friction: f64,
    /// The water's terms given per unit area of cloth (zero switches each off).
    pub water: Water,
}

/// Terms of the water given per unit area of cloth: each multiplies a particle's lumped area
/// ([`crate::Topology::areas`]), so one description gives the same motion at any resolution.
/// Zero switches a term off (and it costs nothing). See `docs/underwater.md`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Water {
    /// Added mass for motion normal to the cloth, kg/m^2: a particle's mass matrix becomes
    /// `m I + m_a n n^T`, `m_a = added_mass * area`. For a sheet rippled with wavelength
    /// lambda, about `rho_w lambda / pi` (both sides): tens of kg/m^2.
    pub added_mass: f64,
    /// Added mass for normal motion given as a coefficient C_a (dimensionless) of the water
    /// density times the cloth's width W ([`crate::Topology::width`]): adds
    /// `C_a * water_density * W` kg/m^2 to [`Water::added_mass`] when the cloth is built
    /// ([`crate::Cloth::model`] holds the sum). Potential flow gives `C_a = pi/4` for a rigid
    /// plate translating face first (`rho_w pi W / 4` per unit area: the whole-sheet value)
    /// and `C_a = lambda / (pi W)` for ripples of wavelength lambda (`rho_w lambda / pi`, both
    /// sides). 0 (the default) adds nothing.
    pub added_mass_coefficient: f64,
    /// Water carried along in every direction, kg/m^2: a particle's mass matrix gains
    /// `m_e I`, `m_e = entrained_mass * area` (inertia only; the weight is unchanged). The
    /// coarse, whole-sheet part of the added mass: a towel moving as a whole drags water along
    /// in-plane too (its boundary layer and wake), and the mass ratio between normal and
    /// tangential motion stays moderate, which keeps a swung cloth from crumpling.
    pub entrained_mass: f64,
    /// Form-drag coefficient C_d (dimensionless) of the velocity normal to the cloth relative
    /// to the water: `-1/2 rho_w C_d area |v_n| v_n n`.
    pub form_drag: f64,
    /// Length over which the form drag smooths the normal velocity before it acts, m (0: the
    /// drag of each particle's own normal velocity). Ripples much shorter than this carry the
    /// water beside them along and shed little; the sheet's motion at large meets the full
    /// drag (`forces/wide_drag.rs`). The rms radius of the smoothing, the same on any mesh.
    pub form_drag_scale: f64,
    /// Skin (tangential) drag on the velocity along the cloth relative to the water, N s/m^3:
    /// `-skin_drag area (v_rel - (v_rel . n) n)`. The friction of a steady flow along the
    /// cloth (an old, thick boundary layer).
    pub skin_drag: f64,
    /// Skin drag on the unsteady part of the tangential relative velocity, N s/m^3 (0 = off):
    /// adds `-skin_drag_unsteady area P_t (v_rel - mean)`, `mean` the running mean of `v_rel`
    /// over [`Water::skin_drag_memory`] and `P_t` the projection on the cloth's plane. Motion
    /// along the cloth that reverses meets a young, thin boundary layer (a Stokes layer:
    /// `sqrt(2 rho_w mu omega)` on both faces, in phase) where a steady flow meets the old one
    /// [`Water::skin_drag`] states; the sum acts on motion faster than the memory, `skin_drag`
    /// alone on a steady current. Keeps a running mean (24 bytes a particle, in snapshots).
    pub skin_drag_unsteady: f64,
    /// Time constant of the running mean [`Water::skin_drag_unsteady`] acts against, s (> 0
    /// when it is on): about how long a boundary layer takes to grow from a sudden start to a
    /// steady flow's (a Rayleigh layer's friction falls to the laminar plate's after
    /// `0.72 L / U`: 1 s for 0.3 m/s along 0.4 m).
    pub skin_drag_memory: f64,
    /// Viscous drag per unit area, N s/m^3 (adds to [`Model::viscous_drag`] times the area).
    pub viscous_drag: f64,
    /// History drag per unit area, N s^{1/2}/m^3 (adds to [`Model::history_drag`] times the area).
    pub history_drag: f64,
    /// Normal drag per unit area, N s/m^3 (adds to [`Model::normal_drag`] times the area).
    pub normal_drag: f64,
    /// Added mass of the cloth's large-scale normal motion, kg/m^2 (0 = off): motion smoother
    /// than [`Water::coarse_length`] carries this much more water per unit area than
    /// [`Water::added_mass`] alone, ripples shorter than it only the local added mass. A
    /// scale-aware inertia (`forces/coarse_water.rs`): a rigid plate of width W carries
    /// about `rho_w pi W / 4` in all (potential flow), a ripple of wavelength lambda about
    /// `rho_w lambda / pi`. Costs one patches-by-patches solve a step and the tile-fused step.
    pub coarse_added_mass: f64,
    /// The coarse level's patch spacing over the rest shape, m (> 0 when
    /// [`Water::coarse_added_mass`] is on): bilinear patches this far apart in the rest shape's
    /// plane each average the normal velocity of their vertices; at most
    /// 256 of them (a shorter length is refused).
    pub coarse_length: f64,
}

impl Water {
    /// Whether the skin drag keeps a running mean of the relative velocity
    /// ([`Water::skin_drag_unsteady`]).
    pub fn unsteady_skin(&self) -> bool {
        self.skin_drag_unsteady != 0.0
    }

    /// Whether any water rides on the cloth's normal motion (the turning forces' pass).
    pub fn normal_water(&self) -> bool {
        self.added_mass != 0.0 || self.coarse_added_mass != 0.0
    }

    /// The normal added mass per unit area of a cloth of width `width` (m) in water of density
    /// `water_density` (kg/m^3): `added_mass + added_mass_coefficient * water_density * width`.
    pub fn added_mass_for(&self, water_density: f64, width: f64) -> f64 {
        if self.added_mass_coefficient == 0.0 {
            return self.added_mass;
        }
        self.added_mass + self.added_mass_coefficient * water_density * width
    }
}

impl Model {
    /// Damping constant of a spring family: `spring_damping` times the family's scale.
    pub fn spring_damping_of(&self, kind: SpringKind) -> f64 {
        self.spring_damping * self.spring_damping_scale[kind as usize]
    }

    /// Spring constant of a spring family on a cloth of spacing `spacing` (m;
    /// [`crate::topology::Topology::spacing`]), N/m: the bend springs' scaled by
    /// `(bend_reference_spacing / spacing)^2` when a reference is set.
    pub fn stiffness(&self, kind: SpringKind, spacing: f64) -> f64 {
        match kind {
            SpringKind::Stretch => self.stretch_stiffness,
            SpringKind::Shear => self.shear_stiffness,
            SpringKind::Bend => self.bend_stiffness * self.bend_scale(spacing),
        }
    }

    /// What multiplies `bend_stiffness` on a cloth of spacing `spacing`: 1 without a reference,
    /// for a spacing that is not positive, or one equal to the reference in single precision
    /// (the precision of `FcClothDesc.spacing`: a grid of 0.01 m through the ABI or from Rust
    /// is the same cloth), else `(bend_reference_spacing / spacing)^2`.
    pub fn bend_scale(&self, spacing: f64) -> f64 {
        let r = self.bend_reference_spacing;
        if r > 0.0 && spacing > 0.0 && r as f32 != spacing as f32 {
            (r / spacing) * (r / spacing)
        } else {
            1.0
        }
    }

    /// Whether the cloth keeps apart from itself (a self-collision thickness in metres; a
    /// cloth's model has its thickness in spacings resolved into it).
    pub fn self_collision_on(&self) -> bool {
        self.self_collision_thickness > 0.0
    }

    /// Checks every coefficient; the cloth is never built from a model that fails this.
    pub fn validate(&self) -> Result<(), Error> {
        check_positive("cloth_density", self.cloth_density)?;
        check_non_negative("water_density", self.water_density)?;
        check_finite_vec("gravity", &self.gravity)?;
        check_finite_vec("current", &self.current)?;
        check_non_negative("stretch_stiffness", self.stretch_stiffness)?;
        check_non_negative("shear_stiffness", self.shear_stiffness)?;
        check_non_negative("bend_stiffness", self.bend_stiffness)?;
        check_non_negative("bend_reference_spacing", self.bend_reference_spacing)?;
        check_non_negative("spring_damping", self.spring_damping)?;
        for (name, v) in [
            "stretch_damping_scale",
            "shear_damping_scale",
            "bend_damping_scale",
        ]
        .into_iter()
        .zip(self.spring_damping_scale)
        {
            check_non_negative(name, v)?;
        }
        check_non_negative("viscous_drag", self.viscous_drag)?;
        check_non_negative("history_drag", self.history_drag)?;
        check_non_negative("normal_drag", self.normal_drag)?;
        check_non_negative("collision_stiffness", self.collision_stiffness)?;
        check_non_negative("collision_damping", self.collision_damping)?;
        check_non_negative("collision_margin", self.collision_margin)?;
        check_non_negative("self_collision_thickness", self.self_collision_thickness)?;
        check_non_negative("self_collision_relative", self.self_collision_relative)?;
        check_non_negative("self_collision_friction", self.self_collision_friction)?;
        let w = &self.water;
        check_non_negative("added_mass", w.added_mass)?;
        check_non_negative("added_mass_coefficient", w.added_mass_coefficient)?;
        check_non_negative("entrained_mass", w.entrained_mass)?;
        check_non_negative("form_drag", w.form_drag)?;
        check_non_negative("form_drag_scale", w.form_drag_scale)?;
        check_non_negative("skin_drag", w.skin_drag)?;
        check_non_negative("skin_drag_unsteady", w.skin_drag_unsteady)?;
        check_non_negative("skin_drag_memory", w.skin_drag_memory)?;
        if w.skin_drag_unsteady > 0.0 {
            check_positive(
                "skin_drag_memory (with skin_drag_unsteady on)",
                w.skin_drag_memory,
            )?;
        }
        check_non_negative("viscous_drag_per_area", w.viscous_drag)?;
        check_non_negative("history_drag_per_area", w.history_drag)?;
        check_non_negative("normal_drag_per_area", w.normal_drag)?;
        check_non_negative("coarse_added_mass", w.coarse_added_mass)?;
        check_non_negative("coarse_length", w.coarse_length)?;
        if w.coarse_added_mass > 0.0 {
            check_positive("coarse_length (with coarse_added_mass on)", w.coarse_length)?;
        }
        Ok(())
    }

    /// The fractional cloth of the paper (Eq. 2-5): fractional springs, viscous and history drag.
    ///
    /// The paper gives no numbers; these were tuned so a 61 x 41 towel of 2 cm spacing
    /// sinks slowly and forms travelling bumps when swung (see `tools/src/scenes.rs`).
    pub fn fractional() -> Self {
        Self {
            cloth_density: 1100.0,
            water_density: 1000.0,
            gravity: Vec3::new(0.0, -9.81, 0.0),
            current: Vec3::zeros(),
            stretch_stiffness: 10.0,
            shear_stiffness: 2.0,
            bend_stiffness: 0.5,
            bend_reference_spacing: 0.0,
            spring_damping: 0.35,
            spring_damping_mode: SpringDamping::Fractional,
            spring_damping_scale: [1.0; 3],
            viscous_drag: 1.0e-3,
            history_drag: 2.0e-3,
            normal_drag: 0.0,
            collision_stiffness: 50.0,
            collision_damping: 0.05,
            collision_margin: 0.01,
            self_collision_thickness: 0.0,
            self_collision_relative: 0.0,
            self_collision_friction: 0.0,
            water: Water::default(),
        }
    }

    /// Regular cloth with the same coefficients: classic damped springs (velocity damping,
    /// coefficient scaled to the same local strength) and no history drag. `drag` picks
    /// which of the paper's three regular models of Fig. 7.
    pub fn regular(drag: RegularDrag) -> Self {
        let f = Self::fractional();
        let (viscous, normal) = match drag {
            RegularDrag::ViscousAndNormal => (f.viscous_drag, REGULAR_NORMAL_DRAG),
            RegularDrag::Viscous => (f.viscous_drag, 0.0),
            RegularDrag::Normal => (0.0, REGULAR_NORMAL_DRAG),
        };
        Self {
            spring_damping: REGULAR_SPRING_DAMPING,
            spring_damping_mode: SpringDamping::Velocity,
            viscous_drag: viscous,
            history_drag: 0.0,
            normal_drag: normal,
            ..f
        }
    }
}

impl Model {
    /// A wet towel in water (`FC_PRESET_UNDERWATER`): the paper's springs, lightly
    /// velocity-damped ([`UNDERWATER_SPRING_DAMPING`]), and the water's physics per unit area, each term by direction
    /// (`docs/underwater.md` derives the numbers and measures the look):
    /// - normal added mass [`UNDERWATER_ADDED_MASS`] (the water a face carries when it moves
    ///   face first; none along the cloth), with the turning forces that keep its energy
    ///   (`forces/inertia.rs`);
    /// - form drag on the normal velocity, C_d = [`UNDERWATER_FORM_DRAG`], smoothed over
    ///   [`UNDERWATER_FORM_DRAG_SCALE`] (short ripples shed little; the sheet at large meets
    ///   the full drag);
    /// - skin drag on the tangential velocity, [`UNDERWATER_SKIN_DRAG`] (laminar skin friction
    ///   on both faces, linearised at 0.3 m/s on a 0.4 m cloth): a current along the cloth
    ///   drags it, and motion in its plane dies out;
    /// - more skin drag on the tangential motion that changes faster than a second,
    ///   [`UNDERWATER_SKIN_DRAG_UNSTEADY`] over [`UNDERWATER_SKIN_DRAG_MEMORY`] (a young
    ///   boundary layer, a Stokes layer's friction at 0.5 Hz in all).
    ///
    /// Swung 4 cm at 0.25 to 2 Hz the towel hangs (at least 0.9 of its length: 0.905 at 2 Hz)
    /// and shows bumps travelling down, more and shorter the brisker the swing (about 3.6
    /// half-waves at 0.5 Hz, 0.16 m/s; 6 at 2 Hz), the same within 7 % from 2 cm to 0.5 cm
    /// spacing (its bend springs' constant is stated at 1 cm, [`UNDERWATER_BEND_SPACING`], and
    /// scaled to the cloth's spacing).
    pub fn underwater() -> Self {
        Self {
            spring_damping: UNDERWATER_SPRING_DAMPING,
            spring_damping_mode: SpringDamping::Velocity,
            bend_reference_spacing: UNDERWATER_BEND_SPACING,
            viscous_drag: 0.0,
            history_drag: 0.0,
            normal_drag: 0.0,
            water: Water {
                added_mass: UNDERWATER_ADDED_MASS,
                form_drag: UNDERWATER_FORM_DRAG,
                form_drag_scale: UNDERWATER_FORM_DRAG_SCALE,
                skin_drag: UNDERWATER_SKIN_DRAG,
                skin_drag_unsteady: UNDERWATER_SKIN_DRAG_UNSTEADY,
                skin_drag_memory: UNDERWATER_SKIN_DRAG_MEMORY,
                ..Water::default()
            },
            ..Self::fractional()
        }
    }
}

/// The spacing the underwater preset's bend springs (0.5 N/m) were tuned at, m: the 1 cm grid
/// its look was measured on. Other spacings scale the bend springs
/// ([`Model::bend_reference_spacing`]).
pub const UNDERWATER_BEND_SPACING: f64 = 0.01;

/// Normal added mass of the underwater preset, kg/m^2. Potential flow gives
/// `rho_w lambda / pi` for a sheet rippled at wavelength lambda (about 80 kg/m^2 for the
/// 0.25 m bumps the preset shows at 0.5 Hz) and up to `rho_w pi W / 4` for a whole sheet of
/// width W moving rigidly. The preset carries far less: more gives more and deeper bumps and
/// a shorter hang, and 8 keeps a towel swung 4 cm at 2 Hz hanging at 0.9 of its length
/// with 6 half-waves (10 with the drag smoothed over 1 cm and the steady skin drag alone hangs
/// 0.352 m; `docs/underwater.md`).
pub const UNDERWATER_ADDED_MASS: f64 = 8.0;
/// Form-drag coefficient of the underwater preset (a flat plate face on: 1-2).
pub const UNDERWATER_FORM_DRAG: f64 = 1.0;
/// Length over which the underwater preset's form drag smooths the normal velocity, m
/// ([`Water::form_drag_scale`]). Fitted, of the order of the ripples' amplitude: ripples a
/// few centimetres long shed little, so bumps keep growing in number with the drive's
/// frequency (without it the visible half-waves fell from 4.6 at 1 Hz to 3.8 at 2 Hz: a
/// quadratic drag takes the same share of a wave's energy each cycle at any frequency).
/// 1.2 cm until 0.9.26; 1 cm with the unsteady skin drag hangs the 2 Hz swing at 0.9 of its
/// length with the half-waves still growing (`docs/underwater.md`).
pub const UNDERWATER_FORM_DRAG_SCALE: f64 = 0.010;
/// Skin drag of the underwater preset, N s/m^3: laminar skin friction on both faces,
/// `2 * 0.664 rho_w sqrt(nu / L) U^1.5` (`C_f = 1.328 / sqrt(Re)` per face, water
/// `nu = 1e-6 m^2/s`), is 0.345 N/m^2 at U = 0.3 m/s over L = 0.4 m; over U, 1.15 N s/m^3.
pub const UNDERWATER_SKIN_DRAG: f64 = 1.15;
/// Skin drag of the underwater preset on the unsteady part of the tangential motion, N s/m^3
/// ([`Water::skin_drag_unsteady`]): a plate oscillating in its plane at `omega` meets the Stokes
/// layer's in-phase friction `sqrt(2 rho_w mu omega)` on its two faces, 2.51 N s/m^3 at the
/// 0.5 Hz the preset's look is stated at (1.77 at 0.25 Hz, 5.0 at 2 Hz); this is what it adds to
/// the steady [`UNDERWATER_SKIN_DRAG`] to make that, 2.51 - 1.15.
pub const UNDERWATER_SKIN_DRAG_UNSTEADY: f64 = 1.36;
/// The running mean's time constant of the underwater preset's unsteady skin drag, s: a
/// Rayleigh layer's friction `sqrt(rho_w mu / (pi t))` per face falls to the laminar plate's
/// after `0.72 L / U`, 0.96 s at 0.3 m/s along 0.4 m.
pub const UNDERWATER_SKIN_DRAG_MEMORY: f64 = 1.0;

/// Velocity spring damping of the underwater preset, N s/m: light. It only keeps grid-scale
/// motion from ringing; the water's terms make the look (none gives the same bumps at 0.5 Hz,
/// and a chaotic 2 Hz swing). The 0.4 preset's 0.015 N s/m, acting on the cloth's own mass alone
/// now that no water is carried in its plane, limited symplectic Euler to 0.8 ms at 1 cm
/// spacing; 0.003 allows 2 ms and gives the same look (`docs/underwater.md`).
pub const UNDERWATER_SPRING_DAMPING: f64 = 3.0e-3;

/// Velocity spring damping of the regular presets, N s/m.
pub const REGULAR_SPRING_DAMPING: f64 = 1.5e-2;
/// Normal drag of the regular presets, N s/m.
pub const REGULAR_NORMAL_DRAG: f64 = 4.0e-3;

/// The three regular (non-fractional) comparison models of the paper's Fig. 7.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RegularDrag {
    /// Viscous drag and normal drag (first column).
    ViscousAndNormal,
    /// Viscous drag only (second column).
    Viscous,
    /// Normal drag only (third column; the paper's best regular model).
    Normal,
}

impl Default for Model {
    fn default() -> Self {
        Self::fractional()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bend springs scale as the square of the reference over the spacing; the paper's
    /// models (no reference) and a spacing equal to the reference in single precision do not.
    #[test]
    fn bend_springs_scale_with_the_square_of_the_spacing() {
        let m = Model::underwater();
        assert_eq!(
            m.stiffness(SpringKind::Bend, f64::from(0.01f32)),
            m.bend_stiffness
        );
        assert_eq!(m.stiffness(SpringKind::Bend, 0.01), m.bend_stiffness);
        assert!((m.stiffness(SpringKind::Bend, 0.02) - 0.25 * m.bend_stiffness).abs() < 1e-15);
        assert!((m.stiffness(SpringKind::Bend, 0.005) - 4.0 * m.bend_stiffness).abs() < 1e-14);
        assert_eq!(m.stiffness(SpringKind::Stretch, 0.02), m.stretch_stiffness);
        assert_eq!(m.stiffness(SpringKind::Shear, 0.02), m.shear_stiffness);
        assert_eq!(m.stiffness(SpringKind::Bend, 0.0), m.bend_stiffness);
        let paper = Model::fractional();
        assert_eq!(paper.stiffness(SpringKind::Bend, 0.02), paper.bend_stiffness);
        let bad = Model {
            bend_reference_spacing: -1.0,
            ..Model::underwater()
        };
        assert!(bad.validate().is_err());
    }
}
