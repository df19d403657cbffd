//! The plant's own closed forms for the frequency-response sweep: its eigenmodes (the natural
//! frequency and Q of each, with quadrature coupling) and its exact response under the held
//! drive. The sweep's fits are checked against them.

use gyroemu_core::Complex64;
use gyroemu_resonator::{hold_response, Resonator, ResonatorParams};
use nalgebra::Matrix4;

/// The natural frequency (Hz) and Q of each mode of the plant `p` at rest, from the eigenvalues
/// `s` of its state matrix (`f0 = |s| / 2 pi`, `Q = |s| / (2 Re(-s))`). With quadrature
/// coupling the two eigenmodes mix the configured modes; each is named for the mode that
/// dominates its mode shape. NaN if the matrix has no two oscillatory eigenvalue pairs.
pub fn coupled_modes(p: &ResonatorParams) -> [(f64, f64); 2] {
    let tau = core::f64::consts::TAU;
    let (w1, w2) = (tau * p.mode1.f0_hz, tau * p.mode2.f0_hz);
    // In units of a reference frequency (time scaled by it, displacement by it too), every
    // entry is near 1 or small, and the eigenvalues keep their relative precision.
    let wr = 0.5 * (w1 + w2);
    let (r1, r2) = (w1 / wr, w2 / wr);
    let k = p.quadrature_coupling_rad2_s2 / (wr * wr);
    let (g1, g2) = (r1 / p.mode1.q, r2 / p.mode2.q);
    #[rustfmt::skip]
    let a = Matrix4::new(
        0.0, 0.0, 1.0, 0.0,
        0.0, 0.0, 0.0, 1.0,
        -r1 * r1, -k, -g1, 0.0,
        -k, -r2 * r2, 0.0, -g2,
    );
    let mut upper: Vec<Complex64> = a
        .complex_eigenvalues()
        .iter()
        .filter(|s| s.im > 0.0)
        .copied()
        .collect();
    if upper.len() != 2 {
        return [(f64::NAN, f64::NAN); 2];
    }
    // An eigenvector's mode shape: d1(s) q1 = -k q2 and d2(s) q2 = -k q1, d_i(s) = s^2 + g_i s +
    // r_i^2, so |q2 / q1|^2 = |d1(s)| / |d2(s)|: mode 1 dominates the eigenvalue with the
    // smaller ratio. (Sorting by |s| swapped them on a mode-matched device, where |s| differs
    // only through the damping.)
    let share = |s: Complex64| {
        let d = |r: f64, g: f64| (s * s + s * g + r * r).norm();
        d(r1, g1) / d(r2, g2)
    };
    let (a1, a2) = (share(upper[0]), share(upper[1]));
    if a1 > a2 || (a1 == a2 && upper[0].norm() > upper[1].norm()) {
        upper.swap(0, 1);
    }
    core::array::from_fn(|i| {
        (
            upper[i].norm() * wr / tau,
            upper[i].norm() / (-2.0 * upper[i].re),
        )
    })
}

/// The velocity of both modes per unit force on mode `m` at `f_hz` under the held drive,
/// over the hold's response at `f_hz`: what `stepped_sine` measures when the emulation is
/// exact (from `plant`'s exact held steady state).
pub fn held_response(plant: &Resonator<f64>, f_hz: f64, m: usize) -> [Complex64; 2] {
    let mut force = [Complex64::new(0.0, 0.0); 2];
    force[m] = Complex64::new(1.0, 0.0);
    let x = plant.held_steady_state(f_hz, force);
    let hold = hold_response(f_hz, plant.params().fs_hz);
    [x[2] / hold, x[3] / hold]
}
