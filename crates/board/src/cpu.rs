//! Which CPU this is, from CPUID: its vendor, family, model and brand string. The lane width
//! and the generator's look-up are chosen from them at run time, and a benchmark's figures mean
//! little without them (machines differ from run to run), so `gyroemu bench` prints them
//! (beside the choices, `lanes::vector_paths`).

/// A CPU as CPUID names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CpuId {
    /// Leaf 0's twelve bytes, trimmed: "GenuineIntel", "AuthenticAMD", ...
    pub vendor: String,
    /// The display family (leaf 1: base family, plus the extended family when the base is 0Fh).
    pub family: u32,
    /// The display model (leaf 1: base model, plus the extended model times 16 when the base
    /// family is 6 or 0Fh).
    pub model: u32,
    /// Leaves 8000_0002h to 8000_0004h, trimmed; empty where the CPU lacks them.
    pub brand: String,
}

impl CpuId {
    /// This CPU, or `None` off x86-64.
    pub fn this_cpu() -> Option<Self> {
        #[cfg(target_arch = "x86_64")]
        {
            use core::arch::x86_64::__cpuid;
            // Leaves 0, 1 and 8000_0000h exist on every x86-64 CPU.
            let v = __cpuid(0);
            let eax1 = __cpuid(1).eax;
            let brand = if __cpuid(0x8000_0000).eax >= 0x8000_0004 {
                let words: Vec<u32> = (0x8000_0002..=0x8000_0004u32)
                    .flat_map(|leaf| {
                        let r = __cpuid(leaf);
                        [r.eax, r.ebx, r.ecx, r.edx]
                    })
                    .collect();
                text_of(&words)
            } else {
                String::new()
            };
            Some(CpuId {
                vendor: text_of(&[v.ebx, v.edx, v.ecx]),
                family: family(eax1),
                model: model(eax1),
                brand,
            })
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            None
        }
    }

    /// "Intel(R) Xeon(R) Processor (GenuineIntel family 6 model 167)": the brand, then the
    /// vendor, family and model in decimal (how `/proc/cpuinfo` gives them).
    pub fn describe(&self) -> String {
        let id = format!(
            "{} family {} model {}",
            self.vendor, self.family, self.model
        );
        if self.brand.is_empty() {
            id
        } else {
            format!("{} ({id})", self.brand)
        }
    }
}

/// CPUID's registers as the ASCII text they hold (little-endian bytes in register order), up
/// to the first NUL (where the kernel stops too), without the spaces that pad it; a byte that
/// is not printable ASCII reads as a space.
fn text_of(words: &[u32]) -> String {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    let text: String = bytes
        .iter()
        .take_while(|&&b| b != 0)
        .map(|&b| {
            if b.is_ascii_graphic() || b == b' ' {
                b as char
            } else {
                ' '
            }
        })
        .collect();
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The display family of CPUID leaf 1's EAX: the base family, plus the extended family when
/// the base is 0Fh (the rule of both vendors' manuals).
fn family(eax: u32) -> u32 {
    let base = (eax >> 8) & 0xF;
    if base == 0xF {
        base + ((eax >> 20) & 0xFF)
    } else {
        base
    }
}

/// The display model of CPUID leaf 1's EAX: the base model, plus the extended model times 16
/// when the base family is 6 or 0Fh (Intel's rule; AMD's adds it for 0Fh, the base family of
/// every AMD x86-64 part, so the two agree on every x86-64 CPU).
fn model(eax: u32) -> u32 {
    let base = (eax >> 4) & 0xF;
    match (eax >> 8) & 0xF {
        0x6 | 0xF => base + (((eax >> 16) & 0xF) << 4),
        _ => base,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `s` as CPUID would return it in words (zero-padded to whole words).
    fn words(s: &str) -> Vec<u32> {
        let mut b = s.as_bytes().to_vec();
        b.resize(b.len().div_ceil(4) * 4, 0);
        b.chunks(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    }

    #[test]
    fn cpuid_words_decode_to_vendor_family_and_model() {
        // Leaf 0's EBX, EDX, ECX of each vendor.
        assert_eq!(
            text_of(&[0x6874_7541, 0x6974_6e65, 0x444d_4163]),
            "AuthenticAMD"
        );
        assert_eq!(
            text_of(&[0x756e_6547, 0x4965_6e69, 0x6c65_746e]),
            "GenuineIntel"
        );
        // Leaf 1's EAX: Zen 4 EPYC 9004 (family 19h model 11h), Zen 5 (1Ah model 02h),
        // Zen 3 (19h model 01h), an Intel Sapphire Rapids (6, model 8Fh), a Pentium 4
        // (0Fh, model 2; extended family 0) and a 486-era base family 4 whose extended bits
        // must be ignored.
        for (eax, fam, m) in [
            (0x00A1_0F11, 0x19, 0x11),
            (0x00B0_0F20, 0x1A, 0x02),
            (0x00A0_0F11, 0x19, 0x01),
            (0x0008_06F8, 6, 0x8F),
            (0x0000_0F29, 0xF, 0x2),
            (0x0FF0_0400, 4, 0),
        ] {
            assert_eq!((family(eax), model(eax)), (fam, m), "{eax:#010x}");
        }
    }

    #[test]
    fn the_brand_string_is_trimmed_and_described_with_the_ids() {
        let mut w = words("       Intel(R) Xeon(R) Processor  ");
        w.resize(12, 0);
        let cpu = CpuId {
            vendor: "GenuineIntel".into(),
            family: 6,
            model: 167,
            brand: text_of(&w),
        };
        assert_eq!(
            cpu.describe(),
            "Intel(R) Xeon(R) Processor (GenuineIntel family 6 model 167)"
        );
        let bare = CpuId {
            brand: String::new(),
            ..cpu
        };
        assert_eq!(bare.describe(), "GenuineIntel family 6 model 167");
    }

    #[test]
    #[cfg(target_arch = "x86_64")]
    fn this_cpu_has_a_vendor() {
        // Not always twelve letters once trimmed ("  Shanghai  ", "VIA VIA VIA "); the
        // integration test compares every field with /proc/cpuinfo.
        let cpu = CpuId::this_cpu().expect("x86-64");
        assert!(!cpu.vendor.is_empty() && cpu.vendor.is_ascii(), "{cpu:?}");
        assert!(cpu.family >= 6, "{cpu:?}");
    }

    #[test]
    fn text_ends_at_the_first_nul() {
        let mut w = words("Brand");
        w.extend(words("\0\0\0\0after"));
        assert_eq!(text_of(&w), "Brand");
        assert_eq!(text_of(&[0; 4]), "");
    }
}
