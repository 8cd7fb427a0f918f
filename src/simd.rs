//! Run-time choice of vector width for the hot loops.
//!
//! The library is built for baseline x86-64 (SSE2), so it runs on any 64-bit x86 CPU. The
//! few loops that dominate a step are written over small fixed-size arrays so that the
//! compiler vectorises them; `simd_dispatch!` compiles such a loop
//! again with AVX2 and with AVX-512 enabled and calls the widest one the CPU supports.
//! Rust never fuses a multiply and an add on its own (no FMA contraction), and IEEE
//! arithmetic rounds the same in every vector width, so all three produce the same bits.

/// Widest vector extension this CPU offers, as chosen by `simd_dispatch!`.
pub fn level() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") {
            return "avx512";
        }
        if std::is_x86_feature_detected!("avx2") {
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
    ($vis:vis fn $name:ident ( $($p:ident : $t:ty),* $(,)? ) => $body:ident) => {
        $vis fn $name($($p: $t),*) {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f")]
                unsafe fn wide512($($p: $t),*) {
                    $body($($p),*)
                }
                #[target_feature(enable = "avx2")]
                unsafe fn wide256($($p: $t),*) {
                    $body($($p),*)
                }
                if std::is_x86_feature_detected!("avx512f") {
                    // SAFETY: the CPU supports AVX-512F (checked just above).
                    return unsafe { wide512($($p),*) };
                }
                if std::is_x86_feature_detected!("avx2") {
                    // SAFETY: the CPU supports AVX2 (checked just above).
                    return unsafe { wide256($($p),*) };
                }
            }
            $body($($p),*)
        }
    };
}
