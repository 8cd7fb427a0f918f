//! The look meter: what a swinging cloth's centre column does at the drive frequency
//! (half-waves, travel speed, depth of the motion, roughness, bulges), measured in absolute
//! coordinates from any point cache; and, for a cloth held still in a current, how far it leans
//! and how its free edge flutters (`stream.rs`). Definitions and their checks: `docs/look.md`,
//! `tests/look.rs`.

mod descriptors;
mod harmonic;
mod meter;
mod stream;

pub use descriptors::{
    describe, extrema_with_hysteresis, half_waves_cut_at, straight_line_residual, unwrapped_lags, visibility,
    zigzag, ColumnMotion, Descriptors, RowHarmonic, BULGE_HYSTERESIS, MAX_STRAIGHT_RESIDUAL, MIN_TRAVEL_LAG,
    VISIBLE_FRACTION, VISIBLE_RAMP,
};
pub use harmonic::{complex_amplitude, dominant_frequency};
pub use meter::{measure, Look};
pub use stream::{measure_stream, Stream, STILL};
