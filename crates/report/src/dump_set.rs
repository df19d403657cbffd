//! A dump as the figures see it: the full-rate and decimated recordings of one run (either
//! may be missing), read back from disk, and the node each channel belongs to.

use gyroemu_board::Probe;
use gyroemu_io::{read_dump, Dump, IoError};
use std::path::{Path, PathBuf};

/// The recordings of one dump.
#[derive(Clone, Debug)]
pub struct DumpSet {
    /// What the user named (for titles and messages).
    pub name: String,
    /// The folder the recordings are in.
    pub dir: PathBuf,
    /// The full-rate recording (`*_fullrate`, or a recording of another name).
    pub full: Option<Dump>,
    /// The decimated recording (`*_decimated`).
    pub decimated: Option<Dump>,
}

impl DumpSet {
    /// The recordings present, full rate first.
    pub fn recordings(&self) -> impl Iterator<Item = &Dump> {
        self.full.iter().chain(&self.decimated)
    }

    /// A number of the operating point (`gyroemu:<key>` of either recording's metadata).
    pub fn extra(&self, key: &str) -> Option<f64> {
        self.recordings()
            .find_map(|d| d.extra.get(key).copied())
            .filter(|v| v.is_finite())
    }
}

/// The extensions a recording is named by.
const EXTS: [&str; 4] = [".sigmf-meta", ".sigmf-data", ".csv", ".wav"];

/// Reads the dump `path` names: a recording (`.sigmf-meta`, `.sigmf-data` or `.csv` path, or
/// their stem), whose `_fullrate`/`_decimated` sibling is read too when present (in the same
/// format); the stem of such a pair (`out/dump`); or a folder holding `dump_fullrate.*` and
/// `dump_decimated.*`. A `.wav` path is refused (it holds float32 copies only).
pub fn read_dump_set(path: &Path) -> Result<DumpSet, IoError> {
    let name = path.display().to_string();
    let refuse = |reason: &str| IoError::Read {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    };
    let (dir, file) = if path.is_dir() {
        (path.to_path_buf(), "dump".to_string())
    } else {
        let file = path
            .file_name()
            .map(|f| f.to_string_lossy().into_owned())
            .ok_or_else(|| refuse("names no file"))?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        (dir, file)
    };
    if file.ends_with(".wav") {
        return Err(refuse(
            "a WAV holds float32 copies only: give the .sigmf-meta, .sigmf-data or .csv beside it",
        ));
    }
    let ext = EXTS.iter().find(|e| file.ends_with(*e)).copied();
    let stem = ext.map_or(file.as_str(), |e| &file[..file.len() - e.len()]);
    let exists = |s: &str| match ext {
        Some(e) => dir.join(format!("{s}{e}")).exists(),
        None => [".sigmf-meta", ".csv"]
            .iter()
            .any(|e| dir.join(format!("{s}{e}")).exists()),
    };
    let read = |s: &str| read_dump(&dir.join(format!("{s}{}", ext.unwrap_or(""))));
    let pair = |base: &str| -> Result<(Option<Dump>, Option<Dump>), IoError> {
        let (f, d) = (format!("{base}_fullrate"), format!("{base}_decimated"));
        Ok((
            exists(&f).then(|| read(&f)).transpose()?,
            exists(&d).then(|| read(&d)).transpose()?,
        ))
    };
    let (full, decimated) = if let Some(base) = stem.strip_suffix("_fullrate") {
        let (_, d) = pair(base)?;
        (Some(read(stem)?), d)
    } else if let Some(base) = stem.strip_suffix("_decimated") {
        let (f, _) = pair(base)?;
        (f, Some(read(stem)?))
    } else if ext.is_none() && !exists(stem) {
        let p = pair(stem)?;
        if p.0.is_none() && p.1.is_none() {
            return Err(refuse(&format!(
                "no dump there: looked for {stem}.sigmf-meta, {stem}.csv, {stem}_fullrate.* and {stem}_decimated.*"
            )));
        }
        p
    } else {
        (Some(read(stem)?), None)
    };
    Ok(DumpSet {
        name,
        dir,
        full,
        decimated,
    })
}

/// One node of the board as the figures group it: a title and the channel names it holds
/// (in order).
pub struct Node {
    /// Panel title.
    pub title: &'static str,
    /// Channel names.
    pub channels: &'static [&'static str],
}

impl Node {
    /// The unit of the node's samples: the probe's, which writes it into every recording
    /// (one table, so a figure and a recording cannot disagree).
    pub fn unit(&self) -> &'static str {
        Probe::channel_unit(self.channels[0]).unwrap_or("")
    }
}

/// The board's nodes, in signal order (docs/user-guide.md section 5.3).
pub const NODES: [Node; 8] = [
    Node {
        title: "Drive (DAC output)",
        channels: &["drive1", "drive2"],
    },
    Node {
        title: "Displacement",
        channels: &["q1_m", "q2_m"],
    },
    Node {
        title: "Velocity",
        channels: &["v1_m_s", "v2_m_s"],
    },
    Node {
        title: "TIA output",
        channels: &["tia1_v", "tia2_v"],
    },
    Node {
        title: "Stage-1 mixer I/Q (before the low-pass)",
        channels: &["mix1_i1", "mix1_q1", "mix1_i2", "mix1_q2"],
    },
    Node {
        title: "Low-pass output (decimated)",
        channels: &["lp_i1", "lp_q1", "lp_i2", "lp_q2"],
    },
    Node {
        title: "Modulation phasor cos, sin Ωt",
        channels: &["mod_cos", "mod_sin"],
    },
    Node {
        title: "Stage-2 products",
        channels: &[
            "c1_i", "c1_q", "s1_i", "s1_q", "c2_i", "c2_q", "s2_i", "s2_q",
        ],
    },
];

/// The unit of a channel: the recording's, or the probe's for a board channel (a CSV dump
/// records none).
pub fn channel_unit<'a>(name: &str, recorded: &'a str) -> &'a str {
    if !recorded.is_empty() {
        return recorded;
    }
    Probe::channel_unit(name).unwrap_or(recorded)
}

/// A panel's title, its unit and its channels `(name, samples)`.
pub type Group<'a> = (String, String, Vec<(&'a str, &'a [f64])>);

/// One panel's worth of channels of a recording: `(title, unit, [(name, samples)])`. The
/// board's nodes first; any other channel gets a panel of its own.
pub fn groups(d: &Dump) -> Vec<Group<'_>> {
    let mut out = Vec::new();
    let mut used = vec![false; d.channels.len()];
    for node in &NODES {
        let chans: Vec<(&str, &[f64])> = node
            .channels
            .iter()
            .filter_map(|name| {
                let k = d.channels.iter().position(|c| c.name == *name)?;
                used[k] = true;
                Some((d.channels[k].name.as_str(), d.data[k].as_slice()))
            })
            .collect();
        if !chans.is_empty() {
            out.push((node.title.to_string(), node.unit().to_string(), chans));
        }
    }
    for (k, c) in d.channels.iter().enumerate().filter(|(k, _)| !used[*k]) {
        out.push((
            c.name.clone(),
            channel_unit(&c.name, &c.unit).to_string(),
            vec![(c.name.as_str(), d.data[k].as_slice())],
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_node_of_the_figures_is_a_probe_channel_with_one_unit() {
        for n in &NODES {
            let units: Vec<Option<&str>> =
                n.channels.iter().map(|c| Probe::channel_unit(c)).collect();
            assert!(units.iter().all(|u| u.is_some()), "{}: {units:?}", n.title);
            assert!(
                units.windows(2).all(|w| w[0] == w[1]),
                "{}: {units:?}",
                n.title
            );
        }
        assert_eq!(NODES[0].unit(), "m/s²");
        assert_eq!(NODES[6].unit(), "");
    }
}
