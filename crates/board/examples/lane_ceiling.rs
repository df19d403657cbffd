//! What eight lanes can gain over four on this CPU, for the two kinds of work the sample loop
//! does: arithmetic on values held in registers, and states that go through memory every
//! sample (a store and a load: the loop's spills). Issue 15's goal 2 asks 1.4x; where a 512-bit
//! store takes twice a 256-bit one's slot (Intel's cores), only the first kind gets there.
//!
//!     cargo run --release -p gyroemu-board --example lane_ceiling
//!
//! A measurement, not a test: the figures and the CPU model go to docs/performance.md.

#[cfg(target_arch = "x86_64")]
mod x86 {
    use core::arch::x86_64::*;
    use std::time::Instant;

    /// Independent recursions, enough to hide the latency of each operation.
    const CHAINS: usize = 12;
    /// States that go through memory each pass, as a spilled loop's do.
    const SLOTS: usize = 16;

    macro_rules! kernels {
        ($regs:ident, $mem:ident, $feat:literal, $v:ty, $set1:ident, $fma:ident, $add:ident) => {
            /// `iters` passes of one multiply-add on each of [`CHAINS`] values in registers.
            #[target_feature(enable = $feat)]
            unsafe fn $regs(iters: u64) -> f64 {
                let mut a: [$v; CHAINS] = core::array::from_fn(|i| $set1(1.0 + i as f64 * 1e-3));
                let (c, d) = ($set1(1e-9), $set1(0.999_999));
                for _ in 0..iters {
                    for x in a.iter_mut() {
                        *x = $fma(*x, d, c);
                    }
                    // Keeps the passes apart (no reassociation across them).
                    core::arch::asm!("", options(nomem, nostack));
                }
                a.iter().map(|v| *(v as *const $v).cast::<f64>()).sum()
            }

            /// `iters` passes of load, add, store on each of [`SLOTS`] states in memory.
            #[target_feature(enable = $feat)]
            unsafe fn $mem(iters: u64, slots: &mut [$v; SLOTS]) {
                let c = $set1(1e-9);
                for _ in 0..iters {
                    for k in 0..SLOTS {
                        let p = slots.as_mut_ptr().add(k);
                        core::ptr::write_volatile(p, $add(core::ptr::read_volatile(p), c));
                    }
                }
            }
        };
    }
    kernels!(
        regs4,
        mem4,
        "avx2,fma",
        __m256d,
        _mm256_set1_pd,
        _mm256_fmadd_pd,
        _mm256_add_pd
    );
    kernels!(
        regs8,
        mem8,
        "avx512f",
        __m512d,
        _mm512_set1_pd,
        _mm512_fmadd_pd,
        _mm512_add_pd
    );

    /// The best of `runs` timings of `f`, in seconds.
    fn best(runs: usize, mut f: impl FnMut()) -> f64 {
        (0..runs)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min)
    }

    pub fn main() {
        if !is_x86_feature_detected!("avx2") || !is_x86_feature_detected!("fma") {
            eprintln!("this CPU lacks AVX2 and FMA, which four lanes are built for");
            std::process::exit(1);
        }
        let eight = is_x86_feature_detected!("avx512f");
        let (iters, runs) = (50_000_000u64, 5);
        // Alternating widths within each run, so a drift of the host's speed hits both.
        let (mut t4, mut t8) = ([f64::INFINITY; 2], [f64::INFINITY; 2]);
        for _ in 0..runs {
            // SAFETY: AVX2 and FMA checked above; AVX-512F only where detected.
            t4[0] = t4[0].min(best(1, || {
                std::hint::black_box(unsafe { regs4(iters) });
            }));
            let mut s4 = [unsafe { _mm256_set1_pd(1.0) }; SLOTS];
            t4[1] = t4[1].min(best(1, || unsafe { mem4(iters / 4, &mut s4) }));
            if eight {
                t8[0] = t8[0].min(best(1, || {
                    std::hint::black_box(unsafe { regs8(iters) });
                }));
                let mut s8 = [unsafe { _mm512_set1_pd(1.0) }; SLOTS];
                t8[1] = t8[1].min(best(1, || unsafe { mem8(iters / 4, &mut s8) }));
            }
        }
        let ops = [
            (iters * CHAINS as u64) as f64,
            (iters / 4 * SLOTS as u64) as f64,
        ];
        println!(
            "what (G lane-operations/s, best of {runs})       f64x4     f64x8   f64x8 / f64x4"
        );
        for (k, what) in [
            "multiply-add in registers",
            "load, add, store through memory",
        ]
        .iter()
        .enumerate()
        {
            let r4 = 4.0 * ops[k] / t4[k] / 1e9;
            if eight {
                let r8 = 8.0 * ops[k] / t8[k] / 1e9;
                println!("{what:40} {r4:9.2} {r8:9.2} {:10.2}", r8 / r4);
            } else {
                println!("{what:40} {r4:9.2}         -          - (no AVX-512)");
            }
        }
    }
}

fn main() {
    #[cfg(target_arch = "x86_64")]
    x86::main();
    #[cfg(not(target_arch = "x86_64"))]
    eprintln!("lane_ceiling measures x86-64 vector widths only");
}
