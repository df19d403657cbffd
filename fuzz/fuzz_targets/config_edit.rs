//! A preset with one line replaced by fuzz input: most inputs still parse, so the fuzzer
//! spends its time in the validation rules (the `config` target mostly exercises TOML
//! syntax). Same assertions: no panic, and a valid config survives a TOML round trip.

#![no_main]

use gyroemu_config::presets::PRESETS;
use libfuzzer_sys::fuzz_target;

#[path = "common/round_trip.rs"]
mod round_trip;

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
    round_trip::check(&text);
});
