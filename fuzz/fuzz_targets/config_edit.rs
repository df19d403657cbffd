//! A preset with one line replaced by fuzz input: most inputs still parse, so the fuzzer
//! spends its time in the validation rules (the `config` target mostly exercises TOML
//! syntax). Same assertions: no panic, and a valid config survives a TOML round trip.

#![no_main]

use gyroemu_experiment::parse_config;
use gyroemu_experiment::presets::PRESETS;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let [which, line, rest @ ..] = data else {
        return;
    };
    let preset = PRESETS[*which as usize % PRESETS.len()].2;
    let mut lines: Vec<&str> = preset.lines().collect();
    let at = *line as usize % lines.len();
    let edit = String::from_utf8_lossy(rest);
    lines[at] = &edit;
    let text = lines.join("\n");
    let Ok(cfg) = parse_config(&text) else {
        return;
    };
    if cfg.validate().is_ok() {
        let again = toml::to_string(&cfg).expect("a valid config serialises");
        let back = parse_config(&again)
            .unwrap_or_else(|e| panic!("its own TOML does not parse: {e}\n{again}"));
        assert_eq!(back, cfg, "round trip changed the config:\n{again}");
    }
});
