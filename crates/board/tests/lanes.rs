//! The board in f64x4 lanes gives each lane the result the scalar board gives for that
//! operating point alone (bit for bit: the arithmetic is lane-wise, and `Sample::mul_add` is
//! fused or not alike for f64 and f64x4), with and without noise (each point has its own
//! stream, so its noise does not depend on the lane that runs it); so does a group of eight
//! lanes on a CPU with AVX-512, and a group of either width chosen by `GroupBoard::new`.

mod common;

use common::{m2tfg, noisy, point};
use gyroemu_board::{eight_lanes_available, Board, BoardParams, GroupBoard, RunOptions, Shape};
use gyroemu_core::f64x4;

fn check(name: &str, p: &BoardParams, n: u64) {
    let points = [point(25.0, n), point(100.0, n - 9), point(175.0, n + 4)];
    let rad: Vec<f64> = points.iter().map(|p| p.rate_rad_s).collect();
    let streams = [7, 3, 11];
    let n_settle = 12;
    let lanes = Board::<f64x4>::new(p, &rad, &streams)
        .unwrap()
        .run(n_settle, &points, RunOptions::default(), &|_| {})
        .unwrap()
        .lanes;
    for (i, q) in points.iter().enumerate() {
        let scalar = Board::<f64>::new(p, &[q.rate_rad_s], &[streams[i]])
            .unwrap()
            .run(n_settle, &[*q], RunOptions::default(), &|_| {})
            .unwrap()
            .lanes;
        assert_eq!(lanes[i], scalar[0], "{name}: lane {i}");
    }
}

#[test]
fn lanes_equal_scalar_for_every_shape_with_and_without_noise() {
    for shape in [
        Shape::Coriolis,
        Shape::RateTable { freq_hz: 2.0 },
        Shape::Rotating,
    ] {
        let p = m2tfg(shape);
        check(&format!("{shape:?}"), &p, 110);
        check(&format!("{shape:?} noisy"), &noisy(p, 42), 110);
    }
}

/// Seven points in one group of eight lanes (one lane idle), each against the scalar board.
fn check_eight(name: &str, p: &BoardParams, n: u64) {
    let rates = [25.0, 100.0, 175.0, -50.0, 0.0, 60.0, -175.0];
    let points: Vec<_> = rates
        .iter()
        .enumerate()
        .map(|(i, &r)| point(r, n + 3 * i as u64 - 9))
        .collect();
    let rad: Vec<f64> = points.iter().map(|p| p.rate_rad_s).collect();
    let streams: Vec<u64> = (0..7).map(|i| 5 * i + 2).collect();
    let n_settle = 12;
    let mut board = GroupBoard::with_width(8, p, &rad, &streams).unwrap();
    assert_eq!((board.width(), board.lanes()), (8, 7));
    let lanes = board
        .run(n_settle, &points, RunOptions::default(), &|_| {})
        .unwrap()
        .lanes;
    for (i, q) in points.iter().enumerate() {
        let scalar = Board::<f64>::new(p, &[q.rate_rad_s], &[streams[i]])
            .unwrap()
            .run(n_settle, &[*q], RunOptions::default(), &|_| {})
            .unwrap()
            .lanes;
        assert_eq!(lanes[i], scalar[0], "{name}: lane {i}");
    }
}

#[test]
fn eight_lanes_equal_scalar_for_every_shape_with_and_without_noise() {
    if !eight_lanes_available() {
        eprintln!("no AVX-512 on this CPU: groups of eight are not run here");
        return;
    }
    for shape in [
        Shape::Coriolis,
        Shape::RateTable { freq_hz: 2.0 },
        Shape::Rotating,
    ] {
        let p = m2tfg(shape);
        check_eight(&format!("{shape:?}"), &p, 110);
        check_eight(&format!("{shape:?} noisy"), &noisy(p, 42), 110);
    }
}

#[test]
fn a_group_board_picks_four_lanes_for_four_points_and_refuses_a_bad_width() {
    let p = m2tfg(Shape::Coriolis);
    assert_eq!(
        GroupBoard::new(&p, &[0.0; 4], &[0, 1, 2, 3])
            .unwrap()
            .width(),
        4
    );
    let five = GroupBoard::new(&p, &[0.0; 5], &[0, 1, 2, 3, 4]);
    assert_eq!(five.is_ok(), eight_lanes_available());
    for bad in [0, 2, 16] {
        let e = GroupBoard::with_width(bad, &p, &[0.0], &[0]).err().unwrap();
        assert!(e.to_string().contains("must be 4 or 8"), "{e}");
    }
    if !eight_lanes_available() {
        let e = GroupBoard::with_width(8, &p, &[0.0], &[0]).err().unwrap();
        assert!(e.to_string().contains("AVX-512"), "{e}");
    }
}

#[test]
fn same_seed_same_bits_other_seed_other_bits() {
    let p = m2tfg(Shape::Coriolis);
    let q = point(100.0, 240);
    let run = |seed: u64| {
        Board::<f64>::new(&noisy(p, seed), &[q.rate_rad_s], &[0])
            .unwrap()
            .run(48, &[q], RunOptions::default(), &|_| {})
            .unwrap()
            .lanes[0]
    };
    assert_eq!(run(1), run(1));
    assert_ne!(run(1), run(2));
}

#[test]
fn a_bad_lane_count_is_refused_not_a_panic() {
    let p = m2tfg(Shape::Coriolis);
    assert!(Board::<f64>::new(&p, &[0.0, 1.0], &[0, 1]).is_err());
    assert!(Board::<f64x4>::new(&p, &[], &[]).is_err());
    assert!(Board::<f64x4>::new(&p, &[0.0], &[0, 1]).is_err());
}

/// The width per chain: four only for the ideal rotating loop on a CPU that splits 512-bit
/// operations, and only when eight are not forced; every other chain, and every chain on
/// another CPU, runs the widest the process can.
#[test]
fn the_lane_width_is_four_only_for_the_ideal_rotating_loop_on_split_512_bit_units() {
    use gyroemu_board::{Converter, LaneCpu};
    let shapes = [
        Shape::Coriolis,
        Shape::RateTable { freq_hz: 2.0 },
        Shape::Rotating,
    ];
    for shape in shapes {
        let ideal = m2tfg(shape);
        // Each part of the imperfect loop alone turns it on.
        let mut dac = ideal;
        dac.dac = Some(Converter {
            bits: 16,
            full_scale: 1.5,
        });
        let mut adc = ideal;
        adc.adc = Some(Converter {
            bits: 16,
            full_scale: 0.1,
        });
        let mut rail = ideal;
        rail.tia.rail_v = Some(5.0);
        let mut noise = noisy(ideal, 1);
        noise.adc = None;
        noise.dac = None;
        for (name, p) in [
            ("ideal", &ideal),
            ("dac", &dac),
            ("adc", &adc),
            ("rail", &rail),
            ("noise", &noise),
        ] {
            assert_eq!(p.imperfect(), name != "ideal", "{name}");
            for widest in [4, 8] {
                for forced_eight in [false, true].into_iter().take(widest / 4) {
                    for halves_512 in [false, true] {
                        let cpu = LaneCpu {
                            widest,
                            forced_eight,
                            halves_512,
                        };
                        let four = widest == 4
                            || (halves_512
                                && !forced_eight
                                && shape.is_rotating()
                                && name == "ideal");
                        let want = if four { 4 } else { 8 };
                        assert_eq!(cpu.lanes_for(p), want, "{shape:?} {name} {cpu:?}");
                    }
                }
            }
        }
    }
}

/// The first CPU's `keys` in `/proc/cpuinfo` (trimmed values; a brand string keeps its
/// colons), or `None` where the file or a key is missing.
fn cpuinfo<const K: usize>(keys: [&str; K]) -> Option<[String; K]> {
    let info = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    let field = |key: &str| {
        info.lines()
            .find(|l| l.split(':').next().map(str::trim) == Some(key))
            .and_then(|l| l.split_once(':'))
            .map(|(_, v)| v.trim().to_string())
    };
    let values: Vec<String> = keys.iter().map(|k| field(k)).collect::<Option<_>>()?;
    values.try_into().ok()
}

/// CPUID's answer agrees with the kernel's: a CPU splits 512-bit operations when it runs
/// eight lanes and `/proc/cpuinfo` names an AMD of family 25 (19h, Zen 4).
#[test]
fn split_512_bit_units_are_what_proc_cpuinfo_says() {
    let Some([vendor, family]) = cpuinfo(["vendor_id", "cpu family"]) else {
        return;
    };
    let zen4 = vendor == "AuthenticAMD" && family == "25";
    assert_eq!(
        gyroemu_board::halves_512(),
        zen4 && eight_lanes_available(),
        "{vendor} family {family}"
    );
}

/// CPUID's vendor, family, model and brand agree with the kernel's `/proc/cpuinfo` (what
/// `gyroemu bench` prints about the CPU its figures come from).
#[test]
fn the_cpu_id_is_what_proc_cpuinfo_says() {
    let Some([vendor, family, model]) = cpuinfo(["vendor_id", "cpu family", "model"]) else {
        return;
    };
    let cpu = gyroemu_board::CpuId::this_cpu().expect("/proc/cpuinfo names an x86 CPU");
    assert_eq!(
        (
            cpu.vendor.as_str(),
            cpu.family.to_string(),
            cpu.model.to_string()
        ),
        (vendor.as_str(), family, model)
    );
    // The kernel prints the brand string with its padding trimmed (runs of spaces inside it
    // are kept there and folded here), or "unknown" for a CPU without one.
    if let Some([name]) = cpuinfo(["model name"]).filter(|[n]| n != "unknown") {
        let folded = name.split_whitespace().collect::<Vec<_>>().join(" ");
        assert_eq!(cpu.brand, folded);
    }
}
