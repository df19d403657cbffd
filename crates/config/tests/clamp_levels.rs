//! A clamp level (the DAC's and the ADC's full scale, the TIA's rails) must lie in the band
//! every node is held to, `NODE_RANGE`: at 1e-300 each had passed validation, run 30 to 80
//! times slower in subnormals and ended with NaN phases (exit 1), not a refusal naming it.

use gyroemu_config::{parse_config, NODE_RANGE};

fn refusal(key: &str, v: f64) -> String {
    let text = format!(
        "[device]\nf0_hz = 15000.0\nq = 2000.0\nangular_gain = 1.0\n\
         [drive]\nf1 = 1.0\nf2 = 1.0\n\
         [board]\nfs_hz = 240000.0\ntia_gain_ohm = 1e6\ndac_bits = 16\nadc_bits = 16\n{key} = {v:e}\n\
         [experiment]\nkind = \"coriolis\"\nrates_dps = [25.0]\naverage_s = 0.05\n"
    );
    match parse_config(&text).and_then(|c| c.validate().map(|_| ())) {
        Ok(()) => String::new(),
        Err(e) => e.to_string(),
    }
}

#[test]
fn levels_outside_the_node_band_are_refused_by_their_own_key() {
    let (lo, hi) = NODE_RANGE;
    for key in ["dac_full_scale", "adc_full_scale_v", "tia_rail_v"] {
        let named = format!("`board.{key}`");
        for v in [1e-300, lo / 2.0, hi * 2.0, 1e300] {
            let e = refusal(key, v);
            assert!(
                e.contains(&named) && e.contains("must lie in"),
                "{key} = {v:e}: {e}"
            );
        }
        for v in [lo, hi] {
            let e = refusal(key, v);
            // Other rules (a dead or clipping converter) may speak; this one must not.
            assert!(!e.contains("must lie in"), "{key} = {v:e}: {e}");
        }
        assert!(refusal(key, -1.0).contains("> 0"), "{key}");
    }
}
