//! The check both targets make on a config text: parsing and validation never panic, and a
//! config that validates survives a TOML round trip unchanged.

use gyroemu_config::parse_config;

pub fn check(text: &str) {
    let Ok(cfg) = parse_config(text) else {
        return;
    };
    if cfg.validate().is_ok() {
        let again = toml::to_string(&cfg).expect("a valid config serialises");
        let back = parse_config(&again)
            .unwrap_or_else(|e| panic!("its own TOML does not parse: {e}\n{again}"));
        assert_eq!(back, cfg, "round trip changed the config:\n{again}");
    }
}
