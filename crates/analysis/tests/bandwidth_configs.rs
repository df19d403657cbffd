//! The bandwidth sweep's configs are validated in parallel; the error returned is the one a
//! validation in frequency order meets first.

use gyroemu_analysis::bandwidth::{bandwidth_config, bandwidth_configs, BANDWIDTH_FREQS_HZ};
use gyroemu_config::presets::preset;

#[test]
fn the_first_error_in_frequency_order_is_returned() {
    let mut found_case = false;
    for cutoff_hz in [0.5, 1.0, 2.0, 4.0] {
        let mut base = preset("m2tfg-ratetable").unwrap();
        base.board.lpf_cutoff_hz = Some(cutoff_hz);
        let each: Vec<_> = BANDWIDTH_FREQS_HZ
            .iter()
            .map(|&f| bandwidth_config(&base, f).err().map(|e| e.to_string()))
            .collect();
        let first = each.iter().flatten().next().cloned();
        let got = bandwidth_configs(&base).err().map(|e| e.to_string());
        assert_eq!(got, first, "cutoff {cutoff_hz}");
        // The case that tells an ordered reduction from any other: several errors, and
        // not all the same message.
        let distinct: std::collections::BTreeSet<_> = each.iter().flatten().collect();
        found_case |= distinct.len() >= 2;
    }
    assert!(found_case, "no cutoff gave two different errors");
}
