//! A process limited to four lanes (`--lanes 4`) runs four-lane code only, as on a CPU without
//! AVX-512: its boards, with every flicker source, equal the reference board bit for bit.
//! Its own test binary, since the lane limit is the process's.

mod common;

use common::check::check_width;
use common::{flickering, imperfect, m2tfg, point};
use gyroemu_board::{set_max_lanes, Board, Shape};
use gyroemu_core::f64x4;

#[test]
fn four_lane_flicker_equals_the_reference() {
    set_max_lanes(4).unwrap();
    for m in [100, 600] {
        for shape in [Shape::Rotating, Shape::Coriolis] {
            let mut p = flickering(m2tfg(shape), 3);
            p.decimation = m;
            let b = Board::<f64x4>::new(&p, &[0.0], &[0]).unwrap();
            assert!(!b.tia_flicker_joined(), "--lanes 4 keeps the sources apart");
            let pts = [point(25.0, 8), point(-100.0, 6), point(60.0, 7)];
            check_width(&format!("{shape:?} M = {m}"), 4, &p, &pts, 5);
            check_width(
                &format!("{shape:?} M = {m} imperfect"),
                4,
                &imperfect(p),
                &pts,
                5,
            );
        }
    }
}
