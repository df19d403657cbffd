//! What the mechanical bandwidth does to a rate-table measurement: the phase amplitude per unit
//! rate against the table frequency, emulated at each frequency, beside the first-order
//! low-pass of THEORY.md section 3 (DC gain 2 Q lambda / w0, corner f0/(2Q)).

use gyroemu_config::{Config, RateTable};
use gyroemu_experiment::{run_table_sweeps, SweepError, SweepResult};
use gyroemu_theory::rate_table_gain;

/// Rate-table frequencies of the bandwidth sweep, Hz (the corner is f0/(2Q) = 0.21 Hz at
/// 15 kHz and Q = 36 000).
pub const BANDWIDTH_FREQS_HZ: [f64; 9] = [0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0];
/// Rate-table amplitude of the bandwidth sweep, deg/s (small: the first-order model is linear).
pub const BANDWIDTH_AMPLITUDE_DPS: f64 = 5.0;

/// One table frequency of the bandwidth sweep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BandwidthPoint {
    /// Table frequency, Hz.
    pub table_freq_hz: f64,
    /// Emulated phase amplitude per unit rate, per mode, deg per deg/s.
    pub gain_deg_per_dps: [f64; 2],
    /// Small-signal theory of that gain (both modes with equal drives).
    pub theory_gain_deg_per_dps: f64,
    /// Emulated lag of the phase behind the table, per mode, degrees.
    pub lag_deg: [f64; 2],
    /// Small-signal theory of that lag, degrees.
    pub theory_lag_deg: f64,
}

/// Runs the rate-table config `base` at each of [`BANDWIDTH_FREQS_HZ`] with the amplitude
/// [`BANDWIDTH_AMPLITUDE_DPS`] (each over at least two table periods and 4 s), the frequencies
/// packed into shared lane groups (each lane on its own table: the bits of nine separate
/// runs); `group_threads` as in [`gyroemu_experiment::SweepOptions`].
pub fn bandwidth(
    base: &Config,
    group_threads: Option<usize>,
) -> Result<Vec<BandwidthPoint>, SweepError> {
    let runs = run_table_sweeps(&bandwidth_configs(base)?, group_threads)?;
    Ok(bandwidth_points(base, &runs))
}

/// The configs of the bandwidth sweep's points, one per [`BANDWIDTH_FREQS_HZ`], validated: what
/// [`bandwidth`] runs as table sweeps. Validated in parallel (the rate-table rules weigh each
/// point's periodic steady state: tens of milliseconds in all); the first error in frequency
/// order is the one returned.
pub fn bandwidth_configs(base: &Config) -> Result<Vec<Config>, SweepError> {
    use rayon::prelude::*;
    let each: Vec<Result<Config, SweepError>> = BANDWIDTH_FREQS_HZ
        .par_iter()
        .map(|&f| bandwidth_config(base, f))
        .collect();
    each.into_iter().collect()
}

/// The bandwidth sweep's points from the runs of [`bandwidth_configs`], in order, beside the
/// first-order model's gain and lag.
pub fn bandwidth_points(base: &Config, runs: &[SweepResult]) -> Vec<BandwidthPoint> {
    let d = &base.device;
    BANDWIDTH_FREQS_HZ
        .iter()
        .zip(runs)
        .map(|(&f, r)| {
            let p = &r.points[0];
            let (g, ph) = rate_table_gain(d.f0_hz, d.q, d.angular_gain, 1.0, 1.0, f);
            BandwidthPoint {
                table_freq_hz: f,
                gain_deg_per_dps: p.phase_deg.map(|x| x / BANDWIDTH_AMPLITUDE_DPS),
                theory_gain_deg_per_dps: g,
                lag_deg: p.table_lag_deg.unwrap_or([f64::NAN; 2]),
                theory_lag_deg: ph.to_degrees(),
            }
        })
        .collect()
}

/// The config of the bandwidth sweep's point at table frequency `f_hz`.
pub fn bandwidth_config(base: &Config, f_hz: f64) -> Result<Config, SweepError> {
    let mut cfg = base.clone();
    cfg.experiment.rate_table = RateTable::Sinusoid;
    cfg.experiment.table_freq_hz = Some(f_hz);
    cfg.experiment.rates_dps = vec![BANDWIDTH_AMPLITUDE_DPS];
    cfg.experiment.average_s = (2.0 / f_hz).max(4.0);
    cfg.validate()?;
    Ok(cfg)
}
