//! Malformed configs, each one edit away from a valid preset: parsing or validation refuses
//! it with a message that names the key, shows the bad value, states the rule, and (for a
//! TOML error) gives the line and column; the soft rules validate with a warning instead.
//! One edit is one problem (no follow-on errors); a file with several problems gets them all
//! in one message; no message speaks Rust (`usize`, `f64`, ...).

use gyroemu_config::presets::preset_text;
use gyroemu_config::{parse_config, ConfigError};

const C: &str = "m2tfg-coriolis";
const R: &str = "m2tfg-rotating";
const T: &str = "m2tfg-ratetable";
const M: &str = "m2tfg-montecarlo";
const S: &str = "m2tfg-sweep";

/// How the edited config must fail.
#[derive(Debug)]
enum Expect {
    /// Parsing refuses it at this 1-based line.
    ParseAt(usize),
    /// Parsing refuses it where no line is to blame (a missing section): no location.
    Parse,
    /// It parses, `validate()` refuses it.
    Invalid,
    /// It parses and validates, with a warning.
    Warning,
}

/// One edited config.
struct Case {
    what: &'static str,
    text: String,
    expect: Expect,
    /// The first needle is the (first) problem's key, exactly (unless it has none).
    needles: Vec<&'static str>,
    /// How many problems the message lists (one edit: one problem).
    problems: usize,
}

impl Case {
    fn problems(self, problems: usize) -> Self {
        Self { problems, ..self }
    }
}

fn base(name: &str) -> String {
    preset_text(name).unwrap().to_string()
}

/// The 0-based index of the header line `[section]` and the end of that section.
fn section_range(lines: &[&str], section: &str) -> Option<(usize, usize)> {
    let head = format!("[{section}]");
    let start = lines
        .iter()
        .position(|l| l.trim_start().starts_with(&head))?;
    let end = lines[start + 1..]
        .iter()
        .position(|l| l.trim_start().starts_with('['))
        .map_or(lines.len(), |i| start + 1 + i);
    Some((start, end))
}

fn key_of(line: &str) -> Option<&str> {
    let l = line.trim_start();
    if l.starts_with('#') {
        return None;
    }
    l.split_once('=').map(|(k, _)| k.trim())
}

/// Sets `key = value` in `[section]` (replacing the key's line, or inserting it right after
/// the header; a missing section is appended). Returns the text and the 1-based line.
fn set(text: &str, section: &str, key: &str, value: &str) -> (String, usize) {
    let mut lines: Vec<&str> = text.lines().collect();
    let new = format!("{key} = {value}");
    let Some((start, end)) = section_range(&lines, section) else {
        let t = format!("{text}\n[{section}]\n{new}\n");
        let n = t.lines().count();
        return (t, n);
    };
    let at = match (start + 1..end).find(|&i| key_of(lines[i]) == Some(key)) {
        Some(i) => {
            lines[i] = &new;
            i
        }
        None => {
            lines.insert(start + 1, &new);
            start + 1
        }
    };
    (lines.join("\n") + "\n", at + 1)
}

/// Renames `key` in `[section]` (a misspelling); returns the text and the 1-based line.
fn rename(text: &str, section: &str, key: &str, to: &str) -> (String, usize) {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let refs: Vec<&str> = lines.iter().map(String::as_str).collect();
    let (start, end) = section_range(&refs, section).expect("section");
    let i = (start + 1..end)
        .find(|&i| key_of(&lines[i]) == Some(key))
        .expect("key");
    lines[i] = lines[i].replacen(key, to, 1);
    (lines.join("\n") + "\n", i + 1)
}

/// Removes `key` from `[section]`.
fn remove(text: &str, section: &str, key: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let (start, end) = section_range(&lines, section).expect("section");
    let i = (start + 1..end)
        .find(|&i| key_of(lines[i]) == Some(key))
        .expect("key");
    let mut lines = lines;
    lines.remove(i);
    lines.join("\n") + "\n"
}

/// The 1-based line of the header `[section]`.
fn header_line(text: &str, section: &str) -> usize {
    let lines: Vec<&str> = text.lines().collect();
    section_range(&lines, section).expect("section").0 + 1
}

/// `text` without `key` of `[section]`, refused at the section's header.
fn missing(text: &str, section: &str, key: &str) -> (String, usize) {
    (remove(text, section, key), header_line(text, section))
}

/// Removes the whole `[section]`.
fn remove_section(text: &str, section: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let (start, end) = section_range(&lines, section).expect("section");
    let mut lines = lines;
    lines.drain(start..end);
    lines.join("\n") + "\n"
}

/// A valid dump for the Coriolis preset (rate 100 deg/s is emulated).
const DUMP: &str = "\n[dump]\nrate_dps = 100.0\nstart_s = 0.5\nduration_s = 0.002\nnodes = [\"tia\", \"stage2\"]\n";

fn with(text: String, extra: &str) -> String {
    text + extra
}

fn parse_case(what: &'static str, (text, line): (String, usize), needles: &[&'static str]) -> Case {
    Case {
        what,
        text,
        expect: Expect::ParseAt(line),
        needles: needles.to_vec(),
        problems: 1,
    }
}

fn case(what: &'static str, text: String, expect: Expect, needles: &[&'static str]) -> Case {
    Case {
        what,
        text,
        expect,
        needles: needles.to_vec(),
        problems: 1,
    }
}

fn invalid(what: &'static str, (text, _): (String, usize), needles: &[&'static str]) -> Case {
    case(what, text, Expect::Invalid, needles)
}

/// `text` at sample rate `fs` just above 2 f0, with the decimation and TIA pole that rate
/// allows (the 200 Hz low-pass stays below the decimated Nyquist rate).
fn near_nyquist(text: &str, fs: &str) -> String {
    let t = set(text, "board", "fs_hz", fs).0;
    let t = set(&t, "board", "decimation", "10").0;
    set(&t, "board", "tia_pole_hz", "10000.0").0
}

fn cases() -> Vec<Case> {
    use Expect::*;
    let c = base(C);
    let r = base(R);
    let t = base(T);
    let noise = with(
        c.clone(),
        "\n[noise]\ntemperature_k = 300.0\neffective_mass_kg = 1e-9\n",
    );
    let selfcal = with(
        c.clone(),
        "\n[selfcal]\ntau_max_s = 10.0\ndrift_delta_t_k = [10.0]\n",
    );
    let dumped = with(c.clone(), DUMP);
    let m = base(M);
    let sw = base(S);
    vec![
        // Unknown or misspelt keys, in every section.
        parse_case(
            "misspelt device key",
            rename(&c, "device", "f0_hz", "f0_hzz"),
            &[
                "device.f0_hzz",
                "unknown key",
                "did you mean `f0_hz`?",
                "expected one of",
                "`quadrature_coupling_rad2_s2`",
            ],
        ),
        parse_case(
            "unknown drive key",
            set(&c, "drive", "f3", "1.0"),
            &[
                "drive.f3",
                "unknown key",
                "expected one of `f1`, `f2`, `carrier_hz`",
            ],
        ),
        parse_case(
            "misspelt board key",
            rename(&c, "board", "decimation", "decimaton"),
            &[
                "board.decimaton",
                "unknown key",
                "did you mean `decimation`?",
            ],
        ),
        parse_case(
            "unknown experiment key",
            set(&c, "experiment", "average", "2.0"),
            &[
                "experiment.average",
                "unknown key",
                "did you mean `average_s`?",
            ],
        ),
        parse_case(
            "misspelt noise key",
            set(&noise, "noise", "temprature_k", "300.0"),
            &[
                "noise.temprature_k",
                "unknown key",
                "did you mean `temperature_k`?",
            ],
        ),
        parse_case(
            "misspelt selfcal key",
            set(&selfcal, "selfcal", "tau_max", "10.0"),
            &[
                "selfcal.tau_max",
                "unknown key",
                "did you mean `tau_max_s`?",
            ],
        ),
        parse_case(
            "unknown dump key",
            set(&dumped, "dump", "window_s", "1.0"),
            &["dump.window_s", "unknown key", "`duration_s`"],
        ),
        parse_case(
            "unknown section",
            {
                // Reported at the appended header, one line above its key.
                let (t, line) = set(&c, "devices", "f0_hz", "1.0");
                (t, line - 1)
            },
            &[
                "devices",
                "unknown key",
                "did you mean `device`?",
                "`experiment`",
            ],
        ),
        // Wrong types.
        parse_case(
            "string for a number",
            set(&c, "device", "q", "\"high\""),
            &["device.q", "= \"high\"", "expected a number"],
        ),
        parse_case(
            "float for an integer",
            set(&c, "board", "decimation", "100.5"),
            &[
                "board.decimation",
                "= 100.5",
                "expected a non-negative integer",
            ],
        ),
        parse_case(
            "negative for usize",
            set(&c, "board", "lpf_order", "-4"),
            &["board.lpf_order", "= -4", "expected an integer from 1 to 8"],
        ),
        parse_case(
            "negative seed",
            set(&noise, "noise", "seed", "-1"),
            &["noise.seed", "= -1", "expected a non-negative integer"],
        ),
        parse_case(
            "integer for a bool",
            set(&c, "board", "tia_inverting", "1"),
            &["board.tia_inverting", "= 1", "expected true or false"],
        ),
        parse_case(
            "number for a list",
            set(&c, "experiment", "rates_dps", "25.0"),
            &[
                "experiment.rates_dps",
                "= 25.0",
                "expected a list of numbers",
            ],
        ),
        parse_case(
            "string in the rate list",
            set(&c, "experiment", "rates_dps", "[25.0, \"x\"]"),
            &["experiment.rates_dps[1]", "= \"x\"", "expected a number"],
        ),
        parse_case(
            "unknown kind",
            set(&c, "experiment", "kind", "\"spinning\""),
            &[
                "experiment.kind",
                "= \"spinning\"",
                "expected \"coriolis\" or \"rotating\"",
            ],
        ),
        parse_case(
            "unknown rate table",
            set(&c, "experiment", "rate_table", "\"triangle\""),
            &[
                "experiment.rate_table",
                "= \"triangle\"",
                "expected \"constant\" or \"sinusoid\"",
            ],
        ),
        parse_case(
            "unknown window",
            set(&c, "experiment", "window", "\"flat\""),
            &[
                "experiment.window",
                "= \"flat\"",
                "expected \"boxcar\" or \"hann\"",
            ],
        ),
        parse_case(
            "negative dac_bits",
            set(&c, "board", "dac_bits", "-1"),
            &["board.dac_bits", "= -1", "expected an integer from 2 to 32"],
        ),
        parse_case(
            "float adc_bits",
            set(&c, "board", "adc_bits", "16.0"),
            &[
                "board.adc_bits",
                "= 16.0",
                "expected an integer from 2 to 32",
                "write 16 without a decimal point",
            ],
        ),
        parse_case(
            "TOML syntax: no value",
            set(&c, "device", "q", ""),
            &["device.q"],
        ),
        // Missing required keys and tables.
        parse_case(
            "missing f0_hz",
            missing(&c, "device", "f0_hz"),
            &["device.f0_hz", "is missing", "[device] requires it"],
        ),
        parse_case(
            "missing angular_gain",
            missing(&c, "device", "angular_gain"),
            &["device.angular_gain", "is missing", "[device] requires it"],
        ),
        parse_case(
            "missing f1",
            missing(&c, "drive", "f1"),
            &["drive.f1", "is missing", "[drive] requires it"],
        ),
        parse_case(
            "missing rates",
            missing(&c, "experiment", "rates_dps"),
            &[
                "experiment.rates_dps",
                "is missing",
                "[experiment] requires it",
            ],
        ),
        parse_case(
            "missing kind",
            missing(&c, "experiment", "kind"),
            &["experiment.kind", "is missing", "[experiment] requires it"],
        ),
        parse_case(
            "missing average_s",
            missing(&c, "experiment", "average_s"),
            &[
                "experiment.average_s",
                "is missing",
                "[experiment] requires it",
            ],
        ),
        // A missing section is named as itself (not as a key of the section above it), with
        // the keys it must hold.
        case(
            "missing [drive]",
            remove_section(&c, "drive"),
            Parse,
            &["drive", "the section [drive] (with f1)"],
        ),
        case(
            "missing [device] (the first section)",
            remove_section(&c, "device"),
            Parse,
            &[
                "device",
                "the section [device] (with f0_hz, q, angular_gain)",
            ],
        ),
        case(
            "missing [experiment]",
            remove_section(&c, "experiment"),
            Parse,
            &[
                "experiment",
                "the section [experiment] (with kind, rates_dps, average_s)",
            ],
        ),
        case(
            "missing [drive] in a file that starts with [device]",
            remove_section(&strip_comments(&c), "drive"),
            Parse,
            &["drive", "the section [drive]"],
        ),
        case(
            "only a comment",
            "# nothing here\n".into(),
            Parse,
            &[
                "device",
                "[device]",
                "[drive]",
                "[experiment]",
                "3 problems",
            ],
        )
        .problems(3),
        case("empty file", String::new(), Invalid, &["empty"]),
        case("blank file", " \n\t\n".into(), Invalid, &["empty"]),
        // nan, inf and -inf (TOML accepts them).
        invalid(
            "f0 nan",
            set(&c, "device", "f0_hz", "nan"),
            &["device.f0_hz", "NaN", "finite number > 0"],
        ),
        invalid(
            "q inf",
            set(&c, "device", "q", "inf"),
            &["device.q", "inf", "finite number > 0"],
        ),
        invalid(
            "lambda -inf",
            set(&c, "device", "angular_gain", "-inf"),
            &["device.angular_gain", "-inf", "finite number > 0"],
        ),
        invalid(
            "mismatch nan",
            set(&c, "device", "mode2_f0_offset_hz", "nan"),
            &["device.mode2_f0_offset_hz", "NaN", "finite"],
        ),
        invalid(
            "k12 inf",
            set(&c, "device", "quadrature_coupling_rad2_s2", "inf"),
            &["device.quadrature_coupling_rad2_s2", "inf", "finite"],
        ),
        invalid(
            "rate nan",
            set(&c, "experiment", "rates_dps", "[25.0, nan]"),
            &["experiment.rates_dps[1]", "NaN", "finite"],
        ),
        invalid(
            "phase shifter nan",
            set(&c, "board", "phase_shifter_error_deg", "nan"),
            &["board.phase_shifter_error_deg", "NaN", "(-90, 90)"],
        ),
        invalid(
            "average inf",
            set(&c, "experiment", "average_s", "inf"),
            &["experiment.average_s", "inf", "finite number > 0"],
        ),
        // Zero or negative where meaningless.
        invalid(
            "f0 zero",
            set(&c, "device", "f0_hz", "0.0"),
            &["device.f0_hz", "= 0", "> 0"],
        ),
        invalid(
            "Q zero",
            set(&c, "device", "q", "0.0"),
            &["device.q", "= 0", "> 0"],
        ),
        invalid(
            "Q negative",
            set(&c, "device", "q", "-5.0"),
            &["device.q", "-5", "> 0"],
        ),
        invalid(
            "q_mode2 zero",
            set(&c, "device", "q_mode2", "0.0"),
            &["device.q_mode2", "= 0", "> 0"],
        ),
        invalid(
            "lambda zero",
            set(&c, "device", "angular_gain", "0.0"),
            &["device.angular_gain", "= 0", "> 0"],
        ),
        invalid(
            "mode 2 below 0 Hz",
            set(&c, "device", "mode2_f0_offset_hz", "-15000.0"),
            &["device.mode2_f0_offset_hz", "-15000", "> 0"],
        ),
        invalid(
            "transduction zero",
            set(&c, "device", "transduction_a_s_per_m", "0.0"),
            &["device.transduction_a_s_per_m", "= 0", "> 0"],
        ),
        invalid(
            "F1 zero",
            set(&c, "drive", "f1", "0.0"),
            &["drive.f1", "= 0", "> 0"],
        ),
        invalid(
            "F2 negative",
            set(&c, "drive", "f2", "-1.0"),
            &["drive.f2", "-1", "> 0"],
        ),
        invalid(
            "fs negative",
            set(&c, "board", "fs_hz", "-240000.0"),
            &["board.fs_hz", "-240000", "> 0"],
        ),
        invalid(
            "TIA gain zero",
            set(&c, "board", "tia_gain_ohm", "0.0"),
            &["board.tia_gain_ohm", "= 0", "> 0"],
        ),
        invalid(
            "TIA rail zero",
            set(&c, "board", "tia_rail_v", "0.0"),
            &["board.tia_rail_v", "= 0", "> 0"],
        ),
        invalid(
            "DAC full scale zero",
            set(&c, "board", "dac_full_scale", "0.0"),
            &["board.dac_full_scale", "= 0", "> 0"],
        ),
        invalid(
            "ADC full scale negative",
            set(&c, "board", "adc_full_scale_v", "-1.0"),
            &["board.adc_full_scale_v", "-1", "> 0"],
        ),
        invalid(
            "temperature zero",
            set(&noise, "noise", "temperature_k", "0.0"),
            &["noise.temperature_k", "= 0", "> 0"],
        ),
        invalid(
            "mass negative",
            set(&noise, "noise", "effective_mass_kg", "-1e-9"),
            &["noise.effective_mass_kg", "-1e-9", "> 0"],
        ),
        // Sample rate against f0.
        invalid(
            "fs = 2 f0",
            set(&c, "board", "fs_hz", "30000.0"),
            &["board.fs_hz", "30000", "above 2*f0 = 30000 Hz"],
        ),
        invalid(
            "fs below 2 f0 of mode 2",
            set(&c, "device", "mode2_f0_offset_hz", "200000.0"),
            &["board.fs_hz", "240000", "above 2*f0 = 430000 Hz"],
        ),
        case(
            "fs near 2 f0 states the hold's error",
            near_nyquist(&c, "30300.0"),
            Warning,
            &[
                "board.fs_hz = 30300",
                "2.02 samples per carrier period",
                "mdeg",
            ],
        ),
        case(
            "fs at 2.0003 f0 is refused: the hold's images dominate",
            near_nyquist(&c, "30004.0"),
            Invalid,
            &["board.fs_hz", "30004", "zero-order hold", "raise fs_hz"],
        ),
        // Signals that would overflow or underflow, a plant that is unstable.
        invalid(
            "drive that overflows",
            set(&c, "drive", "f1", "1e120"),
            &["drive.f1", "1e120", "overflow"],
        ),
        invalid(
            "drive that underflows",
            set(&c, "drive", "f2", "1e-120"),
            &["drive.f2", "1e-120", "underflow", "mode 2"],
        ),
        invalid(
            "TIA gain that overflows",
            set(&c, "board", "tia_gain_ohm", "1e110"),
            &["board.tia_gain_ohm", "1e110", "TIA output", "overflow"],
        ),
        invalid(
            "coupling that makes the plant unstable",
            set(&c, "device", "quadrature_coupling_rad2_s2", "1e10"),
            &[
                "device.quadrature_coupling_rad2_s2",
                "10000000000",
                "unstable",
            ],
        ),
        // Converters that would be dead, or clip.
        invalid(
            "drive below half a DAC LSB",
            set(&set(&c, "board", "dac_bits", "8").0, "drive", "f1", "1e-3"),
            &[
                "drive.f1",
                "0.001",
                // Half of 1.0 / 2^7, the full scale over half the codes (it had printed the
                // whole LSB as half of one).
                "half an LSB of the DAC (3.90625e-3;",
                "board.dac_bits",
            ],
        ),
        case(
            "drive beyond the DAC's range warns",
            set(
                &set(&c, "board", "dac_bits", "12").0,
                "board",
                "dac_full_scale",
                "0.5",
            )
            .0,
            Warning,
            &["drive.f1 = 1", "clip", "board.dac_full_scale"],
        ),
        invalid(
            "TIA output far below an ADC LSB",
            set(
                &set(&c, "board", "adc_bits", "8").0,
                "board",
                "adc_full_scale_v",
                "100.0",
            ),
            &[
                "board.adc_bits",
                "= 8",
                "half an LSB",
                "board.adc_full_scale_v",
            ],
        ),
        case(
            "TIA output beyond the ADC's range warns",
            set(
                &set(&c, "board", "adc_bits", "12").0,
                "board",
                "adc_full_scale_v",
                "0.01",
            )
            .0,
            Warning,
            &["ADC's range", "board.adc_full_scale_v"],
        ),
        case(
            "TIA output beyond its rails warns",
            set(&c, "board", "tia_rail_v", "0.01").0,
            Warning,
            &["board.tia_rail_v = 0.01", "saturate"],
        ),
        // Orders, factors and cutoffs.
        invalid(
            "decimation 0",
            set(&c, "board", "decimation", "0"),
            &["board.decimation", "= 0", "integer >= 1"],
        ),
        invalid(
            "lpf_order 0",
            set(&c, "board", "lpf_order", "0"),
            &["board.lpf_order", "= 0", "1 to 8"],
        ),
        invalid(
            "lpf_order 9",
            set(&c, "board", "lpf_order", "9"),
            &["board.lpf_order", "= 9", "1 to 8"],
        ),
        invalid(
            "TIA pole at Nyquist",
            set(&c, "board", "tia_pole_hz", "120000.0"),
            &[
                "board.tia_pole_hz",
                "120000",
                "below Nyquist (fs_hz/2 = 120000 Hz)",
            ],
        ),
        invalid(
            "TIA pole above Nyquist",
            set(&c, "board", "tia_pole_hz", "200000.0"),
            &[
                "board.tia_pole_hz",
                "200000",
                "below Nyquist (fs_hz/2 = 120000 Hz)",
            ],
        ),
        invalid(
            "TIA pole zero",
            set(&c, "board", "tia_pole_hz", "0.0"),
            &["board.tia_pole_hz", "= 0", "> 0"],
        ),
        invalid(
            "cutoff at output Nyquist",
            set(&c, "board", "lpf_cutoff_hz", "1200.0"),
            &[
                "board.lpf_cutoff_hz",
                "1200",
                "fs_hz/decimation/2 = 1200 Hz",
            ],
        ),
        invalid(
            "cutoff zero",
            set(&c, "board", "lpf_cutoff_hz", "0.0"),
            &["board.lpf_cutoff_hz", "= 0", "> 0"],
        ),
        invalid(
            "cutoff above f0",
            set(
                &set(&c, "board", "decimation", "1").0,
                "board",
                "lpf_cutoff_hz",
                "20000.0",
            ),
            &["board.lpf_cutoff_hz", "20000", "below f0_hz"],
        ),
        invalid(
            "cutoff f64 cannot realise",
            set(&c, "board", "lpf_cutoff_hz", "1e-7"),
            &[
                "board.lpf_cutoff_hz",
                "1e-7",
                "cannot be built",
                "unit circle",
            ],
        ),
        // Averaging and settling.
        invalid(
            "average below one output period",
            set(&c, "experiment", "average_s", "0.0001"),
            &[
                "experiment.average_s",
                "0.0001",
                "one output sample period (0.0004166",
            ],
        ),
        invalid(
            "average zero",
            set(&c, "experiment", "average_s", "0.0"),
            &["experiment.average_s", "= 0", "> 0"],
        ),
        invalid(
            "average below half a modulation period",
            set(&r, "experiment", "average_s", "3.0"),
            &[
                "experiment.average_s",
                "= 3",
                "half a modulation period",
                "25 deg/s: 7.2 s",
            ],
        ),
        invalid(
            "run longer than 2^53 samples",
            set(&c, "experiment", "average_s", "1e12"),
            &["experiment.average_s", "1000000000000", "2^53"],
        ),
        invalid(
            "settle negative",
            set(&c, "experiment", "settle_s", "-1.0"),
            &["experiment.settle_s", "-1", ">= 0"],
        ),
        case(
            "settle below the mechanical time constants warns",
            set(&c, "experiment", "settle_s", "0.01").0,
            Warning,
            &["experiment.settle_s", "0.01", "plant's start-up", "mdeg"],
        ),
        invalid(
            "rotating rate above the cutoff",
            set(&r, "experiment", "rates_dps", "[25.0, 1e5]"),
            &[
                "experiment.rates_dps[1]",
                "100000",
                "below board.lpf_cutoff_hz = 200 Hz",
            ],
        ),
        // Rates and the rate table.
        invalid(
            "rates empty",
            set(&c, "experiment", "rates_dps", "[]"),
            &["experiment.rates_dps", "[]", "at least one rate"],
        ),
        invalid(
            "sinusoid without table_freq_hz",
            (remove(&t, "experiment", "table_freq_hz"), 0),
            &["experiment.table_freq_hz", "(missing)", "required"],
        ),
        invalid(
            "a negative table amplitude",
            set(&t, "experiment", "rates_dps", "[25.0, -175.0]"),
            &[
                "experiment.rates_dps",
                "-175",
                "must be > 0",
                "lag 180 deg on",
            ],
        ),
        invalid(
            "a zero table amplitude",
            set(&t, "experiment", "rates_dps", "[0.0, 25.0]"),
            &["experiment.rates_dps", "= 0", "no swing and no lag"],
        ),
        invalid(
            "table_freq_hz with a constant table",
            set(&c, "experiment", "table_freq_hz", "2.0"),
            &["experiment.table_freq_hz", "= 2", "only applies"],
        ),
        invalid(
            "rate table in a rotating run",
            set(&r, "experiment", "rate_table", "\"sinusoid\""),
            &["experiment.rate_table", "sinusoid", "coriolis"],
        ),
        invalid(
            "table frequency above the cutoff",
            set(&t, "experiment", "table_freq_hz", "300.0"),
            &[
                "experiment.table_freq_hz",
                "300",
                "below board.lpf_cutoff_hz = 200 Hz",
            ],
        ),
        invalid(
            "table frequency zero",
            set(&t, "experiment", "table_freq_hz", "0.0"),
            &["experiment.table_freq_hz", "= 0", "> 0"],
        ),
        invalid(
            "average below a table period",
            set(&t, "experiment", "average_s", "0.3"),
            &[
                "experiment.average_s",
                "0.3",
                "one rate-table period (0.5 s)",
            ],
        ),
        // Converter resolutions.
        invalid(
            "dac_bits 1",
            set(&c, "board", "dac_bits", "1"),
            &["board.dac_bits", "= 1", "2 to 32"],
        ),
        invalid(
            "dac_bits 33",
            set(&c, "board", "dac_bits", "33"),
            &["board.dac_bits", "= 33", "2 to 32"],
        ),
        invalid(
            "adc_bits 0",
            set(&c, "board", "adc_bits", "0"),
            &["board.adc_bits", "= 0", "2 to 32"],
        ),
        invalid(
            "adc_bits 64",
            set(&c, "board", "adc_bits", "64"),
            &["board.adc_bits", "= 64", "2 to 32"],
        ),
        // Noise densities.
        invalid(
            "current noise negative",
            set(&noise, "noise", "tia_current_noise_a_per_rthz", "-1e-12"),
            &["noise.tia_current_noise_a_per_rthz", "-1e-12", ">= 0"],
        ),
        invalid(
            "voltage noise nan",
            set(&noise, "noise", "tia_voltage_noise_v_per_rthz", "nan"),
            &["noise.tia_voltage_noise_v_per_rthz", "NaN", ">= 0"],
        ),
        // Each flicker level by its own key (one list serves the config and the board).
        invalid(
            "tia flicker corner negative",
            set(&noise, "noise", "tia_voltage_flicker_corner_hz", "-1.0"),
            &["noise.tia_voltage_flicker_corner_hz", "= -1", ">= 0"],
        ),
        invalid(
            "drive amplitude flicker negative",
            set(&noise, "noise", "drive_amplitude_flicker_per_rthz", "-2e-5"),
            &["noise.drive_amplitude_flicker_per_rthz", "-0.00002", ">= 0"],
        ),
        invalid(
            "drive phase flicker nan",
            set(&noise, "noise", "drive_phase_flicker_rad_per_rthz", "nan"),
            &["noise.drive_phase_flicker_rad_per_rthz", "NaN", ">= 0"],
        ),
        invalid(
            "carrier phase flicker negative",
            set(
                &noise,
                "noise",
                "carrier_phase_flicker_rad_per_rthz",
                "-3e-5",
            ),
            &[
                "noise.carrier_phase_flicker_rad_per_rthz",
                "-0.00003",
                ">= 0",
            ],
        ),
        // A level whose density (its square) overflows, refused by its key before the board
        // is built (the board refused it, unnamed, after validation had passed).
        invalid(
            "drive phase flicker density overflows",
            set(&noise, "noise", "drive_phase_flicker_rad_per_rthz", "1e200"),
            &[
                "noise.drive_phase_flicker_rad_per_rthz",
                "1e200",
                "density at 1 Hz of inf",
            ],
        ),
        invalid(
            "tia flicker density overflows",
            set(
                &set(&noise, "noise", "tia_voltage_flicker_corner_hz", "1000.0").0,
                "noise",
                "tia_voltage_noise_v_per_rthz",
                "1e160",
            ),
            &[
                "noise.tia_voltage_noise_v_per_rthz",
                "1e160",
                "tia_voltage_flicker_corner_hz",
            ],
        ),
        case(
            "noise section with no source warns",
            with(c.clone(), "\n[noise]\nseed = 3\n"),
            Warning,
            &["[noise]", "noiseless"],
        ),
        // Self-calibration keys.
        invalid(
            "allan record too short",
            set(&selfcal, "selfcal", "allan_record_s", "5.0"),
            &["selfcal.allan_record_s", "= 5", "from 10 s"],
        ),
        invalid(
            "tau_max below 2 s",
            set(&selfcal, "selfcal", "tau_max_s", "1.0"),
            &["selfcal.tau_max_s", "= 1", "from 2 s"],
        ),
        invalid(
            "drift offset out of range",
            set(&selfcal, "selfcal", "drift_delta_t_k", "[10.0, 500.0]"),
            &["selfcal.drift_delta_t_k[1]", "500", "-200..200 K"],
        ),
        invalid(
            "f0 coefficient out of range",
            set(&selfcal, "selfcal", "f0_tc_ppm_per_k", "2e4"),
            &["selfcal.f0_tc_ppm_per_k", "20000", "below 1e4"],
        ),
        invalid(
            "f0 coefficient at the excluded bound",
            set(&selfcal, "selfcal", "f0_tc_ppm_per_k", "1e4"),
            &["selfcal.f0_tc_ppm_per_k", "10000", "magnitude below 1e4"],
        ),
        invalid(
            "Q coefficient nan",
            set(&selfcal, "selfcal", "q_tc_ppm_per_k", "nan"),
            &["selfcal.q_tc_ppm_per_k", "NaN", "below 1e5"],
        ),
        invalid(
            "Q coefficient drives Q negative",
            set(
                &set(&selfcal, "selfcal", "q_tc_ppm_per_k", "-9e4").0,
                "selfcal",
                "drift_delta_t_k",
                "[20.0]",
            ),
            &["selfcal.drift_delta_t_k[0]", "20", "keep Q and f0 > 0"],
        ),
        // Monte Carlo keys.
        parse_case(
            "misspelt montecarlo key",
            rename(&m, "montecarlo", "q_sigma_rel", "q_sigma"),
            &[
                "montecarlo.q_sigma",
                "unknown key",
                "did you mean `q_sigma_rel`?",
            ],
        ),
        parse_case(
            "unknown distribution",
            set(&m, "montecarlo", "distribution", "\"gauss\""),
            &["montecarlo.distribution", "\"normal\" or \"uniform\""],
        ),
        parse_case(
            "montecarlo seed negative",
            set(&m, "montecarlo", "seed", "-1"),
            &["montecarlo.seed", "-1"],
        ),
        parse_case(
            "montecarlo spec missing",
            missing(&m, "montecarlo", "spec_abs_relative_error"),
            &[
                "montecarlo.spec_abs_relative_error",
                "missing",
                "[montecarlo] requires it",
            ],
        ),
        invalid(
            "negative spread",
            set(&m, "montecarlo", "mode_split_sigma_hz", "-0.1"),
            &[
                "montecarlo.mode_split_sigma_hz",
                "-0.1",
                "a standard deviation",
            ],
        ),
        invalid(
            "spread nan",
            set(&m, "montecarlo", "phase_shifter_sigma_deg", "nan"),
            &["montecarlo.phase_shifter_sigma_deg", "NaN", ">= 0"],
        ),
        invalid(
            "spec zero",
            set(&m, "montecarlo", "spec_abs_relative_error", "0.0"),
            &["montecarlo.spec_abs_relative_error", "= 0", "> 0"],
        ),
        invalid(
            "truncation out of range",
            set(&m, "montecarlo", "truncate_sigma", "0.5"),
            &["montecarlo.truncate_sigma", "0.5", "from 1 to 8"],
        ),
        invalid(
            "Q spread reaching Q <= 0 at the truncation",
            set(&m, "montecarlo", "q_sigma_rel", "0.3"),
            &["montecarlo.q_sigma_rel", "0.3", "below 0.25", "Q <= 0"],
        ),
        invalid(
            "drive-gain spread reaching F2 <= 0 (uniform)",
            set(
                &set(&m, "montecarlo", "distribution", "\"uniform\"").0,
                "montecarlo",
                "drive_gain_sigma_rel",
                "0.6",
            ),
            &[
                "montecarlo.drive_gain_sigma_rel",
                "0.6",
                "below 0.57735 ",
                "sqrt(3)",
            ],
        ),
        invalid(
            "lambda spread reaching lambda <= 0",
            set(&m, "montecarlo", "lambda_sigma_rel", "0.25"),
            &["montecarlo.lambda_sigma_rel", "0.25", "lambda <= 0"],
        ),
        invalid(
            "Q mismatch spread reaching Q2 <= 0",
            set(&m, "montecarlo", "q_mismatch_sigma_rel", "1.0"),
            &["montecarlo.q_mismatch_sigma_rel", "Q of mode 2 <= 0"],
        ),
        invalid(
            "mode split spread reaching a mode-2 resonance <= 0",
            set(&m, "montecarlo", "mode_split_sigma_hz", "4000.0"),
            &[
                "montecarlo.mode_split_sigma_hz",
                "4000",
                "mode-2 resonance > 0",
            ],
        ),
        // Frequency-sweep keys (the sweep preset has a [sweep] section, so every command
        // judges it).
        parse_case(
            "misspelt sweep key",
            set(&sw, "sweep", "point", "61"),
            &["sweep.point", "unknown key", "did you mean `points`?"],
        ),
        parse_case(
            "unknown sweep spacing",
            set(&sw, "sweep", "spacing", "\"cubic\""),
            &[
                "sweep.spacing",
                "= \"cubic\"",
                "expected one of \"resonance\", \"linear\", \"log\"",
            ],
        ),
        invalid(
            "too few sweep points",
            set(&sw, "sweep", "points", "3"),
            &["sweep.points", "= 3", "from 5"],
        ),
        invalid(
            "sweep stop below its start",
            set(&sw, "sweep", "stop_hz", "14990.0"),
            &["sweep.stop_hz", "14990", "above sweep.start_hz"],
        ),
        invalid(
            "sweep start below the low-pass cutoff",
            set(&sw, "sweep", "start_hz", "100.0"),
            &["sweep.start_hz", "= 100", "board.lpf_cutoff_hz = 200 Hz"],
        ),
        invalid(
            "sweep stop above Nyquist",
            set(&sw, "sweep", "stop_hz", "130000.0"),
            &["sweep.stop_hz", "130000", "Nyquist"],
        ),
        invalid(
            "sweep settling negative",
            set(&sw, "sweep", "settle_s", "-1.0"),
            &["sweep.settle_s", "-1", ">= 0"],
        ),
        invalid(
            "sweep averaging zero",
            set(&sw, "sweep", "average_s", "0.0"),
            &["sweep.average_s", "= 0", "> 0"],
        ),
        case(
            "short sweep settling warns",
            set(&sw, "sweep", "settle_s", "1.0").0,
            Warning,
            &["sweep.settle_s", "10.6 mechanical time constants"],
        ),
        case(
            "a sweep span missing a resonance warns",
            set(
                &set(&sw, "sweep", "start_hz", "15000.4").0,
                "sweep",
                "stop_hz",
                "15002.0",
            )
            .0,
            Warning,
            &["mode 1's resonance", "outside"],
        ),
        case(
            "a sparse sweep warns",
            set(
                &set(&sw, "sweep", "points", "5").0,
                "sweep",
                "spacing",
                "\"linear\"",
            )
            .0,
            Warning,
            &["within a half-bandwidth", "raise sweep.points"],
        ),
        // Dumps.
        invalid(
            "dump longer than the run",
            set(&dumped, "dump", "duration_s", "100.0"),
            &["dump.duration_s", "100", "within that point's run"],
        ),
        invalid(
            "dump node unknown",
            set(&dumped, "dump", "nodes", "[\"tia\", \"foo\"]"),
            &["dump.nodes[1]", "\"foo\"", "must be one of", "\"stage2\""],
        ),
        invalid(
            "dump node listed twice",
            set(&dumped, "dump", "nodes", "[\"tia\", \"lowpass\", \"tia\"]"),
            &[
                "dump.nodes[2]",
                "\"tia\"",
                "already listed as dump.nodes[0]",
            ],
        ),
        invalid(
            "dump shorter than a sample",
            set(&dumped, "dump", "duration_s", "1e-9"),
            &["dump.duration_s", "at least one full-rate sample"],
        ),
        invalid(
            "dump nodes empty",
            set(&dumped, "dump", "nodes", "[]"),
            &["dump.nodes", "[]", "at least one node"],
        ),
        invalid(
            "dump rate not emulated",
            set(&dumped, "dump", "rate_dps", "33.0"),
            &["dump.rate_dps", "33", "one of the emulated rates"],
        ),
        invalid(
            "dump start negative",
            set(&dumped, "dump", "start_s", "-1.0"),
            &["dump.start_s", "-1", ">= 0"],
        ),
        invalid(
            "dump of a huge settle",
            set(
                &set(&dumped, "experiment", "settle_s", "1e300").0,
                "dump",
                "duration_s",
                "1e299",
            ),
            &["experiment.settle_s", "1e300", "2^53"],
        )
        // The dump's own window is also far too long, whatever the run.
        .problems(2),
        // The dump's default window is sized from the point's run before validation bounds
        // it; the sizing must not wrap (or, with overflow checks, panic).
        invalid(
            "dump of a huge averaging window",
            set(&dumped, "experiment", "average_s", "1e300"),
            &["experiment.average_s", "1e300", "2^53"],
        ),
    ]
}

/// `text` without comment lines and blank lines (it then starts with its first header).
fn strip_comments(text: &str) -> String {
    text.lines()
        .filter(|l| !l.trim_start().starts_with('#') && !l.trim().is_empty())
        .map(|l| l.split(" #").next().unwrap_or(l).trim_end())
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

fn check_needles(what: &str, msg: &str, needles: &[&str]) -> Result<(), String> {
    match needles.iter().find(|n| !msg.contains(*n)) {
        Some(n) => Err(format!("{what}: `{n}` missing from: {msg}")),
        None => Ok(()),
    }
}

/// The refusal of `text`: by parsing, or else by validation.
fn refusal(text: &str) -> Option<ConfigError> {
    match parse_config(text) {
        Err(e) => Some(e),
        Ok(cfg) => cfg.validate().err(),
    }
}

/// The error names the case's key (its first needle) first, and lists as many problems as
/// the case expects, each with a key.
fn check_key_and_count(case: &Case, e: &ConfigError) -> Result<(), String> {
    let what = case.what;
    let n = e.problems().len();
    if n != case.problems {
        return Err(format!(
            "{what}: {n} problems, expected {}: {e}",
            case.problems
        ));
    }
    match &e.key {
        Some(k) if k != case.needles[0] => Err(format!(
            "{what}: key `{k}`, expected `{}`: {e}",
            case.needles[0]
        )),
        Some(_) if e.problems().iter().any(|p| p.key.is_none()) => {
            Err(format!("{what}: a problem without a key: {e}"))
        }
        _ => Ok(()),
    }
}

/// Checks one case; `Err` says what is wrong with its message.
fn check_case(case: &Case) -> Result<(), String> {
    let Case {
        what,
        text,
        expect,
        needles,
        ..
    } = case;
    match expect {
        Expect::ParseAt(_) | Expect::Parse => {
            let e: ConfigError = parse_config(text)
                .err()
                .ok_or_else(|| format!("{what}: parsed"))?;
            let msg = e.to_string();
            eprintln!("{what}: {msg}");
            match (expect, e.location.as_deref()) {
                (Expect::ParseAt(line), Some(loc)) => {
                    if !(loc.starts_with(&format!("line {line}, column "))) {
                        return Err(format!("{what}: expected line {line}: {msg}"));
                    }
                }
                (Expect::Parse, None) => {}
                _ => return Err(format!("{what}: wrong location: {msg}")),
            }
            if e.key.is_none() {
                return Err(format!("{what}: no key in {msg}"));
            }
            check_key_and_count(case, &e)?;
            check_needles(what, &msg, needles)
        }
        Expect::Invalid => {
            let e = refusal(text).ok_or_else(|| format!("{what}: validated"))?;
            eprintln!("{what}: {e}");
            check_key_and_count(case, &e)?;
            check_needles(what, &e.to_string(), needles)
        }
        Expect::Warning => {
            let cfg = parse_config(text).map_err(|e| format!("{what}: {e}"))?;
            let w = cfg
                .validate()
                .map_err(|e| format!("{what}: refused: {e}"))?;
            eprintln!("{what}: {w:?}");
            if w.iter().any(|w| needles.iter().all(|n| w.contains(n))) {
                Ok(())
            } else {
                Err(format!("{what}: no warning with {needles:?} in: {w:?}"))
            }
        }
    }
}

#[test]
fn every_malformed_config_is_refused_with_key_value_and_rule() {
    let cases = cases();
    assert!(cases.len() >= 40, "{}", cases.len());
    let parse = cases
        .iter()
        .filter(|c| matches!(c.expect, Expect::ParseAt(_) | Expect::Parse))
        .count();
    assert!(parse >= 20, "{parse}");
    let failures: Vec<String> = cases.iter().filter_map(|c| check_case(c).err()).collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn validation_errors_have_the_key_value_rule_form() {
    // `key `a.b` = value: rule` for every validate() refusal.
    for Case {
        what, text, expect, ..
    } in cases()
    {
        if let Expect::Invalid = expect {
            if let Ok(cfg) = parse_config(&text) {
                let e = cfg.validate().unwrap_err();
                let key = e.key.as_deref().unwrap_or_else(|| panic!("{what}: no key"));
                let msg = e.to_string();
                assert!(
                    msg.contains(&format!("key `{key}` = ")) && e.detail.contains(": "),
                    "{what}: {msg}"
                );
                assert!(e.location.is_none(), "{what}");
            }
        }
    }
}

#[test]
fn the_unedited_presets_and_the_edit_helpers_are_sound() {
    for name in [C, R, T, S] {
        let c = parse_config(&base(name)).unwrap();
        assert!(c.validate().is_ok(), "{name}");
        // Setting a key to its own value changes nothing.
        let (text, line) = set(&base(name), "device", "f0_hz", "15000.0");
        assert_eq!(parse_config(&text).unwrap(), c, "{name}");
        assert!(base(name)
            .lines()
            .nth(line - 1)
            .unwrap()
            .starts_with("f0_hz"));
    }
    let dumped = parse_config(&with(base(C), DUMP)).unwrap();
    assert!(dumped.validate().is_ok());
}

/// The Rust words serde would use, none of which a user should have to read.
const RUST_WORDS: [&str; 20] = [
    "usize", "isize", "u8", "u16", "u32", "u64", "u128", "i8", "i16", "i32", "i64", "i128", "f32",
    "f64", "sequence", "boolean", "floating", "variant", "struct", "field",
];

/// The Rust words in `msg` (whole words: `f0_hz` is not `f0`).
fn rust_words(msg: &str) -> Vec<&'static str> {
    let words: Vec<&str> = msg
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .collect();
    RUST_WORDS
        .into_iter()
        .filter(|w| words.contains(w))
        .collect()
}

#[test]
fn no_message_names_a_rust_type() {
    assert_eq!(rust_words("expected usize, not f0_hz or u64x"), ["usize"]);
    let mut checked = 0;
    for case in cases() {
        let msgs = match refusal(&case.text) {
            Some(e) => vec![e.to_string()],
            None => parse_config(&case.text).unwrap().validate().unwrap(),
        };
        for m in msgs {
            assert!(rust_words(&m).is_empty(), "{}: {m}", case.what);
            checked += 1;
        }
    }
    assert!(checked >= 100, "{checked}");
    // Every key of every section, set to values of every wrong kind.
    let full = with(
        with(base(T), DUMP),
        "\n[noise]\nseed = 1\n\n[selfcal]\ntau_max_s = 10.0\n",
    );
    let values = [
        "\"text\"",
        "\"1.0\"",
        "-1",
        "2.5",
        "1e400",
        "99999999999999999999",
        "4294967296",
        "true",
        "[1.0, \"x\"]",
        "[\"tia\", 3]",
        "{ a = 1 }",
        "1979-05-27",
    ];
    let doc: toml::Table = full.parse().unwrap();
    let mut refused = 0;
    for (section, table) in &doc {
        for key in table.as_table().unwrap().keys() {
            for v in values {
                let (text, line) = set(&full, section, key, v);
                let Err(e) = parse_config(&text) else {
                    continue;
                };
                let msg = e.to_string();
                assert!(rust_words(&msg).is_empty(), "{section}.{key} = {v}: {msg}");
                assert!(
                    e.key
                        .as_deref()
                        .is_some_and(|k| k.starts_with(&format!("{section}.{key}"))),
                    "{section}.{key} = {v}: {msg}"
                );
                assert!(
                    msg.contains(&format!("line {line}, column ")),
                    "{section}.{key} = {v}: {msg}"
                );
                refused += 1;
            }
        }
    }
    assert!(refused >= 150, "{refused}");
}

/// The keys of an error's problems, in order.
fn keys(e: &ConfigError) -> Vec<String> {
    e.problems()
        .into_iter()
        .map(|p| p.key.unwrap_or_default())
        .collect()
}

#[test]
fn a_file_with_several_bad_keys_gets_every_one_in_one_message() {
    // Parsing: a wrong type, a misspelt key, a missing key and a negative count, in four
    // sections; each is its own line with the key, the value and the rule, in file order.
    let c = base(C);
    let (t, l_q) = set(&c, "device", "q", "\"high\"");
    let (t, l_f3) = set(&t, "drive", "f3", "1.0");
    let (t, l_order) = set(&t, "board", "lpf_order", "-4");
    let l_exp = header_line(&t, "experiment");
    let t = remove(&t, "experiment", "average_s");
    let e = parse_config(&t).unwrap_err();
    assert_eq!(
        keys(&e),
        [
            "device.q",
            "drive.f3",
            "board.lpf_order",
            "experiment.average_s"
        ]
    );
    let lines: Vec<usize> = e
        .problems()
        .iter()
        .map(|p| {
            let loc = p.location.as_deref().unwrap();
            loc["line ".len()..loc.find(',').unwrap()].parse().unwrap()
        })
        .collect();
    assert_eq!(lines, [l_q, l_f3, l_order, l_exp]);
    let msg = e.to_string();
    let body: Vec<&str> = msg.lines().collect();
    assert_eq!(body[0], "config error: 4 problems:", "{msg}");
    for (line, needles) in body[1..].iter().zip([
        &["device.q", "= \"high\"", "expected a number"][..],
        &[
            "drive.f3",
            "unknown key",
            "expected one of `f1`, `f2`, `carrier_hz`",
        ],
        &["board.lpf_order", "= -4", "an integer from 1 to 8"],
        &["experiment.average_s", "is missing"],
    ]) {
        check_needles("several parse problems", line, needles).unwrap();
    }

    // Validation: three independent bad values, each reported with key, value and rule.
    let t = set(&c, "device", "q", "-5.0").0;
    let t = set(&t, "board", "tia_gain_ohm", "0.0").0;
    let t = set(&t, "experiment", "average_s", "0.0").0;
    let t = set(&t, "board", "dac_bits", "40").0;
    let e = parse_config(&t).unwrap().validate().unwrap_err();
    assert_eq!(
        keys(&e),
        [
            "device.q",
            "board.tia_gain_ohm",
            "board.dac_bits",
            "experiment.average_s"
        ]
    );
    let msg = e.to_string();
    for needles in [
        &["key `device.q` = -5: ", "> 0"][..],
        &["key `board.tia_gain_ohm` = 0: ", "> 0"],
        &["key `board.dac_bits` = 40: ", "2 to 32"],
        &["key `experiment.average_s` = 0: ", "> 0"],
    ] {
        check_needles("several invalid values", &msg, needles).unwrap();
    }
    assert_eq!(msg.lines().count(), 5, "{msg}");
}

#[test]
fn a_bad_value_brings_no_follow_on_errors_through_derived_keys() {
    // f0 = 0 with the sample rate, cutoff and decimation left to their defaults (derived from
    // f0): only f0 is reported, not the rate, cutoff or decimation computed from it; a bad
    // F1 is not repeated as the F2 derived from it.
    let mut t = strip_comments(&base(C));
    for key in ["fs_hz", "lpf_cutoff_hz", "decimation", "tia_pole_hz"] {
        t = remove(&t, "board", key);
    }
    let t = remove(&t, "drive", "f2");
    let cfg = parse_config(&t).unwrap();
    assert!(cfg.validate().is_ok());
    let t0 = set(&t, "device", "f0_hz", "0.0").0;
    let e = parse_config(&t0).unwrap().validate().unwrap_err();
    assert_eq!(keys(&e), ["device.f0_hz"], "{e}");
    let t1 = set(&t, "drive", "f1", "-1.0").0;
    let e = parse_config(&t1).unwrap().validate().unwrap_err();
    assert_eq!(keys(&e), ["drive.f1"], "{e}");
    // An F2 the user set is judged on its own.
    let t2 = set(&t1, "drive", "f2", "-2.0").0;
    let e = parse_config(&t2).unwrap().validate().unwrap_err();
    assert_eq!(keys(&e), ["drive.f1", "drive.f2"], "{e}");
}

#[test]
fn validation_problems_are_located_in_the_text_that_set_them() {
    let c = base(C);
    let (t, l_avg) = set(&c, "experiment", "average_s", "0.0");
    let (t, l_q) = set(&t, "device", "q", "-5.0");
    let (t, l_rate) = set(&t, "experiment", "rates_dps", "[25.0, nan]");
    let e = parse_config(&t).unwrap().validate().unwrap_err();
    assert!(e.problems().iter().all(|p| p.location.is_none()));
    let located = e.with_locations(&t);
    // In the order of the text, each at its value (the NaN is the list's second item).
    let rate_col = 1 + t.lines().nth(l_rate - 1).unwrap().find("nan").unwrap();
    let want = [
        ("device.q", format!("line {l_q}, column 5")),
        (
            "experiment.rates_dps[1]",
            format!("line {l_rate}, column {rate_col}"),
        ),
        ("experiment.average_s", format!("line {l_avg}, column 13")),
    ];
    let got: Vec<(String, String)> = located
        .problems()
        .into_iter()
        .map(|p| (p.key.unwrap(), p.location.unwrap()))
        .collect();
    let want: Vec<(String, String)> = want
        .iter()
        .map(|(k, l)| (k.to_string(), l.clone()))
        .collect();
    assert_eq!(got, want);
}

/// The refusal of `text` by validation (it must parse).
fn invalid_msg(what: &str, text: &str) -> ConfigError {
    let e = parse_config(text)
        .unwrap_or_else(|e| panic!("{what}: did not parse: {e}"))
        .validate()
        .expect_err(what);
    assert_eq!(e.problems().len(), 1, "{what}: {e}");
    e
}

#[test]
fn a_tia_pole_too_small_for_its_discretisation_is_named_with_its_bound() {
    // fs = 240 kHz: exp(-2 pi pole / fs) rounds to 1 below about 2.12e-12 Hz, and the TIA's
    // gain is exactly 0 (the node-range rule blamed tia_gain_ohm, or nothing refused it).
    let c = base(C);
    let min = gyroemu_tia::min_pole_hz(240e3);
    assert!((2.12e-12..2.13e-12).contains(&min), "{min}");
    for pole in ["1e-300", "1e-120", "1e-90", "1e-12", "2.12e-12"] {
        let t = set(&c, "board", "tia_pole_hz", pole).0;
        let e = invalid_msg(pole, &t);
        let msg = e.to_string();
        assert_eq!(e.key.as_deref(), Some("board.tia_pole_hz"), "{msg}");
        for n in [
            &format!("= {pole}: "),
            "must be at least 2.12",
            "rounds to exactly 1",
            "exactly 0",
        ] {
            assert!(msg.contains(n), "{pole}: `{n}` missing from: {msg}");
        }
    }
    // Poles that work stay valid, the smallest one included (its gain is not 0).
    for pole in [min, 1e-11, 1e-10, 60000.0] {
        let t = set(&c, "board", "tia_pole_hz", &format!("{pole:e}")).0;
        let cfg = parse_config(&t).unwrap();
        assert!(cfg.validate().is_ok(), "{pole}: {:?}", cfg.validate());
        let chain = gyroemu_board::ChainResponse::new(&cfg.board_params()).unwrap();
        assert!(chain.tia(15e3).norm() > 0.0, "{pole}");
    }
    // When the pole's attenuation is what takes the TIA output out of the node range (the
    // gain alone keeps it in), the node-range rule names the pole.
    let t = set(&c, "board", "tia_gain_ohm", "1e-85").0;
    assert!(parse_config(&t).unwrap().validate().is_ok());
    let t = set(&t, "board", "tia_pole_hz", "1e-11").0;
    let e = invalid_msg("attenuating pole", &t);
    let msg = e.to_string();
    assert_eq!(e.key.as_deref(), Some("board.tia_pole_hz"), "{msg}");
    for n in [
        "= 1e-11: ",
        "the TIA output of mode 1",
        "outside 1e-100..1e100",
        "raise board.tia_pole_hz",
    ] {
        assert!(msg.contains(n), "`{n}` missing from: {msg}");
    }
}

#[test]
fn a_dump_window_starting_past_the_run_names_its_start() {
    let c = base(C);
    let dump = |start: &str, duration: &str| {
        with(
            c.clone(),
            &format!("\n[dump]\nrate_dps = 100.0\nstart_s = {start}\nduration_s = {duration}\nnodes = [\"tia\"]\n"),
        )
    };
    let e = invalid_msg("start past the run", &dump("50.0", "0.002"));
    let msg = e.to_string();
    assert_eq!(e.key.as_deref(), Some("dump.start_s"), "{msg}");
    for n in ["= 50: ", "must start within that point's run (2.71"] {
        assert!(msg.contains(n), "`{n}` missing from: {msg}");
    }
    // A start within the run whose window ends past it: the duration, as before.
    let e = invalid_msg("window past the end", &dump("2.7", "0.2"));
    let msg = e.to_string();
    assert_eq!(e.key.as_deref(), Some("dump.duration_s"), "{msg}");
    assert!(
        msg.contains("= 0.2: the window start_s + duration_s must end within"),
        "{msg}"
    );
}

#[test]
fn a_noise_density_that_would_overflow_the_chain_is_refused_by_its_key() {
    let c = base(C);
    let noise = |lines: &str| with(c.clone(), &format!("\n[noise]\n{lines}\n"));
    // White levels, no flicker corner: no word of flicker (it said "flicker density at 1 Hz
    // of NaN" for 1e200, and nothing refused 1e155..1e199, which failed at run time).
    for (key, v) in [
        ("tia_voltage_noise_v_per_rthz", "1e200"),
        ("tia_voltage_noise_v_per_rthz", "1e160"),
        ("tia_voltage_noise_v_per_rthz", "1e155"),
        ("tia_voltage_noise_v_per_rthz", "1e100"),
        ("tia_current_noise_a_per_rthz", "1e160"),
        ("tia_current_noise_a_per_rthz", "1e100"),
    ] {
        let e = invalid_msg(v, &noise(&format!("{key} = {v}")));
        let msg = e.to_string();
        assert_eq!(e.key.as_deref(), Some(&*format!("noise.{key}")), "{msg}");
        for n in [
            &format!("= {v}: "),
            "per-sample current of standard deviation",
            "at the TIA output",
            "must stay within 1e100",
        ] {
            assert!(msg.contains(n), "{key} = {v}: `{n}` missing from: {msg}");
        }
        assert!(!msg.contains("flicker"), "{key} = {v}: {msg}");
    }
    // The Brownian force of a tiny mass, the slow flicker sources.
    for (key, v, rule) in [
        (
            "effective_mass_kg",
            "1e-230",
            "Brownian force per unit mass",
        ),
        (
            "drive_amplitude_flicker_per_rthz",
            "1e150",
            "scales the largest node's signal",
        ),
        (
            "drive_phase_flicker_rad_per_rthz",
            "1e20",
            "within which the board's sines are accurate",
        ),
        (
            "carrier_phase_flicker_rad_per_rthz",
            "1e20",
            "within which the board's sines are accurate",
        ),
    ] {
        let e = invalid_msg(v, &noise(&format!("{key} = {v}")));
        let msg = e.to_string();
        assert_eq!(e.key.as_deref(), Some(&*format!("noise.{key}")), "{msg}");
        for n in [&format!("= {v}: "), rule] {
            assert!(msg.contains(n), "{key} = {v}: `{n}` missing from: {msg}");
        }
    }
    // With a corner the TIA's flicker may be spoken of, by the key to blame.
    let e = invalid_msg(
        "corner",
        &noise("tia_voltage_noise_v_per_rthz = 1e-8\ntia_voltage_flicker_corner_hz = 1e300"),
    );
    let msg = e.to_string();
    assert_eq!(
        e.key.as_deref(),
        Some("noise.tia_voltage_flicker_corner_hz"),
        "{msg}"
    );
    assert!(
        msg.contains("= 1e300: gives the TIA's voltage flicker"),
        "{msg}"
    );
    assert!(msg.contains("must stay within 1e100"), "{msg}");
    // Levels within the range stay valid, the presets' too.
    for lines in [
        "tia_voltage_noise_v_per_rthz = 1e90",
        "tia_current_noise_a_per_rthz = 1e90",
        "tia_voltage_noise_v_per_rthz = 2e-8\ntia_current_noise_a_per_rthz = 5e-14\neffective_mass_kg = 1e-9",
    ] {
        let cfg = parse_config(&noise(lines)).unwrap();
        assert!(cfg.validate().is_ok(), "{lines}: {:?}", cfg.validate());
    }
    for name in ["m2tfg-selfcal", M] {
        let cfg = parse_config(&base(name)).unwrap();
        assert!(cfg.validate().is_ok(), "{name}: {:?}", cfg.validate());
    }
}

#[test]
fn integers_are_echoed_as_written_and_too_large_ones_say_their_bound() {
    let c = base(C);
    let t = set(&c, "board", "lpf_order", "9223372036854775807").0;
    let msg = invalid_msg("lpf_order i64::MAX", &t).to_string();
    assert!(
        msg.contains("key `board.lpf_order` = 9223372036854775807: must be an integer from 1 to 8"),
        "{msg}"
    );
    let noise = with(c.clone(), "\n[noise]\nseed = 1\n");
    // Past the type's limit: the key's own range when it has one (it said "at most
    // 4294967295" for dac_bits, then 4294967295 was refused as not 2 to 32), else the limit.
    for (section, key, v, rule) in [
        (
            "board",
            "lpf_order",
            "99999999999999999999",
            "too large: must be an integer from 1 to 8",
        ),
        (
            "noise",
            "seed",
            "18446744073709551616",
            "too large: at most 18446744073709551615",
        ),
        (
            "board",
            "dac_bits",
            "4294967296",
            "too large: must be an integer from 2 to 32",
        ),
        (
            "board",
            "adc_bits",
            "0x1_0000_0000",
            "too large: must be an integer from 2 to 32",
        ),
        (
            "board",
            "decimation",
            "18446744073709551616",
            "too large: at most 18446744073709551615",
        ),
        (
            "sweep",
            "points",
            "18446744073709551616",
            "too large: must be an integer from 5 to 10000",
        ),
        (
            "pll",
            "mode",
            "99999999999999999999",
            "too large: must be 1 or 2",
        ),
    ] {
        let (t, line) = set(&noise, section, key, v);
        let e = parse_config(&t).unwrap_err();
        let msg = e.to_string();
        assert_eq!(
            e.key.as_deref(),
            Some(&*format!("{section}.{key}")),
            "{msg}"
        );
        assert!(msg.contains(&format!("line {line}, column ")), "{msg}");
        assert!(
            msg.contains(&format!("= {v}: {rule}")),
            "{section}.{key}: {msg}"
        );
    }
    // One source: the range a too-large value is told is the one validation enforces.
    for (section, key, past, big) in [
        ("board", "lpf_order", "9", "99999999999999999999"),
        ("board", "dac_bits", "33", "4294967296"),
        ("board", "adc_bits", "1", "4294967296"),
        ("sweep", "points", "10001", "99999999999999999999"),
        ("pll", "mode", "3", "99999999999999999999"),
    ] {
        let told = parse_config(&set(&noise, section, key, big).0)
            .unwrap_err()
            .to_string();
        let told = &told[told.find("too large: ").unwrap() + "too large: ".len()..];
        let cfg = parse_config(&set(&noise, section, key, past).0).unwrap();
        let e = cfg.validate().unwrap_err();
        let p = e
            .problems()
            .into_iter()
            .find(|p| p.key.as_deref() == Some(&*format!("{section}.{key}")));
        let rule = p
            .unwrap_or_else(|| panic!("{section}.{key} = {past}: {e}"))
            .detail;
        assert!(
            rule.starts_with(&format!(" = {past}: {told}")),
            "{section}.{key}: {told} vs {rule}"
        );
    }
    // A negative one is not too large: the kind of value is what is wrong.
    let t = set(&noise, "noise", "seed", "-1").0;
    let msg = parse_config(&t).unwrap_err().to_string();
    assert!(
        msg.contains("= -1: expected a non-negative integer"),
        "{msg}"
    );
}

#[test]
fn a_brownian_mass_is_refused_just_past_its_bound_with_the_formula_the_code_applies() {
    // m2tfg-selfcal: the force node binds. Its per-sample deviation
    // sqrt(4 k T w0 / (q m) x fs/2) / sinc(f0/fs) reaches 1e100 at
    // m = 4 k T w0 fs/2 / (q (1e100 sinc)^2), largest for mode 2 (lower Q). The velocity,
    // sqrt(k T / m), reaches it only at m = k T / 1e200, and current and TIA output (x 1e-6
    // A s/m, x at most 1e6 ohm) no sooner.
    let c = base("m2tfg-selfcal");
    let (k, t, fs) = (1.380_649e-23, 300.0, 240e3);
    let sinc = |x: f64| (core::f64::consts::PI * x).sin() / (core::f64::consts::PI * x);
    let bound = [(15e3, 2000.0), (15e3 + 0.02, 1950.0)]
        .map(|(f0, q): (f64, f64)| {
            let w0 = core::f64::consts::TAU * f0;
            4.0 * k * t * w0 * 0.5 * fs / (q * (1e100 * sinc(f0 / fs)).powi(2))
        })
        .into_iter()
        .fold(0.0, f64::max);
    assert!((9e-214..1e-213).contains(&bound), "{bound:e}");
    assert!(bound > 1e3 * k * t / 1e200);
    let mass = |m: f64| set(&c, "noise", "effective_mass_kg", &format!("{m:e}")).0;
    // 9.7e-211 was refused with a deviation of "inf" (m^2 rounded to 0).
    for m in [bound * (1.0 + 1e-9), 9.7e-211, 2e-162, 1e-9] {
        let cfg = parse_config(&mass(m)).unwrap();
        assert!(cfg.validate().is_ok(), "{m:e}: {:?}", cfg.validate());
    }
    for m in [bound * (1.0 - 1e-9), 1e-250, 1e-300, 5e-324] {
        let e = invalid_msg(&format!("{m:e}"), &mass(m));
        let msg = e.to_string();
        assert_eq!(e.key.as_deref(), Some("noise.effective_mass_kg"), "{msg}");
        // The first mode out of range (just past the bound only mode 2 is), and the
        // deviation its formula gives, not inf.
        let (mode, f0, q) = if msg.contains("gives mode 1 ") {
            (1, 15e3, 2000.0)
        } else {
            (2, 15e3 + 0.02, 1950.0)
        };
        assert!(mode == 2 || m < bound * 0.9, "{msg}");
        let w0 = core::f64::consts::TAU * f0;
        let want = (4.0 * k * t * w0 / (q * m)).sqrt() * (0.5 * fs).sqrt() / sinc(f0 / fs);
        for n in [
            &format!("gives mode {mode} a Brownian force per unit mass of standard deviation {want:.3e} m/s^2 per sample"),
            "sqrt(4 k temperature_k w0 / (q effective_mass_kg) x fs_hz/2) / sinc(f0/fs_hz)",
            "must stay within 1e100",
        ] {
            assert!(msg.contains(n), "{m:e}: `{n}` missing from: {msg}");
        }
        assert!(!msg.contains("inf"), "{m:e}: {msg}");
    }
}

#[test]
fn a_tia_pole_realised_off_its_value_is_warned_with_both_poles() {
    // At 240 kHz, a = exp(-2 pi p / fs) steps in units of 2^-53 below 1: a pole near the
    // minimum is realised as k 2^-53 fs / (2 pi), k = round(2 pi p / fs 2^53). It validated
    // with no word (1e-11 Hz gave 15 % less attenuation at 15 kHz than configured).
    let c = base(C);
    let fs: f64 = 240e3;
    let step = 2f64.powi(-53) * fs / core::f64::consts::TAU;
    let warnings = |pole: &str| {
        let t = set(&c, "board", "tia_pole_hz", pole).0;
        let cfg = parse_config(&t).unwrap();
        cfg.validate()
            .unwrap_or_else(|e| panic!("{pole}: {e}"))
            .into_iter()
            .filter(|w| w.contains("realises a pole"))
            .collect::<Vec<_>>()
    };
    for (pole, k) in [(2.13e-12, 1.0), (1e-11, 2.0), (1e-9, 236.0)] {
        assert_eq!(k, (pole / step).round(), "{pole}");
        let realised = k * step;
        let rel = realised / pole - 1.0;
        let w = warnings(&format!("{pole:e}"));
        assert_eq!(w.len(), 1, "{pole}: {w:?}");
        for n in [
            &format!("board.tia_pole_hz = {pole:e}: "),
            &format!("realises a pole of {realised:.6e} Hz"),
            &format!("not {pole:e} Hz: {rel:+.3e} relative"),
            "the ADC range, the rails and the noise levels",
        ] {
            assert!(w[0].contains(n), "{pole}: `{n}` missing from: {}", w[0]);
        }
    }
    // Above 2^-54 x 1e6 x fs / (2 pi) = 2.1e-6 Hz every pole is realised within 1e-6.
    for pole in ["2.2e-6", "1e-3", "60000.0", "119000.0"] {
        assert!(warnings(pole).is_empty(), "{pole}: {:?}", warnings(pole));
    }
    // The configured pole's rounding is what is weighed, not a threshold on the pole: one on
    // the grid (k = 1e5, well below that bound) is realised within 1e-6 and stays quiet.
    let exact = 1e5 * step;
    assert!(warnings(&format!("{exact:e}")).is_empty());
}

#[test]
fn a_flicker_low_corner_too_low_for_its_poles_is_refused_not_a_panic() {
    // The lowest pole's radius exp(-2 pi f_lo / fs) must stay 1000 ulps below 1:
    // f_lo >= 1000 (eps / 2) fs / (2 pi) = 4.24e-9 Hz at 240 kHz. 1e-310 made the pole count
    // infinite (a panic in validation); 1e-300 blamed other keys with NaN deviations.
    let c = base("m2tfg-selfcal");
    let min = 1000.0 * f64::EPSILON / 2.0 * 240e3 / core::f64::consts::TAU;
    assert!((4.2e-9..4.3e-9).contains(&min), "{min:e}");
    let text = |v: f64| set(&c, "noise", "flicker_f_lo_hz", &format!("{v:e}")).0;
    for v in [min * (1.0 + 1e-12), 1e-5] {
        let cfg = parse_config(&text(v)).unwrap();
        assert!(cfg.validate().is_ok(), "{v:e}: {:?}", cfg.validate());
    }
    for v in [min * (1.0 - 1e-12), 1e-200, 1e-300, 1e-310] {
        let e = invalid_msg(&format!("{v:e}"), &text(v));
        let msg = e.to_string();
        assert_eq!(e.key.as_deref(), Some("noise.flicker_f_lo_hz"), "{msg}");
        assert!(msg.contains("1000 ulps of 1"), "{msg}");
    }
}
