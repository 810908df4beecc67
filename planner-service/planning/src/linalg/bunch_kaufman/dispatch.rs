//! The run-time dispatch of the kernels between AVX2 and the baseline code.

/// Declares `pub fn $name` running `$body` on the widest vector unit the CPU has: AVX2
/// where present (detected at run time; the build targets baseline x86-64), else the
/// baseline (SSE2) code, also public as `$portable`. Both paths execute the same
/// floating-point operations in the same order — no fused multiply-add, partial sums in
/// the same lanes — so they give the same bits (`tests::dispatched_and_portable_paths_agree_bit_for_bit`).
macro_rules! dispatched {
    ($(#[$doc:meta])* $name:ident, $avx2:ident, $portable:ident, $body:ident,
     ($($arg:ident: $ty:ty),*) $(-> $ret:ty)?) => {
        $(#[$doc])*
        pub fn $name($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU has AVX2 (checked just above).
                return unsafe { $avx2($($arg),*) };
            }
            $body($($arg),*)
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        fn $avx2($($arg: $ty),*) $(-> $ret)? {
            $body($($arg),*)
        }

        #[doc = concat!("[`", stringify!($name), "`] on the baseline (SSE2) code path.")]
        pub fn $portable($($arg: $ty),*) $(-> $ret)? {
            $body($($arg),*)
        }
    };
}
