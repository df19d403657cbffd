//! Converter and rail counts: the DAC's clipped and zero samples of a known drive against
//! their closed-form counts, and every count of a harsh board (clipping DAC, ADC and TIA
//! rails) equal to the reference board's, lane by lane.

mod common;

use common::{m2tfg, point};
use gyroemu_board::reference::run_reference;
use gyroemu_board::{Board, BoardParams, Converter, RunOptions, Shape};
use gyroemu_core::f64x4;

#[test]
fn dac_counts_of_a_carrier_at_16_samples_per_period_are_the_closed_form() {
    // Drive 1.0 through a 4-bit DAC of full scale 0.8: step 0.1, codes -8..=7, so the input
    // clips at or above 0.75 and at or below -0.85, and rounds to exactly 0 within 0.05 of 0.
    // At fs = 16 f0 the carrier takes cos(2 pi n / 16): per period 3 samples >= 0.75 (1 and
    // 0.924 twice), 3 <= -0.85 (-1 and -0.924 twice), 2 within 0.05 of 0 (cos = 0). The
    // quadrature drive (sin) is the same sequence shifted: the same counts.
    let mut p = m2tfg(Shape::Coriolis);
    p.dac = Some(Converter {
        bits: 4,
        full_scale: 0.8,
    });
    let q = point(0.0, 49);
    let n_settle = 30;
    let out = Board::<f64x4>::new(&p, &[0.0], &[0])
        .unwrap()
        .run(n_settle, &[q], RunOptions::default(), &|_| {})
        .unwrap();
    let h = out.lanes[0].health;
    let samples = (n_settle + 50) * 100;
    assert_eq!(h.samples, samples);
    assert_eq!(samples % 16, 0);
    let periods = samples / 16;
    assert_eq!(h.dac_clipped, [6 * periods; 2], "{h:?}");
    assert_eq!(h.dac_zero, [2 * periods; 2], "{h:?}");
    assert_eq!(h.tia_railed, [0; 2]);
    assert!(h.clipped());
}

fn harsh(shape: Shape) -> BoardParams {
    let mut p = m2tfg(shape);
    // The TIA output is about 0.01 V: rails at 9 mV clip it, an ADC of 8 mV full scale
    // clips what is left, and a 0.9 full-scale DAC clips the drive peaks of 1.
    p.tia.rail_v = Some(0.009);
    p.adc = Some(Converter {
        bits: 10,
        full_scale: 0.008,
    });
    p.dac = Some(Converter {
        bits: 12,
        full_scale: 0.9,
    });
    p
}

#[test]
fn every_count_equals_the_reference_boards() {
    for shape in [
        Shape::Coriolis,
        Shape::RateTable { freq_hz: 20.0 },
        Shape::Rotating,
    ] {
        let p = harsh(shape);
        let pts = [point(25.0, 60), point(175.0, 37), point(-100.0, 50)];
        let rates: Vec<f64> = pts.iter().map(|q| q.rate_rad_s).collect();
        let fused = Board::<f64x4>::new(&p, &rates, &[0, 1, 2])
            .unwrap()
            .run(40, &pts, RunOptions::default(), &|_| {})
            .unwrap()
            .lanes;
        for (i, q) in pts.iter().enumerate() {
            let want = run_reference(&p, q.rate_rad_s, i as u64, 40, q).unwrap();
            assert_eq!(fused[i].health, want.health, "{shape:?} lane {i}");
            assert_eq!(fused[i], want, "{shape:?} lane {i}");
            let h = want.health;
            assert!(
                h.tia_railed[0] > 0 && h.adc_clipped[0] > 0 && h.dac_clipped[0] > 0,
                "{shape:?} lane {i}: the harsh board must clip everywhere: {h:?}"
            );
            // Each lane counts its own run: settling plus its own window.
            assert_eq!(h.samples, (40 + q.window.samples()) * 100);
        }
    }
}

/// A dump's recordings carry the converter events of the decimation blocks their windows
/// span, so `inspect` can tell a clipped window later. On the 4-bit DAC above, each drive
/// clips where its carrier, cos or sin of 2 pi n / 16, rounds beyond the codes -8..=7 at step
/// 0.1: counted here sample by sample over those blocks. A board without converters, rails
/// or noise counts nothing and says nothing.
#[test]
fn a_dumps_windows_carry_the_converter_events_of_their_blocks() {
    use gyroemu_board::{Probe, DUMP_NODES, EVENTS_COUNTED_KEY, EVENT_KEYS};
    let mut p = m2tfg(Shape::Coriolis);
    p.dac = Some(Converter {
        bits: 4,
        full_scale: 0.8,
    });
    let clips = |x: f64| !(-8.0..=7.0).contains(&(x / 0.1).round());
    // Input samples n0 .. n1 where each drive clips: the closed form of the carrier.
    let want = |n0: u64, n1: u64| {
        let ph = |n: u64| std::f64::consts::TAU * (n % 16) as f64 / 16.0;
        [
            (n0..n1).filter(|&n| clips(ph(n).cos())).count() as f64,
            (n0..n1).filter(|&n| clips(ph(n).sin())).count() as f64,
        ]
    };
    let nodes: Vec<String> = DUMP_NODES.map(String::from).to_vec();
    // (start, full-rate length, decimated length) in input samples: block-aligned; from
    // inside a block to inside the next; the decimated window longer than the full-rate one.
    for (start, full, dec) in [(1000u64, 400u64, 400u64), (1050, 100, 300), (2730, 7, 2000)] {
        let fs = 240_000.0;
        let mut probe = Probe::new(&nodes, fs, 100, start as f64 / fs, full as f64 / fs, 0)
            .with_decimated_duration(dec as f64 / fs);
        let q = point(0.0, 49);
        Board::<f64x4>::new(&p, &[0.0], &[0])
            .unwrap()
            .run(
                30,
                &[q],
                RunOptions {
                    probe: Some(&mut probe),
                    ..Default::default()
                },
                &|_| {},
            )
            .unwrap();
        // The full-rate window's blocks; the decimated window's outputs k, each formed by
        // block k, from the first output formed at or after the start.
        let full_blocks = (start / 100 * 100, (start + full).div_ceil(100) * 100);
        let k0 = (start + 1).saturating_sub(100).div_ceil(100);
        let dec_blocks = (k0 * 100, (k0 + dec / 100) * 100);
        for (rec, (n0, n1)) in [full_blocks, dec_blocks].into_iter().enumerate() {
            let got = probe.event_extra(rec);
            let w = want(n0, n1);
            assert!(w[0] > 0.0 && w[1] > 0.0);
            assert_eq!(got[EVENT_KEYS[0]], w[0], "{start} {rec}: {got:?}");
            assert_eq!(got[EVENT_KEYS[1]], w[1], "{start} {rec}: {got:?}");
            assert_eq!(got[EVENTS_COUNTED_KEY], (n1 - n0) as f64, "{got:?}");
            for key in &EVENT_KEYS[2..] {
                assert_eq!(got[*key], 0.0, "{key}: {got:?}");
            }
        }
    }
    // Clean: no counts, so no keys (rather than zeros no counter stood behind).
    let mut probe = Probe::new(&nodes, 240_000.0, 100, 0.004, 0.001, 0);
    Board::<f64x4>::new(&m2tfg(Shape::Coriolis), &[0.0], &[0])
        .unwrap()
        .run(
            30,
            &[point(0.0, 49)],
            RunOptions {
                probe: Some(&mut probe),
                ..Default::default()
            },
            &|_| {},
        )
        .unwrap();
    assert!(probe.event_extra(0).is_empty() && probe.event_extra(1).is_empty());
}
