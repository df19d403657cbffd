//! Arbitrary bytes as a config: parsing and validation must never panic, and a config that
//! validates must survive a TOML round trip unchanged.

#![no_main]

use gyroemu_experiment::parse_config;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // The CLI refuses non-UTF-8 files before parsing; lossy decoding still exercises the
    // parser on the rest of the bytes.
    let text = String::from_utf8_lossy(data);
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
