//! Windowed signal dumps of every node of the board, for one lane of one run. Recording
//! happens inside the sample loop only for samples inside the window; memory is bounded by
//! the window.

use crate::health::{Counters, ADC_CLIP, DAC_CLIP, TIA_RAIL};
use gyroemu_core::{Sample, Stage};
use gyroemu_io::{IoError, SignalRecorder};
use gyroemu_mixer::{Iq, Stage2Mixer};
use gyroemu_resonator::PlantOutput;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Which nodes to record, and the recorders for the full-rate and decimated nodes.
#[derive(Clone)]
pub struct Probe {
    lane: usize,
    nodes: [bool; 7],
    full: SignalRecorder,
    decimated: SignalRecorder,
    /// Finite-check mode (locating a non-finite value): every lane of every node is checked
    /// and the first fault kept as (stage, input sample, lane); nothing is recorded.
    check_lanes: usize,
    fault: Option<(&'static str, u64, usize)>,
    /// The converter events the board counted in the decimation blocks each recording's
    /// window spans (in [`EVENT_KEYS`] order) and those blocks' input samples; `None` where
    /// the board counts none (it has no converter, rail or noise, so nothing can clip).
    events: [Option<([u64; 6], u64)>; 2],
}

/// The metadata keys of a recording's converter events (`gyroemu:<key>`), in the order of
/// [`Probe`]'s counts, and the key of the input samples they were counted over.
pub const EVENT_KEYS: [&str; 6] = [
    "dac_clipped_samples_mode1",
    "dac_clipped_samples_mode2",
    "tia_railed_samples_mode1",
    "tia_railed_samples_mode2",
    "adc_clipped_samples_mode1",
    "adc_clipped_samples_mode2",
];

/// See [`EVENT_KEYS`].
pub const EVENTS_COUNTED_KEY: &str = "events_counted_samples";

/// The [`Counters`] slots of [`EVENT_KEYS`].
const EVENT_SLOTS: [usize; 6] = [
    DAC_CLIP,
    DAC_CLIP + 1,
    TIA_RAIL,
    TIA_RAIL + 1,
    ADC_CLIP,
    ADC_CLIP + 1,
];

/// The node names a dump accepts: full-rate `drive`, `displacement`, `velocity`, `tia`,
/// `stage1`; decimated `lowpass`, `stage2`.
pub const DUMP_NODES: [&str; 7] = [
    "drive",
    "displacement",
    "velocity",
    "tia",
    "stage1",
    "lowpass",
    "stage2",
];

/// A node's channels in recording order, each with its unit.
type Channels = &'static [(&'static str, &'static str)];

/// The full-rate nodes (in `DUMP_NODES` order) and their channels with units, as
/// docs/user-guide.md section 5.3 gives them: the dump's metadata takes each channel's unit
/// from here (the drive and mixer names carry none to read it from).
const FULL_NODES: [(&str, Channels); 5] = [
    ("drive", &[("drive1", "m/s²"), ("drive2", "m/s²")]),
    ("displacement", &[("q1_m", "m"), ("q2_m", "m")]),
    ("velocity", &[("v1_m_s", "m/s"), ("v2_m_s", "m/s")]),
    ("tia", &[("tia1_v", "V"), ("tia2_v", "V")]),
    (
        "stage1",
        &[
            ("mix1_i1", "V"),
            ("mix1_q1", "V"),
            ("mix1_i2", "V"),
            ("mix1_q2", "V"),
        ],
    ),
];

/// The decimated nodes, as [`FULL_NODES`]; the modulation phasor is dimensionless.
const DEC_NODES: [(&str, Channels); 2] = [
    (
        "lowpass",
        &[
            ("lp_i1", "V"),
            ("lp_q1", "V"),
            ("lp_i2", "V"),
            ("lp_q2", "V"),
            ("mod_cos", ""),
            ("mod_sin", ""),
        ],
    ),
    (
        "stage2",
        &[
            ("c1_i", "V"),
            ("c1_q", "V"),
            ("s1_i", "V"),
            ("s1_q", "V"),
            ("c2_i", "V"),
            ("c2_q", "V"),
            ("s2_i", "V"),
            ("s2_q", "V"),
        ],
    ),
];

impl Probe {
    /// A probe of `lane` recording `nodes` over `[start_s, start_s + duration_s)`.
    pub fn new(
        nodes: &[String],
        fs_hz: f64,
        decimation: usize,
        start_s: f64,
        duration_s: f64,
        lane: usize,
    ) -> Self {
        let mut on = [false; 7];
        for (i, name) in DUMP_NODES.iter().enumerate() {
            on[i] = nodes.iter().any(|n| n == name);
        }
        // The channels of the nodes asked for, and their units.
        let channels = |table: &[(&str, Channels)], offset: usize| -> (Vec<String>, Vec<&str>) {
            table
                .iter()
                .enumerate()
                .filter(|(i, _)| on[offset + i])
                .flat_map(|(_, (_, chans))| chans.iter())
                .map(|&(name, unit)| (name.to_string(), unit))
                .unzip()
        };
        let (full_names, full_units) = channels(&FULL_NODES, 0);
        let (dec_names, dec_units) = channels(&DEC_NODES, FULL_NODES.len());
        let fs_out = fs_hz / decimation as f64;
        let start = (start_s * fs_hz).round() as u64;
        let len = (duration_s * fs_hz).round().max(1.0) as u64;
        // Decimated sample k is formed at input sample kM + M - 1, at (M - 1) / fs after
        // k / fs_out: the window records from the first output formed at or after its start
        // (to a millionth of an output period), counted from that origin (from t = 0 it came
        // up to an output late, and a window of under an output period at the run's end
        // recorded nothing).
        let origin_s = (decimation - 1) as f64 / fs_hz;
        let start_out = ((start_s - origin_s) * fs_out - 1e-6).ceil().max(0.0) as u64;
        let len_out = (duration_s * fs_out).round().max(1.0) as u64;
        Self {
            lane,
            nodes: on,
            full: SignalRecorder::new(full_names, fs_hz, start, len).with_units(&full_units),
            decimated: SignalRecorder::new(dec_names, fs_out, start_out, len_out)
                .with_units(&dec_units)
                .with_time_origin(origin_s),
            check_lanes: 0,
            fault: None,
            events: [None; 2],
        }
    }

    /// Records the decimated nodes over `duration_s` from the same start instead of the
    /// full-rate window's length: the slow nodes (low-pass, stage 2) cost a decimation's
    /// fraction per second, so they can cover a modulation period the full rate cannot.
    pub fn with_decimated_duration(mut self, duration_s: f64) -> Self {
        let fs_out = self.decimated.fs_hz();
        let start = self.decimated.start();
        let names = self.decimated.names().to_vec();
        let units = self.decimated.units().to_vec();
        let t0 = self.decimated.t0_s();
        let len = (duration_s * fs_out).round().max(1.0) as u64;
        self.decimated = SignalRecorder::new(names, fs_out, start, len)
            .with_units(&units)
            .with_time_origin(t0);
        self
    }

    /// Describes the operating point in both recordings' SigMF metadata (`gyroemu:<key>`).
    pub fn with_extra(mut self, extra: BTreeMap<String, f64>) -> Self {
        self.full = self.full.with_extra(extra.clone());
        self.decimated = self.decimated.with_extra(extra);
        self
    }

    /// A probe that records nothing and checks that every node of the first `lanes` lanes
    /// stays finite (the replay that names the stage where a run overflowed).
    pub fn finite_check(lanes: usize) -> Self {
        Self {
            lane: 0,
            nodes: [false; 7],
            full: SignalRecorder::new(Vec::new(), 1.0, 0, 0),
            decimated: SignalRecorder::new(Vec::new(), 1.0, 0, 0),
            check_lanes: lanes,
            fault: None,
            events: [None; 2],
        }
    }

    /// The first non-finite node found in finite-check mode: (stage, input sample, lane).
    pub fn fault(&self) -> Option<(&'static str, u64, usize)> {
        self.fault
    }

    fn check<S: Sample>(&mut self, stage: &'static str, n: u64, values: &[S]) {
        if self.fault.is_some() {
            return;
        }
        for lane in 0..self.check_lanes {
            if values.iter().any(|v| !v.lane(lane).is_finite()) {
                self.fault = Some((stage, n, lane));
                return;
            }
        }
    }

    /// Checks the low-pass outputs of input sample `n` (finite-check mode only).
    #[inline]
    pub fn check_lowpass<S: Sample>(&mut self, n: u64, z: &[Iq<S>; 2]) {
        if self.check_lanes > 0 {
            self.check("lowpass", n, &[z[0].i, z[0].q, z[1].i, z[1].q]);
        }
    }

    /// Whether input samples `n0 .. n0 + m` touch the full-rate window.
    #[inline]
    pub fn wants_block(&self, n0: u64, m: u64) -> bool {
        if self.check_lanes > 0 {
            return true;
        }
        !self.full.names().is_empty() && n0 < self.full.end() && n0 + m > self.full.start()
    }

    /// The decimated sample `k` after which both windows have ended (input samples up to
    /// `(k + 1) m - 1` recorded): nothing later is kept, so the dump is final. `None` for a
    /// finite check, which watches every sample.
    pub fn recorded_at(&self, m: u64) -> Option<u64> {
        if self.check_lanes > 0 {
            return None;
        }
        // A recorder with no nodes has nothing to wait for.
        let end = |r: &SignalRecorder| if r.names().is_empty() { 0 } else { r.end() };
        Some(
            end(&self.full)
                .div_ceil(m.max(1))
                .max(end(&self.decimated))
                .saturating_sub(1),
        )
    }

    /// Records the full-rate nodes of input sample `n`.
    #[inline]
    pub fn record_full<S: Sample>(
        &mut self,
        n: u64,
        u: &[S; 2],
        p: &PlantOutput<S>,
        y: &[S; 2],
        z: &[Iq<S>; 2],
    ) {
        if self.check_lanes > 0 {
            // Chain order, so the first stage that overflowed is the one named.
            self.check("am/dac (drive)", n, u);
            self.check("resonator", n, &[p.q[0], p.q[1], p.v[0], p.v[1]]);
            self.check("resonator (motional current)", n, &p.current);
            self.check("tia/adc", n, y);
            self.check("mixer (stage 1)", n, &[z[0].i, z[0].q, z[1].i, z[1].q]);
            return;
        }
        if self.full.names().is_empty() || !self.full.wants(n) {
            return;
        }
        let l = self.lane;
        let mut frame = [0.0f64; 12];
        let mut k = 0;
        let mut put = |v: &[f64]| {
            frame[k..k + v.len()].copy_from_slice(v);
            k += v.len();
        };
        if self.nodes[0] {
            put(&[u[0].lane(l), u[1].lane(l)]);
        }
        if self.nodes[1] {
            put(&[p.q[0].lane(l), p.q[1].lane(l)]);
        }
        if self.nodes[2] {
            put(&[p.v[0].lane(l), p.v[1].lane(l)]);
        }
        if self.nodes[3] {
            put(&[y[0].lane(l), y[1].lane(l)]);
        }
        if self.nodes[4] {
            put(&[
                z[0].i.lane(l),
                z[0].q.lane(l),
                z[1].i.lane(l),
                z[1].q.lane(l),
            ]);
        }
        self.full.record(n, &frame[..k]);
    }

    /// Adds this probe's lane of decimation block `k`'s converter events (input samples
    /// `n0 .. n0 + m`) to each recording whose window the block touches: the full-rate one
    /// where the block overlaps its samples, the decimated one where the block forms its
    /// output `k`. Per block, not per sample: a window's edges inside a block count that
    /// block's events whole.
    pub(crate) fn count_block<S: Sample>(&mut self, n0: u64, m: u64, k: u64, c: &Counters<S>) {
        if self.check_lanes > 0 {
            return;
        }
        let touches = [
            !self.full.names().is_empty() && n0 < self.full.end() && n0 + m > self.full.start(),
            !self.decimated.names().is_empty() && self.decimated.wants(k),
        ];
        for (on, acc) in touches.into_iter().zip(&mut self.events) {
            if on {
                let (ev, samples) = acc.get_or_insert(([0; 6], 0));
                for (e, slot) in ev.iter_mut().zip(EVENT_SLOTS) {
                    *e += c.0[slot].lane(self.lane) as u64;
                }
                *samples += m;
            }
        }
    }

    /// The converter events counted for the full-rate (`0`) or decimated (`1`) recording,
    /// as `gyroemu:<key>` entries ([`EVENT_KEYS`], [`EVENTS_COUNTED_KEY`]); empty where the
    /// board counted none.
    pub fn event_extra(&self, recording: usize) -> BTreeMap<String, f64> {
        self.events[recording]
            .iter()
            .flat_map(|(ev, samples)| {
                EVENT_KEYS
                    .iter()
                    .zip(ev)
                    .map(|(k, &v)| (k.to_string(), v as f64))
                    .chain([(EVENTS_COUNTED_KEY.to_string(), *samples as f64)])
            })
            .collect()
    }

    /// Records the decimated nodes of output sample `k`.
    pub fn record_decimated<S: Sample>(
        &mut self,
        k: u64,
        z: &[Iq<S>; 2],
        r: &[S; 2],
        rotating: bool,
    ) {
        if self.decimated.names().is_empty() || !self.decimated.wants(k) {
            return;
        }
        let l = self.lane;
        let mut frame = [0.0f64; 14];
        let mut n = 0;
        if self.nodes[5] {
            for v in [z[0].i, z[0].q, z[1].i, z[1].q, r[0], r[1]] {
                frame[n] = v.lane(l);
                n += 1;
            }
        }
        if self.nodes[6] {
            let mut mix2 = Stage2Mixer::<S>::default();
            for zm in z {
                let o = if rotating {
                    mix2.tick((*zm, *r))
                } else {
                    Default::default()
                };
                for v in [o.c.i, o.c.q, o.s.i, o.s.q] {
                    frame[n] = v.lane(l);
                    n += 1;
                }
            }
        }
        self.decimated.record(k, &frame[..n]);
    }

    /// Why a recording of `nodes` gets no WAV (see [`gyroemu_io::wav_f32_rate_problem`]):
    /// `(recording, reason)` for the full-rate one at `fs_hz` and the decimated one at
    /// `fs_hz / decimation`, each when it has channels.
    pub fn wav_problems(
        nodes: &[String],
        fs_hz: f64,
        decimation: usize,
    ) -> Vec<(&'static str, String)> {
        let count = |table: &[(&str, Channels)]| -> u64 {
            table
                .iter()
                .filter(|(n, _)| nodes.iter().any(|m| m == n))
                .map(|(_, c)| c.len() as u64)
                .sum()
        };
        [
            ("full-rate", fs_hz, count(&FULL_NODES)),
            ("decimated", fs_hz / decimation as f64, count(&DEC_NODES)),
        ]
        .into_iter()
        .filter(|&(_, _, ch)| ch > 0)
        .filter_map(|(what, fs, ch)| Some((what, gyroemu_io::wav_f32_rate_problem(fs, ch)?)))
        .collect()
    }

    /// The unit of a dump channel of the board (`""`: dimensionless), `None` for a name no
    /// node records.
    pub fn channel_unit(name: &str) -> Option<&'static str> {
        FULL_NODES
            .iter()
            .chain(&DEC_NODES)
            .flat_map(|(_, chans)| chans.iter())
            .find(|(n, _)| *n == name)
            .map(|&(_, unit)| unit)
    }

    /// The names of every file [`Probe::write`] may write for `stem` (to clear a folder of
    /// an earlier dump).
    pub fn file_names(stem: &str) -> Vec<String> {
        ["fullrate", "decimated"]
            .iter()
            .flat_map(|r| SignalRecorder::file_names(&format!("{stem}_{r}")))
            .collect()
    }

    /// The files a dump of `nodes` always writes for `stem`: each recorded rate's CSV and
    /// SigMF pair (its WAV depends on the samples' range, so it is not among them). A folder
    /// missing one of them holds a dump with a part lost.
    pub fn required_file_names(nodes: &[String], stem: &str) -> Vec<String> {
        let any = |table: &[(&str, Channels)]| {
            table
                .iter()
                .any(|(node, _)| nodes.iter().any(|n| n == node))
        };
        [
            ("fullrate", any(&FULL_NODES)),
            ("decimated", any(&DEC_NODES)),
        ]
        .into_iter()
        .filter(|&(_, on)| on)
        .flat_map(|(rate, _)| {
            ["csv", "sigmf-data", "sigmf-meta"].map(|e| format!("{stem}_{rate}.{e}"))
        })
        .collect()
    }

    /// Why a recording of this probe gets no WAV though its rate fits one (a sample outside
    /// float32's normal range: [`SignalRecorder::wav_range_problem`]), one sentence each.
    pub fn wav_notes(&self) -> Vec<String> {
        [("full-rate", &self.full), ("decimated", &self.decimated)]
            .into_iter()
            .filter(|(_, r)| !r.names().is_empty())
            // A rate no WAV holds was said before the run.
            .filter(|(_, r)| {
                gyroemu_io::wav_f32_rate_problem(r.fs_hz(), r.names().len() as u64).is_none()
            })
            .filter_map(|(what, r)| {
                let why = r.wav_range_problem()?;
                Some(format!(
                    "the {what} dump has no .wav: {why}; its CSV and SigMF keep the f64 samples"
                ))
            })
            .collect()
    }

    /// Writes `<stem>_fullrate.{csv,wav,sigmf-data,sigmf-meta}` and the same of
    /// `<stem>_decimated` into `dir` (each when it has channels); returns the paths written.
    pub fn write(&self, dir: &Path, stem: &str) -> Result<Vec<PathBuf>, IoError> {
        // The files synced together (one journal commit, not one each), then renamed.
        gyroemu_io::with_batched_persist(|| self.write_each(dir, stem))
    }

    /// [`Probe::write`]'s files, one writer after the other.
    fn write_each(&self, dir: &Path, stem: &str) -> Result<Vec<PathBuf>, IoError> {
        let mut files = Vec::new();
        if !self.full.names().is_empty() {
            let more = self.event_extra(0);
            files.extend(
                self.full
                    .write_with(dir, &format!("{stem}_fullrate"), &more)?,
            );
        }
        if !self.decimated.names().is_empty() {
            let more = self.event_extra(1);
            files.extend(
                self.decimated
                    .write_with(dir, &format!("{stem}_decimated"), &more)?,
            );
        }
        Ok(files)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What a dump always writes is what `write` writes but the WAV, rate by rate.
    #[test]
    fn a_dumps_required_files_are_those_write_gives_but_the_wav() {
        let dir = tempfile::tempdir().unwrap();
        for nodes in [
            &["tia"][..],
            &["stage2"],
            &["drive", "lowpass"],
            &DUMP_NODES,
        ] {
            let nodes: Vec<String> = nodes.iter().map(|n| n.to_string()).collect();
            let mut p = Probe::new(&nodes, 240_000.0, 100, 0.0, 0.01, 0);
            // A sample outside float32's range in each recording: no WAV anywhere.
            for r in [&mut p.full, &mut p.decimated] {
                let ch = r.names().len();
                for n in 0..4 {
                    r.record(r.start() + n, &vec![1e300; ch]);
                }
            }
            let sub = dir.path().join(nodes.join("-"));
            std::fs::create_dir(&sub).unwrap();
            let mut written: Vec<String> = p
                .write(&sub, "dump")
                .unwrap()
                .iter()
                .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
                .collect();
            written.sort();
            let mut required = Probe::required_file_names(&nodes, "dump");
            required.sort();
            assert_eq!(written, required, "{nodes:?}");
        }
    }

    #[test]
    fn the_channel_tables_follow_the_node_order_and_give_every_channel_its_unit() {
        // `Probe::new` switches the tables' nodes on by their position in DUMP_NODES.
        let order: Vec<&str> = FULL_NODES
            .iter()
            .chain(&DEC_NODES)
            .map(|(n, _)| *n)
            .collect();
        assert_eq!(order, DUMP_NODES);
        assert_eq!(Probe::channel_unit("drive2"), Some("m/s²"));
        assert_eq!(Probe::channel_unit("mix1_q2"), Some("V"));
        assert_eq!(Probe::channel_unit("mod_sin"), Some(""));
        assert_eq!(Probe::channel_unit("time_s"), None);
    }
}
