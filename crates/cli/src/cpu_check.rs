//! The check `main` runs before anything else: the build targets x86-64-v3
//! (`.cargo/config.toml`), so on a CPU (or an OS) without it the binary says so instead of
//! dying on an illegal instruction. `is_x86_feature_detected!` cannot tell: it folds to `true`
//! when the build enables the feature, so this asks `cpuid` and `xgetbv` directly.

const AVX2: u32 = 1 << 5; // leaf 7, EBX
const BMI2: u32 = 1 << 8; // leaf 7, EBX
const FMA: u32 = 1 << 12; // leaf 1, ECX
const OSXSAVE: u32 = 1 << 27; // leaf 1, ECX: the OS has XSAVE on, so `xgetbv` may run
/// XCR0's SSE and AVX state bits: the OS saves the YMM registers across context switches.
const XCR0_SSE_AVX: u64 = 0b110;

/// Whether CPUID's words show what the x86-64-v3 build needs (AVX2, FMA, BMI2, with leaf 7
/// only where the highest leaf reaches it) and XCR0 (`None` where the OS has no XSAVE on) that
/// the OS saves the AVX registers; without that, AVX instructions fault even on a CPU that has
/// them.
pub(crate) fn v3_usable(max_leaf: u32, l1_ecx: u32, l7_ebx: u32, xcr0: Option<u64>) -> bool {
    let l7_ebx = if max_leaf >= 7 { l7_ebx } else { 0 };
    let cpu = l1_ecx & FMA != 0 && l7_ebx & AVX2 != 0 && l7_ebx & BMI2 != 0;
    let os = l1_ecx & OSXSAVE != 0 && xcr0.is_some_and(|x| x & XCR0_SSE_AVX == XCR0_SSE_AVX);
    cpu && os
}

/// `Err` with the message to print where [`v3_usable`] is false on this machine.
#[inline(never)]
pub(crate) fn cpu_supports_build() -> Result<(), &'static str> {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    {
        use core::arch::x86_64::{__cpuid, __cpuid_count, _xgetbv};
        let (l0, l1) = (__cpuid(0), __cpuid(1));
        let l7_ebx = if l0.eax >= 7 {
            __cpuid_count(7, 0).ebx
        } else {
            0
        };
        // SAFETY: `xgetbv` runs only where CPUID says the OS has enabled XSAVE (OSXSAVE).
        let xcr0 = (l1.ecx & OSXSAVE != 0).then(|| unsafe { _xgetbv(0) });
        if !v3_usable(l0.eax, l1.ecx, l7_ebx, xcr0) {
            return Err("this gyroemu was built for x86-64-v3 (AVX2, FMA, BMI2), which this CPU lacks or its OS has not enabled; rebuild with \
                 RUSTFLAGS=\"-C target-cpu=x86-64\" cargo build --release (see docs/architecture.md, section 6)\n");
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// CPUID words of an x86-64-v3 CPU: leaf 1 ECX and leaf 7 EBX as Intel's SDM lays them out
    /// (FMA ECX bit 12, OSXSAVE bit 27; AVX2 EBX bit 5, BMI2 bit 8), XCR0 with x87, SSE and AVX
    /// state on.
    const ECX: u32 = FMA | OSXSAVE | (1 << 28) | (1 << 20) | (1 << 19);
    const EBX: u32 = AVX2 | BMI2 | (1 << 3);
    const XCR0: u64 = 0b111;

    #[test]
    fn every_feature_and_the_os_state_are_asked_for() {
        assert!(v3_usable(0xD, ECX, EBX, Some(XCR0)));
        // Each missing piece refuses the build.
        assert!(!v3_usable(0xD, ECX & !FMA, EBX, Some(XCR0)), "no FMA");
        assert!(!v3_usable(0xD, ECX, EBX & !AVX2, Some(XCR0)), "no AVX2");
        assert!(!v3_usable(0xD, ECX, EBX & !BMI2, Some(XCR0)), "no BMI2");
        // Leaf 7 is read only where the highest leaf reaches it (older CPUs return the
        // highest leaf's words for a leaf beyond it).
        assert!(
            !v3_usable(6, ECX, EBX, Some(XCR0)),
            "leaf 7 beyond the highest"
        );
        // The OS: XSAVE off, or the AVX (YMM) state not saved.
        assert!(
            !v3_usable(0xD, ECX & !OSXSAVE, EBX, Some(XCR0)),
            "no OSXSAVE"
        );
        assert!(!v3_usable(0xD, ECX, EBX, None), "no XCR0");
        assert!(!v3_usable(0xD, ECX, EBX, Some(0b011)), "AVX state off");
        assert!(!v3_usable(0xD, ECX, EBX, Some(0b101)), "SSE state off");
    }

    /// This test binary is itself an x86-64-v3 build running, so the check must pass here.
    #[test]
    fn the_machine_running_the_tests_passes() {
        assert_eq!(cpu_supports_build(), Ok(()));
    }
}
