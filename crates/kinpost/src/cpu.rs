//! The processor features this build was compiled to use (`.cargo/config.toml`
//! asks for x86-64-v3), checked before anything else runs: on a processor
//! without them, the first AVX instruction would kill the program with
//! "illegal instruction" somewhere in the middle of a post.
//!
//! Only integer code runs here, and the message goes out through the
//! standard library (compiled for the baseline): nothing in this path may use
//! the features it checks. `.ci/run` runs the command on emulated old and new
//! processors to prove it.

/// Exits with code 2 and a message naming the build's requirements when the
/// processor lacks a feature the build was compiled for; returns otherwise.
#[inline(never)]
pub fn require_build_features() {
    #[cfg(target_arch = "x86_64")]
    if !x86::build_features_present() {
        use std::io::Write as _;
        // One static message (no formatting machinery, which might be
        // inlined here with the features this build assumes).
        let _ = std::io::stderr().write_all(
            b"error: this kinpost was built for x86-64-v3 processors (AVX2, FMA, BMI1, BMI2, \
LZCNT, MOVBE: Intel Haswell, AMD Excavator and later), and this processor lacks some of \
these features. Build it for any x86-64 processor with\n    \
RUSTFLAGS=\"-C target-cpu=x86-64\" cargo install --path crates/kinpost --profile dist\n",
        );
        std::process::exit(2);
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::{__cpuid, __cpuid_count};

    /// A feature: its CPUID leaf, register and bit.
    #[derive(Clone, Copy)]
    enum Reg {
        Ecx,
        Ebx,
    }

    /// Every feature the compiler was allowed to use in this build (of
    /// those x86-64-v2 and v3 add to the baseline), with where CPUID reports
    /// it (Intel SDM vol. 2A, CPUID; AMD APM vol. 3, appendix E).
    const FEATURES: &[(bool, u32, Reg, u32)] = &[
        (cfg!(target_feature = "sse3"), 1, Reg::Ecx, 0),
        (cfg!(target_feature = "ssse3"), 1, Reg::Ecx, 9),
        (cfg!(target_feature = "fma"), 1, Reg::Ecx, 12),
        (cfg!(target_feature = "cmpxchg16b"), 1, Reg::Ecx, 13),
        (cfg!(target_feature = "sse4.1"), 1, Reg::Ecx, 19),
        (cfg!(target_feature = "sse4.2"), 1, Reg::Ecx, 20),
        (cfg!(target_feature = "movbe"), 1, Reg::Ecx, 22),
        (cfg!(target_feature = "popcnt"), 1, Reg::Ecx, 23),
        (cfg!(target_feature = "xsave"), 1, Reg::Ecx, 26),
        (cfg!(target_feature = "avx"), 1, Reg::Ecx, 28),
        (cfg!(target_feature = "f16c"), 1, Reg::Ecx, 29),
        (cfg!(target_feature = "bmi1"), 7, Reg::Ebx, 3),
        (cfg!(target_feature = "avx2"), 7, Reg::Ebx, 5),
        (cfg!(target_feature = "bmi2"), 7, Reg::Ebx, 8),
        (cfg!(target_feature = "lzcnt"), 0x8000_0001, Reg::Ecx, 5),
    ];

    /// Whether the processor (and, for AVX, the operating system) supports
    /// every feature of [`FEATURES`] this build uses.
    pub fn build_features_present() -> bool {
        // (Leaves above the highest one supported are not queried.)
        let (max_basic, max_extended) = (__cpuid(0).eax, __cpuid(0x8000_0000).eax);
        for &(used, leaf, reg, bit) in FEATURES {
            if !used {
                continue;
            }
            let max = if leaf >= 0x8000_0000 {
                max_extended
            } else {
                max_basic
            };
            if leaf > max {
                return false;
            }
            let r = __cpuid_count(leaf, 0);
            let value = match reg {
                Reg::Ecx => r.ecx,
                Reg::Ebx => r.ebx,
            };
            if value & (1 << bit) == 0 {
                return false;
            }
        }
        !cfg!(target_feature = "avx") || os_saves_avx_state()
    }

    /// Whether the operating system saves the AVX registers on a context
    /// switch: OSXSAVE (CPUID.1:ECX bit 27) and XCR0 bits 1 and 2 (SSE and
    /// AVX state).
    fn os_saves_avx_state() -> bool {
        let osxsave = __cpuid_count(1, 0).ecx & (1 << 27) != 0;
        if !osxsave {
            return false;
        }
        let (low, _high): (u32, u32);
        // SAFETY: XGETBV with ECX = 0 is valid when OSXSAVE is set.
        unsafe {
            std::arch::asm!(
                "xgetbv",
                in("ecx") 0u32,
                out("eax") low,
                out("edx") _high,
                options(nomem, nostack, preserves_flags),
            );
        }
        low & 0b110 == 0b110
    }
}
