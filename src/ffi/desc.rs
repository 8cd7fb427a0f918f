//! `FcClothDesc`: everything a cloth is made of, filled by `fc_cloth_desc_default`.
//!
//! Following Box2D v3, hosts start from the defaults and change what they need, so
//! fields added later never break old callers. Configuration crosses as `double`;
//! per-frame geometry (positions, targets, collider centres) crosses as `float`.
//! Enumerated fields are plain `uint32_t` holding an `FcHistoryScheme`,
//! `FcIntegrator` or `FcSpringDamping` value and are checked on use.

use crate::cloth::ClothConfig;
use crate::history::Scheme;
use crate::integrate::{Integrator, SolverSettings};
use crate::math::Vec3;
use crate::model::{Model, RegularDrag, SpringDamping};
use crate::topology::GridSpec;

use super::desc_size::{read_desc, write_desc};

/// `sizeof(FcClothDesc)` in this library.
pub const DESC_SIZE: usize = std::mem::size_of::<FcClothDesc>();
use super::status::{guard, FcStatus, FfiError};

/// Values of `FcClothDesc::history_scheme`: how D^{1/2}x is evaluated.
#[allow(non_camel_case_types)]
#[repr(C)]
pub enum FcHistoryScheme {
    /// No fractional terms (they evaluate to zero); no history is kept.
    FC_HISTORY_OFF = 0,
    /// The paper's Eq. 6 truncated to the last `history_u` states (order 1/2; a damper, not a memory).
    FC_HISTORY_TRUNCATED = 1,
    /// Exact convolution over the whole history, second order; cost and memory grow with the step count. The reference.
    FC_HISTORY_FULL = 2,
    /// Sum of exponentials: full memory to `history_tolerance` on [`history_min_dt`, `history_horizon`] at constant cost. The default.
    FC_HISTORY_SOE = 3,
}

/// Values of `FcClothDesc::integrator`.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy)]
pub enum FcIntegrator {
    /// The paper's Eq. 7: `x += h v; v += h a`. Conditionally stable; see docs/stability.md.
    FC_INTEGRATOR_EXPLICIT_EULER = 0,
    /// `v += h a; x += h v` (semi-implicit). Same cost, stable to about 2/omega without damping.
    FC_INTEGRATOR_SYMPLECTIC_EULER = 1,
    /// Backward Euler (Baraff & Witkin), CG solve. Stable at frame-rate steps with stiff cloth.
    /// First order: it damps fast motion. At the automatic step (`max_substep` < 0) its substep
    /// is also kept short enough for the cloth's motion that this damping does not change the
    /// shot (a brisk 1-2 Hz swing then takes up to 1.4 times symplectic Euler's substeps, each
    /// costing several times more); at a fixed step of a frame a 1-2 Hz swing's free edge moves
    /// 15-70 % less than with symplectic Euler (docs/underwater.md).
    FC_INTEGRATOR_IMPLICIT_EULER = 2,
    /// Second order, explicit: symplectic Euler over the step and over two half steps,
    /// extrapolated (`2 x_half - x_whole`). Three force evaluations per step; about symplectic
    /// Euler's stability. For small steps where accuracy matters (docs/accuracy.md).
    FC_INTEGRATOR_EXTRAPOLATED_SYMPLECTIC = 3,
    /// Second order, stable at frame-rate steps: implicit Euler extrapolated in the same way.
    /// Three linear solves per step.
    FC_INTEGRATOR_EXTRAPOLATED_IMPLICIT = 4,
    /// Symplectic Euler on every force but the stretch and shear springs, which are compliant
    /// constraints projected once a substep (XPBD; every spring's velocity damping too). They
    /// no longer bound the step: the underwater towel's 60 Hz frame takes 3 substeps where
    /// symplectic Euler takes 14. One pass holds the springs softer (a chain about
    /// `1 + (omega h)^2` times as stretched): a tall cloth hangs longer (a 1.5 m curtain by
    /// 20 %) and a brisk swing shows fewer small ripples (docs/realtime.md).
    FC_INTEGRATOR_XPBD = 5,
}

/// Values of `FcClothDesc::spring_damping_mode`.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy)]
pub enum FcSpringDamping {
    /// Purely elastic springs.
    FC_SPRING_DAMPING_NONE = 0,
    /// Classic damped springs, `-k_d [(v_i - v_j) . l_hat] l_hat` (regular cloth).
    FC_SPRING_DAMPING_VELOCITY = 1,
    /// Fractional viscoelastic springs, Eq. 5: `-k_d [(D^{1/2}x_i - D^{1/2}x_j) . l_hat] l_hat`.
    FC_SPRING_DAMPING_FRACTIONAL = 2,
    /// Rotation-invariant fractional springs (not in the paper): `-k_d D^{1/2}(|l| - r) l_hat`,
    /// the half-derivative of each spring's elongation, zero for any rigid motion.
    FC_SPRING_DAMPING_FRACTIONAL_STRAIN = 3,
}

/// Values for `fc_cloth_desc_preset`.
#[allow(non_camel_case_types)]
#[repr(C)]
pub enum FcPreset {
    /// The paper's fractional cloth exactly (Eq. 2-7, u = 3, explicit Euler).
    FC_PRESET_FRACTIONAL_PAPER = 0,
    /// Regular cloth of Fig. 7, first column: damped springs, viscous and normal drag.
    FC_PRESET_REGULAR_VISCOUS_NORMAL = 1,
    /// Regular cloth of Fig. 7, second column: damped springs, viscous drag.
    FC_PRESET_REGULAR_VISCOUS = 2,
    /// Regular cloth of Fig. 7, third column: damped springs, normal drag.
    FC_PRESET_REGULAR_NORMAL = 3,
    /// A wet towel in water: the paper's springs lightly velocity-damped, and per unit area the
    /// water's normal added mass (8 kg/m^2; none along the cloth), form drag (C_d = 1) on the
    /// normal velocity smoothed over 0.01 m, and skin drag (1.15 N s/m^3, plus 1.36 on the
    /// unsteady part over a 1 s mean: 2.51 on motion along the cloth at 0.5 Hz); the bend springs'
    /// constant stated at 0.01 m spacing (`bend_reference_spacing`); symplectic Euler with the automatic step (`max_substep = FC_MAX_SUBSTEP_AUTO`: call
    /// `fc_cloth_step` once per frame). The look, measured: docs/underwater.md.
    FC_PRESET_UNDERWATER = 4,
}

/// Description of a cloth. Units are SI (m, kg, s, N). Obtain with
/// `fc_cloth_desc_default()` (or `fc_cloth_desc_preset`) and change fields as needed.
///
/// **Evolution rule.** Fields are only ever added at the end, and `struct_size` comes first.
/// `fc_cloth_desc_default`, `fc_cloth_desc_preset` and `fc_cloth_get_desc` are inline in this
/// header and set `struct_size = sizeof(FcClothDesc)` as this header knows it. The library reads
/// (and writes) only the fields that fit in `struct_size` and gives any later field its default,
/// so a host built against this header keeps working with later libraries. A `struct_size` of 0,
/// not a multiple of 8, or larger than the library knows (a host built against a newer header
/// than the library) is refused with `FC_ERROR_INVALID_ARGUMENT` and a message.
///
/// Drag coefficients without `_per_area` act per particle; the defaults suit a spacing of 1 cm.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FcClothDesc {
    /// Size of this struct in the host's header, bytes: `sizeof(FcClothDesc)`. Set by
    /// `fc_cloth_desc_default` and `fc_cloth_desc_preset`; keep it when copying.
    pub struct_size: u32,
    /// Grid columns (>= 2). Vertex (column i, row j) has index j * width + i; row 0 is the top edge.
    pub width: u32,
    /// Grid rows (>= 2).
    pub height: u32,
    /// Distance between neighbouring particles, m (> 0). Default 0.01.
    pub spacing: f32,
    /// Mass of the whole cloth, kg. If <= 0, `areal_density` is used instead. Default 0.
    pub total_mass: f64,
    /// Mass per unit area, kg/m^2, used when `total_mass` <= 0. Default 1 (a wet towel).
    pub areal_density: f64,
    /// Density of a wet cloth particle rho_c, kg/m^3 (> 0). Default 1100.
    pub cloth_density: f64,
    /// Density of the water rho_w, kg/m^3 (>= 0). Default 1000.
    pub water_density: f64,
    /// Gravity, m/s^2. Default (0, -9.81, 0): y is up.
    pub gravity: [f64; 3],
    /// Uniform water current, m/s. Default 0.
    pub current: [f64; 3],
    /// Stretch spring constant, N/m. Default 10.
    pub stretch_stiffness: f64,
    /// Shear spring constant, N/m. Default 2.
    pub shear_stiffness: f64,
    /// Bend spring constant, N/m. Default 0.5.
    pub bend_stiffness: f64,
    /// Spring damping k_d: N s^(1/2)/m when fractional (default 0.35), N s/m when velocity damping.
    pub spring_damping: f64,
    /// An `FcSpringDamping` value. Default `FC_SPRING_DAMPING_FRACTIONAL`.
    pub spring_damping_mode: u32,
    /// Viscous drag k_vd (Eq. 3), N s/m per particle. Default 1e-3.
    pub viscous_drag: f64,
    /// History (Basset) drag k_hd (Eq. 4), N s^(1/2)/m per particle. Default 2e-3.
    pub history_drag: f64,
    /// Linear normal drag k_nd, N s/m per particle. Default 0.
    pub normal_drag: f64,
    /// An `FcHistoryScheme` value. Default `FC_HISTORY_SOE`.
    pub history_scheme: u32,
    /// Past states kept by `FC_HISTORY_TRUNCATED` (>= 1). Default 3, as in the paper.
    pub history_u: u32,
    /// Relative error of the SOE kernel, in [1e-12, 0.1]. Default 1e-3.
    pub history_tolerance: f64,
    /// Longest simulated time (s) over which the SOE memory is accurate. Default 3600.
    pub history_horizon: f64,
    /// Smallest step (s) the SOE kernel is built for. Default 1e-4.
    pub history_min_dt: f64,
    /// An `FcIntegrator` value. Default `FC_INTEGRATOR_EXPLICIT_EULER`.
    pub integrator: u32,
    /// Longest substep (s) `fc_cloth_step` takes: a call with a larger dt is split into
    /// `ceil(dt / max_substep)` equal substeps. 0 = never split; `FC_MAX_SUBSTEP_AUTO` (any
    /// negative value) = as few substeps as the cloth needs, chosen by the library each call
    /// (`fc_cloth_get_step_stats` says how many it took). Default 0; `FC_PRESET_UNDERWATER`
    /// uses `FC_MAX_SUBSTEP_AUTO`.
    pub max_substep: f64,
    /// Relative residual at which the implicit solver's CG stops (> 0). Default 1e-6.
    pub solver_tolerance: f64,
    /// Iteration cap of the implicit solver's CG (>= 1). Default 500.
    pub solver_max_iterations: u32,
    /// Collision penalty stiffness, N/m. Default 50.
    pub collision_stiffness: f64,
    /// Collision approach damping, N s/m. Default 0.05.
    pub collision_damping: f64,
    /// Collision margin (distance from a collider surface where repulsion starts), m. Default 0.01.
    pub collision_margin: f64,
    /// Speed above which a step is declared unstable, m/s (> 0). Default 100.
    pub max_speed: f64,
    /// Added mass for motion normal to the cloth, kg/m^2 per unit area (0 = off). About
    /// `water_density * wavelength / pi` for ripples of that wavelength: 30-80 for a towel.
    /// Default 0 (`FC_PRESET_UNDERWATER`: see docs/underwater.md).
    pub added_mass: f64,
    /// Form-drag coefficient C_d of the velocity normal to the cloth (dimensionless, 0 = off):
    /// `-1/2 water_density C_d area |v_n| v_n n`. Default 0.
    pub form_drag: f64,
    /// Water carried along in every direction, kg/m^2 per unit area (0 = off): inertia only,
    /// the weight is unchanged. Default 0.
    pub entrained_mass: f64,
    /// Skin drag on the tangential velocity, N s/m^3 per unit area (0 = off). Default 0.
    pub skin_drag: f64,
    /// Viscous drag per unit area, N s/m^3, added to `viscous_drag` times a particle's area. Default 0.
    pub viscous_drag_per_area: f64,
    /// History drag per unit area, N s^(1/2)/m^3, added to `history_drag` times the area. Default 0.
    pub history_drag_per_area: f64,
    /// Normal drag per unit area, N s/m^3, added to `normal_drag` times the area. Default 0.
    pub normal_drag_per_area: f64,
    /// Multiplies `spring_damping` for the stretch springs (>= 0). Default 1.
    pub stretch_damping_scale: f64,
    /// Multiplies `spring_damping` for the shear springs (>= 0). Default 1.
    pub shear_damping_scale: f64,
    /// Multiplies `spring_damping` for the bend springs (>= 0). Default 1; e.g. 0, 0, 1 damps
    /// the bend springs alone.
    pub bend_damping_scale: f64,
    /// Added mass for normal motion as a coefficient C_a (dimensionless, >= 0): adds
    /// `C_a * water_density * W` kg/m^2 to `added_mass`, W the cloth's width (the smaller extent
    /// of its rest shape in its own plane). pi/4 is a rigid plate's added mass for face-first
    /// motion (potential flow); `lambda / (pi W)` that of ripples of wavelength lambda.
    /// Default 0.
    pub added_mass_coefficient: f64,
    /// Self-collision: the distance the cloth keeps from itself, m (0 = off, the default, and
    /// off in `FC_PRESET_UNDERWATER` too: turn it on for a scene that folds, a drop, a drape, a
    /// brisk swing; a cloth that never comes near itself still pays about 1.1-1.2x the step).
    /// Points nearer than 2.2 times this at rest (neighbours) are not tested: a few millimetres
    /// for a cloth of 1-2 cm spacing.
    /// No vertex moves more than half of it in one substep: a substep in which one would is
    /// taken in 2, 4, ... up to 32 equal pieces instead (`fc_cloth_get_step_stats` counts
    /// them; an extrapolated integrator's half steps alike), so a fixed step keeps its motion;
    /// past 32 the fastest vertices are slowed to it. A substep the library proves brings no
    /// part of the cloth within this distance of another at any instant (an unfolded cloth)
    /// is taken whole however far it moves: implicit Euler at one 1/30 s substep a frame on
    /// the 4 cm, 0.5 Hz swing at 4 mm keeps 1.0 substeps a call and the shot without
    /// self-collision (2.6 before 0.9.30). At a fixed step a split substep's pieces are also
    /// no longer than the automatic step's stable substep (and the limit splits up to 32 times
    /// further), so a fixed substep too long to be stable for symplectic Euler is taken in
    /// stable pieces instead of refused.
    /// At most about 1.5 times the mesh's mean edge length: a larger one would list too many
    /// neighbour pairs and is refused (`FC_ERROR_INVALID_ARGUMENT`, the message says how large
    /// a one the mesh takes). See docs/collisions.md.
    pub self_collision_thickness: f64,
    /// Coulomb friction coefficient of the cloth against itself (>= 0). Default 0.
    pub self_collision_friction: f64,
    /// Length over which the form drag smooths the normal velocity before it acts, m (>= 0;
    /// 0 = each particle's own). Ripples much shorter than it shed little drag, so a brisk
    /// swing keeps its short bumps while the sheet's motion at large is damped in full.
    /// Default 0 (`FC_PRESET_UNDERWATER`: see docs/underwater.md).
    pub form_drag_scale: f64,
    /// Spacing at which `bend_stiffness` holds, m (>= 0; 0 = the paper's spring constant at
    /// any spacing). With a reference, a cloth of spacing h (a grid's `spacing`; for a mesh the
    /// side of a square of two of its triangles' mean area) takes
    /// `bend_stiffness * (reference / h)^2`, so its bending, and the look, do not change with
    /// the resolution. Default 0 (`FC_PRESET_UNDERWATER`: 0.01, see docs/underwater.md).
    pub bend_reference_spacing: f64,
    /// Added mass of the cloth's large-scale normal motion, kg/m^2 per unit area (>= 0; 0 =
    /// off, the default): motion smoother than `coarse_length` carries this much more water
    /// than `added_mass` alone, ripples shorter than it only `added_mass` (a scale-aware
    /// inertia; a rigid plate of width W carries about `water_density * pi * W / 4` in all).
    /// Costs a small solve a step and the tile-fused step. See docs/underwater.md.
    pub coarse_added_mass: f64,
    /// Spacing of the coarse level's patches over the rest shape, m (> 0 when
    /// `coarse_added_mass` is on): at most this far apart along the rest shape's two principal
    /// directions, at most 256 patches (a shorter length is refused with
    /// `FC_ERROR_INVALID_ARGUMENT`, the message naming one that fits). Default 0.
    pub coarse_length: f64,
    /// Self-collision thickness in the cloth's spacings (dimensionless, >= 0; 0 adds nothing,
    /// the default): adds `self_collision_relative * spacing` m to `self_collision_thickness`
    /// when the cloth is built or given this description, `spacing` a grid's own or, for a
    /// mesh, the side of a square of two of its triangles' mean rest area. One value suits a
    /// cloth at any resolution (0.4: 4 mm on a 1 cm grid, 1.2 mm at 3 mm); `fc_cloth_get_desc`
    /// gives it back resolved into `self_collision_thickness` (m), this field 0.
    pub self_collision_relative: f64,
    /// Skin drag on the unsteady part of the motion along the cloth, N s/m^3 per unit area
    /// (>= 0; 0 = off, the default): adds `skin_drag_unsteady` times the tangential velocity
    /// relative to its running mean over `skin_drag_memory`. Motion along the cloth that
    /// reverses meets a young, thin boundary layer (a Stokes layer, `sqrt(2 rho_w mu omega)`
    /// on both faces) and more friction than a steady current, which meets `skin_drag` alone.
    /// Keeps 24 bytes a particle (in snapshots). `FC_PRESET_UNDERWATER`: 1.36, so that motion
    /// at 0.5 Hz meets 2.51 (see docs/underwater.md).
    pub skin_drag_unsteady: f64,
    /// Time constant of the running mean `skin_drag_unsteady` acts against, s (> 0 when it is
    /// on): about how long a boundary layer takes from a sudden start to a steady flow's.
    /// Default 0 (`FC_PRESET_UNDERWATER`: 1).
    pub skin_drag_memory: f64,
}

/// Each ABI enumeration value beside the library's, once: [`FcClothDesc::config`] reads
/// through these tables and [`FcClothDesc::from_model`] writes through them.
const SPRING_DAMPINGS: [(FcSpringDamping, SpringDamping); 4] = [
    (FcSpringDamping::FC_SPRING_DAMPING_NONE, SpringDamping::None),
    (
        FcSpringDamping::FC_SPRING_DAMPING_VELOCITY,
        SpringDamping::Velocity,
    ),
    (
        FcSpringDamping::FC_SPRING_DAMPING_FRACTIONAL,
        SpringDamping::Fractional,
    ),
    (
        FcSpringDamping::FC_SPRING_DAMPING_FRACTIONAL_STRAIN,
        SpringDamping::FractionalStrain,
    ),
];

const INTEGRATORS: [(FcIntegrator, Integrator); 6] = [
    (
        FcIntegrator::FC_INTEGRATOR_EXPLICIT_EULER,
        Integrator::ExplicitEuler,
    ),
    (
        FcIntegrator::FC_INTEGRATOR_SYMPLECTIC_EULER,
        Integrator::SymplecticEuler,
    ),
    (
        FcIntegrator::FC_INTEGRATOR_IMPLICIT_EULER,
        Integrator::ImplicitEuler,
    ),
    (
        FcIntegrator::FC_INTEGRATOR_EXTRAPOLATED_SYMPLECTIC,
        Integrator::ExtrapolatedSymplectic,
    ),
    (
        FcIntegrator::FC_INTEGRATOR_EXTRAPOLATED_IMPLICIT,
        Integrator::ExtrapolatedImplicit,
    ),
    (FcIntegrator::FC_INTEGRATOR_XPBD, Integrator::Xpbd),
];

/// The library's value of the ABI value `raw` in `table`.
fn decode<A: Copy + Into<u32>, B: Copy>(table: &[(A, B)], raw: u32) -> Option<B> {
    table.iter().find(|(a, _)| (*a).into() == raw).map(|&(_, b)| b)
}

/// The ABI value of the library's value `value` in `table` (every value is in its table).
fn encode<A: Copy + Into<u32>, B: Copy + PartialEq>(table: &[(A, B)], value: B) -> u32 {
    table
        .iter()
        .find(|(_, b)| *b == value)
        .map_or(u32::MAX, |&(a, _)| a.into())
}

impl From<FcSpringDamping> for u32 {
    fn from(v: FcSpringDamping) -> u32 {
        v as u32
    }
}

impl From<FcIntegrator> for u32 {
    fn from(v: FcIntegrator) -> u32 {
        v as u32
    }
}

const HISTORY_OFF: u32 = FcHistoryScheme::FC_HISTORY_OFF as u32;
const HISTORY_TRUNCATED: u32 = FcHistoryScheme::FC_HISTORY_TRUNCATED as u32;
const HISTORY_FULL: u32 = FcHistoryScheme::FC_HISTORY_FULL as u32;
const HISTORY_SOE: u32 = FcHistoryScheme::FC_HISTORY_SOE as u32;

fn v3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

impl FcClothDesc {
    pub(crate) fn from_model(model: &Model, config: &ClothConfig) -> Self {
        use crate::history::{DEFAULT_SOE_HORIZON, DEFAULT_SOE_MIN_DT, DEFAULT_SOE_TOLERANCE};
        let (mut tol, mut horizon, mut min_dt) =
            (DEFAULT_SOE_TOLERANCE, DEFAULT_SOE_HORIZON, DEFAULT_SOE_MIN_DT);
        let (scheme, u) = match config.scheme {
            Scheme::Off => (HISTORY_OFF, 3),
            Scheme::Truncated { u } => (HISTORY_TRUNCATED, u),
            Scheme::Full => (HISTORY_FULL, 3),
            Scheme::SumOfExponentials {
                tolerance,
                horizon: hz,
                min_dt: md,
            } => {
                (tol, horizon, min_dt) = (tolerance, hz, md);
                (HISTORY_SOE, 3)
            }
        };
        Self {
            struct_size: DESC_SIZE as u32,
            width: 61,
            height: 41,
            spacing: 0.01,
            total_mass: 0.0,
            areal_density: 1.0,
            cloth_density: model.cloth_density,
            water_density: model.water_density,
            gravity: model.gravity.into(),
            current: model.current.into(),
            stretch_stiffness: model.stretch_stiffness,
            shear_stiffness: model.shear_stiffness,
            bend_stiffness: model.bend_stiffness,
            spring_damping: model.spring_damping,
            spring_damping_mode: encode(&SPRING_DAMPINGS, model.spring_damping_mode),
            viscous_drag: model.viscous_drag,
            history_drag: model.history_drag,
            normal_drag: model.normal_drag,
            history_scheme: scheme,
            history_u: u,
            history_tolerance: tol,
            history_horizon: horizon,
            history_min_dt: min_dt,
            integrator: encode(&INTEGRATORS, config.integrator),
            max_substep: config.max_substep,
            solver_tolerance: config.solver.tolerance,
            solver_max_iterations: config.solver.max_iterations,
            collision_stiffness: model.collision_stiffness,
            collision_damping: model.collision_damping,
            collision_margin: model.collision_margin,
            max_speed: config.max_speed,
            added_mass: model.water.added_mass,
            form_drag: model.water.form_drag,
            entrained_mass: model.water.entrained_mass,
            skin_drag: model.water.skin_drag,
            self_collision_thickness: model.self_collision_thickness,
            self_collision_friction: model.self_collision_friction,
            viscous_drag_per_area: model.water.viscous_drag,
            history_drag_per_area: model.water.history_drag,
            normal_drag_per_area: model.water.normal_drag,
            stretch_damping_scale: model.spring_damping_scale[0],
            shear_damping_scale: model.spring_damping_scale[1],
            bend_damping_scale: model.spring_damping_scale[2],
            added_mass_coefficient: model.water.added_mass_coefficient,
            form_drag_scale: model.water.form_drag_scale,
            bend_reference_spacing: model.bend_reference_spacing,
            coarse_added_mass: model.water.coarse_added_mass,
            coarse_length: model.water.coarse_length,
            self_collision_relative: model.self_collision_relative,
            skin_drag_unsteady: model.water.skin_drag_unsteady,
            skin_drag_memory: model.water.skin_drag_memory,
        }
    }

    /// The grid this description asks for (checked by `GridSpec::build`).
    pub fn grid_spec(&self) -> GridSpec {
        let spacing = f64::from(self.spacing);
        let total_mass = if self.total_mass > 0.0 {
            self.total_mass
        } else {
            self.areal_density
                * f64::from(self.width.saturating_sub(1))
                * f64::from(self.height.saturating_sub(1))
                * spacing
                * spacing
        };
        GridSpec {
            width: self.width,
            height: self.height,
            spacing,
            total_mass,
        }
    }

    /// The configuration this description asks for; enumerated fields are checked here,
    /// coefficients by `Cloth::new`.
    pub fn config(&self) -> Result<ClothConfig, FfiError> {
        if self.total_mass.is_nan() {
            return Err(FfiError::invalid("total_mass is NaN"));
        }
        let spring_damping_mode = decode(&SPRING_DAMPINGS, self.spring_damping_mode).ok_or_else(|| {
            FfiError::invalid(format!(
                "spring_damping_mode {} is not an FcSpringDamping value",
                self.spring_damping_mode
            ))
        })?;
        let scheme = match self.history_scheme {
            HISTORY_OFF => Scheme::Off,
            HISTORY_TRUNCATED if self.history_u >= 1 => Scheme::Truncated { u: self.history_u },
            HISTORY_TRUNCATED => return Err(FfiError::invalid("history_u must be >= 1")),
            HISTORY_FULL => Scheme::Full,
            HISTORY_SOE => Scheme::SumOfExponentials {
                tolerance: self.history_tolerance,
                horizon: self.history_horizon,
                min_dt: self.history_min_dt,
            },
            x => {
                return Err(FfiError::invalid(format!(
                    "history_scheme {x} is not an FcHistoryScheme value"
                )))
            }
        };
        let integrator = decode(&INTEGRATORS, self.integrator).ok_or_else(|| {
            FfiError::invalid(format!(
                "integrator {} is not an FcIntegrator value",
                self.integrator
            ))
        })?;
        Ok(ClothConfig {
            model: Model {
                cloth_density: self.cloth_density,
                water_density: self.water_density,
                gravity: v3(self.gravity),
                current: v3(self.current),
                stretch_stiffness: self.stretch_stiffness,
                shear_stiffness: self.shear_stiffness,
                bend_stiffness: self.bend_stiffness,
                bend_reference_spacing: self.bend_reference_spacing,
                spring_damping: self.spring_damping,
                spring_damping_mode,
                spring_damping_scale: [
                    self.stretch_damping_scale,
                    self.shear_damping_scale,
                    self.bend_damping_scale,
                ],
                viscous_drag: self.viscous_drag,
                history_drag: self.history_drag,
                normal_drag: self.normal_drag,
                collision_stiffness: self.collision_stiffness,
                collision_damping: self.collision_damping,
                collision_margin: self.collision_margin,
                self_collision_thickness: self.self_collision_thickness,
                self_collision_relative: self.self_collision_relative,
                self_collision_friction: self.self_collision_friction,
                water: crate::model::Water {
                    added_mass: self.added_mass,
                    added_mass_coefficient: self.added_mass_coefficient,
                    entrained_mass: self.entrained_mass,
                    form_drag: self.form_drag,
                    form_drag_scale: self.form_drag_scale,
                    skin_drag: self.skin_drag,
                    skin_drag_unsteady: self.skin_drag_unsteady,
                    skin_drag_memory: self.skin_drag_memory,
                    viscous_drag: self.viscous_drag_per_area,
                    history_drag: self.history_drag_per_area,
                    normal_drag: self.normal_drag_per_area,
                    coarse_added_mass: self.coarse_added_mass,
                    coarse_length: self.coarse_length,
                },
            },
            scheme,
            integrator,
            max_speed: self.max_speed,
            max_substep: self.max_substep,
            solver: SolverSettings {
                tolerance: self.solver_tolerance,
                max_iterations: self.solver_max_iterations,
            },
            accept_unconverged: false,
        })
    }
}

/// The default description: a 61 x 41 grid of 1 cm spacing (0.6 m x 0.4 m, 0.24 kg)
/// with the paper's fractional forces (Eq. 2-5), the accurate SOE history (tolerance
/// 1e-3) and explicit Euler. `fc_cloth_desc_preset(FC_PRESET_FRACTIONAL_PAPER, ...)`
/// gives the paper's exact configuration (u = 3).
#[no_mangle]
pub extern "C" fn fc_cloth_desc_default() -> FcClothDesc {
    let config = ClothConfig::default();
    FcClothDesc::from_model(&config.model, &config)
}

/// Fills `*out_desc` (a struct of `struct_size` bytes: `sizeof(FcClothDesc)`) with the
/// defaults, `struct_size` included. What the header's inline `fc_cloth_desc_default` calls.
/// `FC_ERROR_INVALID_ARGUMENT` for a size the library cannot serve (see `FcClothDesc`).
///
/// # Safety
/// `out_desc` must be NULL or point to `struct_size` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_desc_init(out_desc: *mut FcClothDesc, struct_size: usize) -> FcStatus {
    // SAFETY: forwarded caller promise.
    guard(|| unsafe { write_desc(out_desc, struct_size, &fc_cloth_desc_default()) })
}

/// `fc_cloth_desc_preset` for a struct of `struct_size` bytes (what the header's inline
/// `fc_cloth_desc_preset` calls with `sizeof(FcClothDesc)`).
///
/// # Safety
/// `out_desc` must be NULL or point to `struct_size` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_desc_preset_sized(
    preset: u32,
    out_desc: *mut FcClothDesc,
    struct_size: usize,
) -> FcStatus {
    guard(|| {
        let desc = preset_desc(preset)?;
        // SAFETY: forwarded caller promise.
        unsafe { write_desc(out_desc, struct_size, &desc) }
    })
}

/// Fills `*out_desc` with a preset (an `FcPreset` value) on the default grid.
/// Returns `FC_ERROR_INVALID_ARGUMENT` for an unknown preset. Writes this library's whole
/// struct: for binders of other languages; the C header's inline version is sized.
///
/// # Safety
/// `out_desc` must be NULL or point to writable memory for one `FcClothDesc`.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_desc_preset(preset: u32, out_desc: *mut FcClothDesc) -> FcStatus {
    // SAFETY: forwarded caller promise.
    unsafe { fc_cloth_desc_preset_sized(preset, out_desc, DESC_SIZE) }
}

/// The description of a preset (an `FcPreset` value) on the default grid.
fn preset_desc(preset: u32) -> Result<FcClothDesc, FfiError> {
    const PAPER: u32 = FcPreset::FC_PRESET_FRACTIONAL_PAPER as u32;
    const VISCOUS_NORMAL: u32 = FcPreset::FC_PRESET_REGULAR_VISCOUS_NORMAL as u32;
    const VISCOUS: u32 = FcPreset::FC_PRESET_REGULAR_VISCOUS as u32;
    const NORMAL: u32 = FcPreset::FC_PRESET_REGULAR_NORMAL as u32;
    const UNDERWATER: u32 = FcPreset::FC_PRESET_UNDERWATER as u32;
    let model = match preset {
        PAPER => Model::fractional(),
        VISCOUS_NORMAL => Model::regular(RegularDrag::ViscousAndNormal),
        VISCOUS => Model::regular(RegularDrag::Viscous),
        NORMAL => Model::regular(RegularDrag::Normal),
        UNDERWATER => Model::underwater(),
        x => return Err(FfiError::invalid(format!("preset {x} is not an FcPreset value"))),
    };
    let config = ClothConfig {
        scheme: if preset == PAPER {
            Scheme::PAPER
        } else {
            Scheme::DEFAULT
        },
        integrator: if preset == UNDERWATER {
            Integrator::SymplecticEuler
        } else {
            Integrator::ExplicitEuler
        },
        // The underwater preset chooses its own step: one `fc_cloth_step` per frame works.
        max_substep: if preset == UNDERWATER {
            crate::cloth::AUTO
        } else {
            0.0
        },
        ..ClothConfig::default()
    };
    Ok(FcClothDesc::from_model(&model, &config))
}

/// Fills `*out_desc` with the cloth's description now: every coefficient, the history, the
/// integrator and solver settings as the cloth steps with them (an added mass given as
/// `added_mass_coefficient` comes back resolved into `added_mass`, the coefficient 0; a
/// thickness given as `self_collision_relative` into `self_collision_thickness`). The grid
/// fields describe the cloth as built: `width` and `height` (0 for a mesh), `spacing` (the
/// distance between vertices 0 and 1 of a grid; 0 for a mesh), `total_mass` (the sum of the
/// particle masses) and `areal_density` (that mass over the cloth's area).
///
/// # Safety
/// `cloth` NULL or live; `out_desc` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_desc(
    cloth: *const super::FcCloth,
    out_desc: *mut FcClothDesc,
) -> FcStatus {
    // SAFETY: forwarded caller promises.
    unsafe { fc_cloth_get_desc_sized(cloth, out_desc, DESC_SIZE) }
}

/// `fc_cloth_get_desc` for a struct of `struct_size` bytes (what the header's inline
/// `fc_cloth_get_desc` calls with `sizeof(FcClothDesc)`).
///
/// # Safety
/// `cloth` NULL or live; `out_desc` NULL or `struct_size` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_get_desc_sized(
    cloth: *const super::FcCloth,
    out_desc: *mut FcClothDesc,
    struct_size: usize,
) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promise.
        let cloth = unsafe { super::handle::handle(cloth) }?;
        let t = cloth.topology();
        let mut d = FcClothDesc::from_model(cloth.model(), cloth.config());
        let (w, h) = t.grid.unwrap_or((0, 0));
        d.width = w;
        d.height = h;
        d.spacing = match t.grid {
            Some(_) if t.vertex_count() > 1 => (t.rest_positions[1] - t.rest_positions[0]).norm() as f32,
            _ => 0.0,
        };
        d.total_mass = t.masses.iter().sum();
        let area: f64 = t.areas.iter().sum();
        d.areal_density = if area > 0.0 { d.total_mass / area } else { 0.0 };
        // SAFETY: forwarded caller promise.
        unsafe { write_desc(out_desc, struct_size, &d) }
    })
}

/// Changes a cloth's coefficients, integrator, `max_speed`, `max_substep` and solver settings
/// between steps from `*desc` (typically `fc_cloth_get_desc`'s, edited); positions, velocities,
/// pins, colliders, history and time are kept. The grid fields (`width`, `height`, `spacing`,
/// `total_mass`, `areal_density`) are not read. Refused with `FC_ERROR_INVALID_ARGUMENT` and a
/// message, changing nothing, for a bad value, a different history (`history_*` fields), or a
/// model whose fractional terms are switched on or off against the cloth's creation.
///
/// # Safety
/// `cloth` NULL or live; `desc` NULL or a valid description.
#[no_mangle]
pub unsafe extern "C" fn fc_cloth_set_desc(cloth: *mut super::FcCloth, desc: *const FcClothDesc) -> FcStatus {
    guard(|| {
        // SAFETY: forwarded caller promises.
        let cloth = unsafe { super::handle::handle_mut(cloth) }?;
        let desc = unsafe { read_desc(desc, fc_cloth_desc_default()) }?;
        let mut config = desc.config()?;
        config.accept_unconverged = cloth.config().accept_unconverged;
        Ok(cloth.reconfigure(config)?)
    })
}
