//! A rate table whose swing takes a mode's velocity envelope around zero: the config rule that
//! refuses it before any sample agrees with the emulation on where that starts, and a run past
//! the rule says why it has no phase (it had blamed an overflow).

mod common;

use common::finished;
use gyroemu_config::{presets::preset, Config};

/// The rate-table preset with mode 2 split 1.5 Hz from the carrier (seven half-bandwidths)
/// and driven at half of mode 1's force: the Coriolis part coupled in from mode 1 outweighs
/// mode 2's own response at the swing's peaks from about 20 deg/s on.
fn split(rates: &[f64]) -> Config {
    let mut c = preset("m2tfg-ratetable").unwrap();
    c.device.mode2_f0_offset_hz = 1.5;
    c.drive.f2 = Some(0.5);
    c.experiment.average_s = 1.0;
    c.experiment.rates_dps = rates.to_vec();
    c
}

/// Whether the exact steady state of mode 2 winds at `rate` (deg/s).
fn winds(rate: f64) -> bool {
    let c = split(&[rate]);
    let freq = c.experiment.table_freq_hz.unwrap();
    let (amp, _) = c
        .driven_device()
        .rate_table_response(rate.to_radians(), freq);
    amp[1].is_nan()
}

#[test]
fn the_rule_refuses_where_the_emulated_envelope_winds_and_the_run_says_so() {
    // The onset by bisection on the exact steady state, then one point 2 % each side of it.
    let (mut lo, mut hi) = (1.0, 100.0);
    assert!(!winds(lo) && winds(hi));
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if winds(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let (below, above) = (0.98 * lo, 1.02 * hi);

    // The rule: the point below runs, the point above is refused before any sample, named.
    split(&[below]).validate().unwrap();
    let err = split(&[below, above]).validate().unwrap_err().to_string();
    assert!(
        err.contains("experiment.rates_dps") && err.contains(&format!("{above}")),
        "{err}"
    );
    assert!(
        err.contains("mode 2") && err.contains("around zero"),
        "{err}"
    );

    // The emulation, past the rule: below, mode 2 reads its theory; above, its envelope went
    // around zero in the emulated run too, and the problem says so, not an overflow.
    let cfg = split(&[below, above]);
    let res = finished(&cfg);
    let [b, a] = &res.points[..] else {
        panic!("two points")
    };
    assert!(
        (b.phase_deg[1] - b.theory_deg[1]).abs() < 1e-3 * b.theory_deg[1].abs(),
        "below the onset mode 2 reads {} deg against {} deg",
        b.phase_deg[1],
        b.theory_deg[1]
    );
    assert!(a.phase_deg[1].is_nan() && a.phase_deg[0].is_finite());
    let p: Vec<_> = res
        .problems
        .iter()
        .filter(|p| p.contains("mode 2"))
        .collect();
    assert_eq!(p.len(), 1, "{:?}", res.problems);
    assert!(
        p[0].contains(&format!("point {above} deg/s"))
            && p[0].contains("went around zero")
            && !p[0].contains("overflow"),
        "{}",
        p[0]
    );
}
