//! The keys each section of a config takes, what kind of value each holds and which are
//! required: the TOML is checked against this before it is deserialised, so a file's unknown,
//! missing and wrong-typed keys are all reported at once, in the user's words. The tests hold
//! it to the serde structs of `config.rs` (same keys, same required ones, same values
//! accepted).

/// What a key's value must be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Kind {
    /// A number: a float, or an integer within the 64-bit range.
    Number,
    /// An integer from 0 to `max` (its type's limit); `range`, when the key has one, is what
    /// validation accepts, and what the messages about the value's kind give.
    Count { max: u64, range: Option<IntRange> },
    /// `true` or `false`.
    Bool,
    /// A list of numbers.
    Numbers,
    /// A list of strings.
    Names,
    /// A string (an item of `Names`).
    Text,
    /// One of these strings.
    Choice(&'static [&'static str]),
}

/// The integers a key's validation accepts, `lo..=hi`: the one source of its rule and of
/// the range the schema's messages give (a value past the type's limit said "at most
/// 4294967295" for a key that takes 2 to 32).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct IntRange {
    pub lo: u64,
    pub hi: u64,
}

impl IntRange {
    pub fn contains(self, v: impl TryInto<u64>) -> bool {
        v.try_into()
            .is_ok_and(|v: u64| (self.lo..=self.hi).contains(&v))
    }

    /// `an integer from 2 to 32` (`1 or 2` for two values).
    pub fn what(self) -> String {
        if self.hi == self.lo + 1 {
            format!("{} or {}", self.lo, self.hi)
        } else {
            format!("an integer from {} to {}", self.lo, self.hi)
        }
    }

    /// `must be an integer from 2 to 32`: the validation rule.
    pub fn rule(self) -> String {
        format!("must be {}", self.what())
    }
}

/// `board.lpf_order`: the stage-1 low-pass's order.
pub(crate) const LPF_ORDER: IntRange = IntRange { lo: 1, hi: 8 };
/// `board.dac_bits`, `board.adc_bits`.
pub(crate) const CONVERTER_BITS: IntRange = IntRange { lo: 2, hi: 32 };
/// `sweep.points`: at least five, since the resonance fit has four parameters (f0, Q and a
/// complex gain); at most a bound on the sweep's work and files.
pub(crate) const SWEEP_POINTS: IntRange = IntRange { lo: 5, hi: 10_000 };
/// `pll.mode`: the mode whose output the PLL locks on.
pub(crate) const PLL_MODE: IntRange = IntRange { lo: 1, hi: 2 };

/// One key of a section.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Field {
    pub name: &'static str,
    pub kind: Kind,
    pub required: bool,
}

/// One `[section]` of the config.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Section {
    pub name: &'static str,
    pub required: bool,
    pub fields: &'static [Field],
}

const fn req(name: &'static str, kind: Kind) -> Field {
    Field {
        name,
        kind,
        required: true,
    }
}

const fn opt(name: &'static str, kind: Kind) -> Field {
    Field {
        name,
        kind,
        required: false,
    }
}

use Kind::*;

/// Any non-negative integer a `usize` key holds.
const COUNT: Kind = Count {
    max: usize::MAX as u64,
    range: None,
};
const SEED: Kind = Count {
    max: u64::MAX,
    range: None,
};

/// A `usize` key validated within `range`.
const fn count_in(range: IntRange) -> Kind {
    Count {
        max: usize::MAX as u64,
        range: Some(range),
    }
}

/// A `u32` key (converter bits).
const BITS: Kind = Count {
    max: u32::MAX as u64,
    range: Some(CONVERTER_BITS),
};

/// Every section, in the order the user guide documents them.
pub(crate) const SECTIONS: &[Section] = &[
    Section {
        name: "device",
        required: true,
        fields: &[
            req("f0_hz", Number),
            req("q", Number),
            req("angular_gain", Number),
            opt("mode2_f0_offset_hz", Number),
            opt("q_mode2", Number),
            opt("quadrature_coupling_rad2_s2", Number),
            opt("transduction_a_s_per_m", Number),
        ],
    },
    Section {
        name: "drive",
        required: true,
        fields: &[
            req("f1", Number),
            opt("f2", Number),
            opt("carrier_hz", Number),
        ],
    },
    Section {
        name: "board",
        required: false,
        fields: &[
            opt("fs_hz", Number),
            opt("tia_gain_ohm", Number),
            opt("tia_pole_hz", Number),
            opt("tia_inverting", Bool),
            opt("tia_rail_v", Number),
            opt("lpf_order", count_in(LPF_ORDER)),
            opt("lpf_cutoff_hz", Number),
            opt("decimation", COUNT),
            opt("dac_bits", BITS),
            opt("dac_full_scale", Number),
            opt("phase_shifter_error_deg", Number),
            opt("adc_bits", BITS),
            opt("adc_full_scale_v", Number),
        ],
    },
    Section {
        name: "experiment",
        required: true,
        fields: &[
            req("kind", Choice(&["coriolis", "rotating"])),
            req("rates_dps", Numbers),
            opt("settle_s", Number),
            req("average_s", Number),
            opt("window", Choice(&["boxcar", "hann"])),
            opt("rate_table", Choice(&["constant", "sinusoid"])),
            opt("table_freq_hz", Number),
        ],
    },
    Section {
        name: "dump",
        required: false,
        fields: &[
            opt("rate_dps", Number),
            opt("start_s", Number),
            opt("duration_s", Number),
            opt("nodes", Names),
        ],
    },
    Section {
        name: "noise",
        required: false,
        fields: &[
            opt("seed", SEED),
            opt("temperature_k", Number),
            opt("effective_mass_kg", Number),
            opt("tia_current_noise_a_per_rthz", Number),
            opt("tia_voltage_noise_v_per_rthz", Number),
            opt("tia_voltage_flicker_corner_hz", Number),
            opt("drive_amplitude_flicker_per_rthz", Number),
            opt("drive_phase_flicker_rad_per_rthz", Number),
            opt("carrier_phase_flicker_rad_per_rthz", Number),
            opt("flicker_f_lo_hz", Number),
        ],
    },
    Section {
        name: "selfcal",
        required: false,
        fields: &[
            opt("allan_record_s", Number),
            opt("tau_max_s", Number),
            opt("drift_delta_t_k", Numbers),
            opt("f0_tc_ppm_per_k", Number),
            opt("q_tc_ppm_per_k", Number),
        ],
    },
    Section {
        name: "sweep",
        required: false,
        fields: &[
            opt("start_hz", Number),
            opt("stop_hz", Number),
            opt("points", count_in(SWEEP_POINTS)),
            opt("spacing", Choice(&["resonance", "linear", "log"])),
            opt("settle_s", Number),
            opt("average_s", Number),
        ],
    },
    Section {
        name: "pll",
        required: false,
        fields: &[
            opt("natural_hz", Number),
            opt("damping", Number),
            opt("lock_s", Number),
            opt("mode", count_in(PLL_MODE)),
        ],
    },
    Section {
        name: "montecarlo",
        required: false,
        fields: &[
            opt("seed", SEED),
            opt("distribution", Choice(&["normal", "uniform"])),
            opt("truncate_sigma", Number),
            opt("mode_split_sigma_hz", Number),
            opt("q_sigma_rel", Number),
            opt("q_mismatch_sigma_rel", Number),
            opt("drive_gain_sigma_rel", Number),
            opt("phase_shifter_sigma_deg", Number),
            opt("lambda_sigma_rel", Number),
            req("spec_abs_relative_error", Number),
        ],
    },
];

/// `` `a` ``, `` `a` or `b` ``, `` one of `a`, `b`, `c` `` (what follows "expected").
pub(crate) fn one_of(names: &[&str], quote: &str) -> String {
    let q: Vec<String> = names.iter().map(|n| format!("{quote}{n}{quote}")).collect();
    match q.as_slice() {
        [a] => a.clone(),
        [a, b] => format!("{a} or {b}"),
        _ => format!("one of {}", q.join(", ")),
    }
}

/// The known name closest to a misspelt one (two edits at most, or one a prefix of the
/// other), to suggest.
pub(crate) fn closest<'a>(name: &str, known: &[&'a str]) -> Option<&'a str> {
    known
        .iter()
        .map(|k| {
            let d = if k.starts_with(name) || name.starts_with(k) {
                1
            } else {
                edit_distance(name, k)
            };
            (d, *k)
        })
        .filter(|&(d, _)| d <= 2)
        .min_by_key(|&(d, _)| d)
        .map(|(_, k)| k)
}

/// Levenshtein distance (insertions, deletions, substitutions), by characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diag = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let next = (diag + usize::from(ca != cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            diag = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance_is_levenshtein() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("f0_hzz", "f0_hz"), 1);
        assert_eq!(edit_distance("temprature_k", "temperature_k"), 1);
        assert_eq!(
            closest("decimaton", &["decimation", "lpf_order"]),
            Some("decimation")
        );
        assert_eq!(
            closest("average", &["average_s", "kind"]),
            Some("average_s")
        );
        assert_eq!(closest("xyz", &["f1", "f2"]), None);
    }

    #[test]
    fn lists_read_as_english() {
        assert_eq!(one_of(&["f1"], "`"), "`f1`");
        assert_eq!(one_of(&["f1", "f2"], "`"), "`f1` or `f2`");
        assert_eq!(one_of(&["a", "b", "c"], "\""), "one of \"a\", \"b\", \"c\"");
    }
}
