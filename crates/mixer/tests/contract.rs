//! The stage contract (gyroemu_core::check) for the mixers: block processing, reset and f64x4
//! lanes bit for bit (the carrier phasor shared by all lanes, as on the board), and the zero
//! latency of each memoryless mixer along one real path.

use gyroemu_core::check::{self, Gen};
use gyroemu_core::{f64x4, Complex64, Sample, Stage};
use gyroemu_mixer::{
    table_channel, Iq, Stage1Mixer, Stage2Mixer, Stage2Out, TableMixer, MAX_TABLE_HARMONIC,
};

fn stage1_input<S: Sample>(g: &mut Gen) -> (S, Complex64) {
    (g.sample(-3.0, 3.0), g.phasor())
}

fn iq<S: Copy>(z: &Iq<S>) -> (S, S) {
    (z.i, z.q)
}

#[test]
fn stage1_blocks_reset_lanes_and_latency() {
    // phi = 0 takes the mixer's shortcut (no rotation); the others rotate.
    for phi in [0.0, 0.7, -core::f64::consts::FRAC_PI_2] {
        let s = Stage1Mixer::<f64>::new(phi).unwrap();
        let v = Stage1Mixer::<f64x4>::new(phi).unwrap();
        check::tick_vs_process("mixer.stage1", &s, stage1_input, iq);
        check::reset_restores("mixer.stage1", &s, stage1_input, iq);
        check::tick_vs_process("mixer.stage1<f64x4>", &v, stage1_input, iq);
        check::lanes_match(
            "mixer.stage1",
            &v,
            &[s.clone(), s.clone(), s.clone(), s.clone()],
            stage1_input,
            |&(y, c), l| (y.lane(l), c),
            |z, l| (z.i.lane(l), z.q.lane(l)),
            iq,
        );
        // y to I at a carrier phase of 0: `[2 cos phi]`, no delay.
        let mut m = s;
        let lat = m.latency_samples();
        let one = Complex64::new(1.0, 0.0);
        check::latency_matches("mixer.stage1", lat, |x| m.tick((x, one)).i, 8, 0.0);
    }
}

fn stage2_input<S: Sample>(g: &mut Gen) -> (Iq<S>, [S; 2]) {
    let z = Iq::new(g.sample(-3.0, 3.0), g.sample(-3.0, 3.0));
    (z, [g.sample(-1.0, 1.0), g.sample(-1.0, 1.0)])
}

fn terms<S: Copy>(o: &Stage2Out<S>) -> [S; 4] {
    [o.c.i, o.c.q, o.s.i, o.s.q]
}

#[test]
fn stage2_blocks_reset_lanes_and_latency() {
    let s = Stage2Mixer::<f64>::new();
    let v = Stage2Mixer::<f64x4>::new();
    check::tick_vs_process("mixer.stage2", &s, stage2_input, terms);
    check::reset_restores("mixer.stage2", &s, stage2_input, terms);
    check::tick_vs_process("mixer.stage2<f64x4>", &v, stage2_input, terms);
    check::lanes_match(
        "mixer.stage2",
        &v,
        &[s; 4],
        stage2_input,
        |(z, r), l| (Iq::new(z.i.lane(l), z.q.lane(l)), r.map(|x| x.lane(l))),
        |o, l| terms(o).map(|x| x.lane(l)),
        terms,
    );
    // Re z to the C-term's I with the references at (1, 0): `[2]`, no delay.
    let mut m = s;
    let lat = m.latency_samples();
    let path = |x: f64| (Iq::new(x, 0.0), [1.0, 0.0]);
    check::latency_matches("mixer.stage2", lat, |x| m.tick(path(x)).c.i, 8, 0.0);
}

/// Each lane its own table reference (lanes may follow different tables).
fn table_input<S: Sample>(g: &mut Gen) -> ([Iq<S>; 2], (S, S)) {
    let z = [
        Iq::new(g.sample(-3.0, 3.0), g.sample(-3.0, 3.0)),
        Iq::new(g.sample(-3.0, 3.0), g.sample(-3.0, 3.0)),
    ];
    let r: Vec<Complex64> = (0..S::LANES).map(|_| g.phasor()).collect();
    (z, (S::from_fn(|l| r[l].re), S::from_fn(|l| r[l].im)))
}

#[test]
fn table_mixer_blocks_reset_lanes_and_latency() {
    for n in [0, 3, MAX_TABLE_HARMONIC] {
        let s = TableMixer::<f64>::new(n).unwrap();
        let v = TableMixer::<f64x4>::new(n).unwrap();
        check::tick_vs_process("mixer.table", &s, table_input, |o| *o);
        check::reset_restores("mixer.table", &s, table_input, |o| *o);
        check::tick_vs_process("mixer.table<f64x4>", &v, table_input, |o| *o);
        check::lanes_match(
            "mixer.table",
            &v,
            &[s; 4],
            table_input,
            |(z, r), l| {
                (
                    z.map(|zm| Iq::new(zm.i.lane(l), zm.q.lane(l))),
                    (r.0.lane(l), r.1.lane(l)),
                )
            },
            |o, l| o.map(|x| x.lane(l)),
            |o| *o,
        );
        // Re z1 to harmonic 0's real channel at a reference of 1: `[1]`, no delay.
        let mut m = s;
        let lat = m.latency_samples();
        let zero = Iq::new(0.0, 0.0);
        let path = |x: f64| ([Iq::new(x, 0.0), zero], (1.0, 0.0));
        let ch = table_channel(0, 0, n);
        check::latency_matches("mixer.table", lat, |x| m.tick(path(x))[ch], 8, 0.0);
    }
}
