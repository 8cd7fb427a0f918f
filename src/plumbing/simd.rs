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

/// Widest vector extension this CPU offers, as chosen by `simd_dispatch!`.
pub fn level() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") {
            return "avx512";
        }
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            return "avx2";
        }
    }
    "baseline"
}

/// `simd_dispatch! { fn name(a: A, b: B) => body }` defines `fn name(a: A, b: B)` that calls
/// the `#[inline(always)]` function `body(a, b)` compiled for AVX-512, AVX2 or the baseline,
/// whichever is the widest this CPU has.
#[macro_export]
#[doc(hidden)]
macro_rules! simd_dispatch {
    ($vis:vis fn $name:ident ( $($p:ident : $t:ty),* $(,)? ) $(-> $ret:ty)? => $body:ident) => {
        $vis fn $name($($p: $t),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f")]
                unsafe fn wide512($($p: $t),*) $(-> $ret)? {
                    $body($($p),*)
                }
                #[target_feature(enable = "avx2,fma")]
                unsafe fn wide256($($p: $t),*) $(-> $ret)? {
                    $body($($p),*)
                }
                if std::is_x86_feature_detected!("avx512f") {
                    // SAFETY: the CPU supports AVX-512F (checked just above).
                    return unsafe { wide512($($p),*) };
                }
                if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                    // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                    return unsafe { wide256($($p),*) };
                }
            }
            $body($($p),*)
        }
    };
}
