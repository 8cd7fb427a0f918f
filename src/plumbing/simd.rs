//! Run-time choice of vector width for the hot loops.
//!
//! The library is built for baseline x86-64 (SSE2), so it runs on any 64-bit x86 CPU. The
//! few loops that dominate a step are written over small fixed-size arrays so that the
//! compiler vectorises them; `simd_dispatch!` compiles such a loop
//! again with AVX2 (+FMA) and with AVX-512 enabled and calls the widest one the CPU supports.
//! Rust never fuses a multiply and an add on its own (no FMA contraction), and IEEE
//! arithmetic rounds the same in every vector width, so all three produce the same bits.
//! Where a loop asks for a fused multiply-add explicitly (`f64::mul_add`, one rounding), the
//! AVX2 and AVX-512 builds use the FMA instruction and the baseline build calls the C
//! library's `fma`, which rounds identically (correctly rounded by IEEE 754), only slower:
//! the bits are still the same on every CPU.

/// A vector width the hot loops can run at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Width {
    Baseline,
    Avx2,
    Avx512,
}

/// Environment variable that caps the vector width (`avx512`, `avx2` or `baseline`), for
/// measuring one against another on the same machine; never wider than the CPU offers.
pub const WIDTH_VARIABLE: &str = "FRACCLOTH_SIMD";

/// The widest width this CPU offers.
fn offered() -> Width {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") {
            return Width::Avx512;
        }
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            return Width::Avx2;
        }
    }
    Width::Baseline
}

/// The width `simd_dispatch!` runs at: the widest this CPU offers, capped by
/// [`WIDTH_VARIABLE`] when it is set (read once). Every width gives the same bits.
pub fn width() -> Width {
    static CHOSEN: std::sync::OnceLock<Width> = std::sync::OnceLock::new();
    *CHOSEN.get_or_init(|| {
        let cap = match std::env::var(WIDTH_VARIABLE).as_deref() {
            Ok("baseline") | Ok("scalar") => Width::Baseline,
            Ok("avx2") => Width::Avx2,
            _ => Width::Avx512,
        };
        offered().min(cap)
    })
}

/// The vector width `simd_dispatch!` runs at, by name ("avx512", "avx2" or "baseline").
pub fn level() -> &'static str {
    match width() {
        Width::Avx512 => "avx512",
        Width::Avx2 => "avx2",
        Width::Baseline => "baseline",
    }
}

/// `simd_dispatch! { fn name(a: A, b: B) => body }` defines `fn name(a: A, b: B)` that calls
/// the `#[inline(always)]` function `body(a, b)` compiled for AVX-512, AVX2 or the baseline,
/// as [`width`] chooses.
#[macro_export]
#[doc(hidden)]
macro_rules! simd_dispatch {
    ($vis:vis fn $name:ident ( $($p:ident : $t:ty),* $(,)? ) $(-> $ret:ty)? => $body:ident) => {
        // As many arguments as the body it dispatches to has.
        #[allow(clippy::too_many_arguments)]
        $vis fn $name($($p: $t),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f")]
                #[allow(clippy::too_many_arguments)]
                unsafe fn wide512($($p: $t),*) $(-> $ret)? {
                    $body($($p),*)
                }
                #[target_feature(enable = "avx2,fma")]
                #[allow(clippy::too_many_arguments)]
                unsafe fn wide256($($p: $t),*) $(-> $ret)? {
                    $body($($p),*)
                }
                match $crate::simd_width() {
                    // SAFETY: `simd_width` is never wider than the CPU offers (AVX-512F here).
                    $crate::SimdWidth::Avx512 => return unsafe { wide512($($p),*) },
                    // SAFETY: likewise (AVX2 and FMA here).
                    $crate::SimdWidth::Avx2 => return unsafe { wide256($($p),*) },
                    $crate::SimdWidth::Baseline => {}
                }
            }
            $body($($p),*)
        }
    };
}
