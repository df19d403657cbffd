//! Which share of a sweep's operating points this process runs: `--shard i/n`, or the index a
//! scheduler gives an array task (Slurm job arrays, Kubernetes Indexed Jobs). Point `p` belongs
//! to shard `p % n`, so the assignment depends on nothing but the config and `n`.

use crate::error::RunError;
use crate::manifest::{read_manifest, shard_manifest_paths, RunKind, RUN_MANIFEST};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Shard `index` of `count` (0-based), and where that came from (for messages).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
    pub source: String,
    /// Who gave the split: the user, or a scheduler (see [`check_split`]).
    pub from: ShardFrom,
}

/// Where a shard's index and count came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShardFrom {
    /// `--shard I/N`: the user wrote the split out.
    Flag,
    /// A Slurm array task (`task_id` = `SLURM_ARRAY_TASK_ID`), its index taken from its place
    /// in the array; the count from `--shard-count` (`count_given`) or the array's size.
    Slurm { task_id: i64, count_given: bool },
    /// A Kubernetes Indexed Job (`JOB_COMPLETION_INDEX`, the count given beside it).
    Kubernetes,
}

/// Most shards a split may have beyond its items (points, devices). A job array reused for
/// sweeps of any size leaves the shards past the items empty, and they merge fine; 1024 covers
/// Slurm's default MaxArraySize (1001 tasks). Past both, the count is a typo whose merge would
/// need every one of its empty shards.
pub const MAX_SPARSE_SPLIT: usize = 1024;

/// How many shards a message lists before saying how many more.
const LISTED: usize = 5;

/// The environment variable giving the shard count beside `JOB_COMPLETION_INDEX`.
pub const SHARD_COUNT_ENV: &str = "GYROEMU_SHARD_COUNT";

impl Shard {
    /// The points of `n_points` that this shard runs: `p % count == index`.
    pub fn points(&self, n_points: usize) -> Vec<usize> {
        (self.index..n_points).step_by(self.count).collect()
    }

    /// The items (points, devices) of `n` that `shard` runs: all without a shard.
    pub fn items(shard: Option<&Shard>, n: usize) -> Vec<usize> {
        shard.map_or_else(|| (0..n).collect(), |s| s.points(n))
    }

    /// `shard 0/4 (--shard 0/4): 3 of the 10 points`, or `10 points` without a shard.
    pub(crate) fn describe(shard: Option<&Shard>, n: usize, item: &str) -> String {
        match shard {
            Some(s) => {
                let mine = s.points(n).len();
                // More shards than items leaves some shards none: say so, not "all computed".
                let none = if mine == 0 {
                    format!(
                        ": none falls to this shard ({} shards of {n}), nothing to run",
                        s.count
                    )
                } else {
                    String::new()
                };
                format!(
                    "shard {}/{} ({}): {mine} of the {n} {item}s{none}",
                    s.index, s.count, s.source
                )
            }
            None => format!("{n} {item}s"),
        }
    }

    /// The manifest name of this shard inside the output folder.
    pub fn manifest_name(&self) -> String {
        format!("shard-{}-of-{}.json", self.index, self.count)
    }

    /// Refuses a split of more shards than `n` items (each an `item`) and
    /// [`MAX_SPARSE_SPLIT`], before anything runs.
    pub fn check_count(&self, n: usize, item: &str) -> Result<(), RunError> {
        if self.count <= n.max(MAX_SPARSE_SPLIT) {
            return Ok(());
        }
        Err(RunError::BadInput(format!(
            "{}: {} shards of {n} {item}s: a split has at most as many shards as {item}s, or \
             up to {MAX_SPARSE_SPLIT} when there are fewer (the shards past the {item}s are \
             empty, and gyroemu merge needs every one of them)",
            self.source, self.count
        )))
    }

    fn new(index: i64, count: i64, source: String, from: ShardFrom) -> Result<Self, RunError> {
        if count < 1 {
            return Err(RunError::BadInput(format!(
                "{source}: shard count {count} must be at least 1"
            )));
        }
        if index < 0 || index >= count {
            return Err(RunError::BadInput(format!(
                "{source}: shard index {index} must be in 0..{} (0-based, below the count {count})",
                count - 1
            )));
        }
        Ok(Self {
            index: index as usize,
            count: count as usize,
            source,
            from,
        })
    }
}

/// The manifest of a run in `out`: `manifest.json`, or the shard's `shard-I-of-N.json`.
pub(crate) fn manifest_path(out: &Path, shard: Option<&Shard>) -> PathBuf {
    match shard {
        Some(s) => out.join(s.manifest_name()),
        None => out.join(RUN_MANIFEST),
    }
}

/// `--shard-count N` as the signed count the rules compare (an `N` past `i64::MAX` refused).
fn count_of_flag(n: usize) -> Result<i64, RunError> {
    i64::try_from(n).map_err(|_| {
        RunError::BadInput(format!("--shard-count = {n}: must be at most {}", i64::MAX))
    })
}

fn int(name: &str, text: &str) -> Result<i64, RunError> {
    let t = text.trim();
    t.parse().map_err(|_| {
        // Digits alone are an integer, only too large (it was called "not an integer").
        let digits = t.strip_prefix(['-', '+']).unwrap_or(t);
        let what = if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) {
            "an integer out of range"
        } else {
            "not an integer"
        };
        RunError::BadInput(format!(
            "{name} = `{text}`: {what} (from {} to at most {})",
            i64::MIN,
            i64::MAX
        ))
    })
}

/// Parses `i/n` (0 <= i < n).
pub fn parse_shard(text: &str) -> Result<Shard, RunError> {
    let src = format!("--shard {text}");
    let (i, n) = text
        .split_once('/')
        .ok_or_else(|| RunError::BadInput(format!("{src}: expected INDEX/COUNT, e.g. 0/4")))?;
    Shard::new(
        int("--shard index", i)?,
        int("--shard count", n)?,
        src,
        ShardFrom::Flag,
    )
}

/// The shard of this process: `--shard` if given, else the Slurm array task
/// (`SLURM_ARRAY_TASK_ID` minus `SLURM_ARRAY_TASK_MIN`, over `SLURM_ARRAY_TASK_STEP`, of
/// `SLURM_ARRAY_TASK_COUNT` shards, or of those `MIN` to `SLURM_ARRAY_TASK_MAX`; a
/// `--shard-count` must equal that size), else a Kubernetes Indexed Job
/// (`JOB_COMPLETION_INDEX` with `--shard-count` or `GYROEMU_SHARD_COUNT`); `None`: no sharding.
/// A scheduler's split is then checked against the output folder by [`check_split`].
pub fn resolve_shard(
    flag: Option<&str>,
    count_flag: Option<usize>,
    env: &dyn Fn(&str) -> Option<String>,
) -> Result<Option<Shard>, RunError> {
    if let Some(f) = flag {
        let shard = parse_shard(f)?;
        // `--shard I/N` says its count: another --shard-count beside it was ignored unsaid.
        if let Some(n) = count_flag.filter(|&n| n != shard.count) {
            return Err(RunError::BadInput(format!(
                "--shard {f} splits into {} shards but --shard-count = {n}: give the count once (--shard I/N alone)",
                shard.count
            )));
        }
        return Ok(Some(shard));
    }
    if let Some(id) = env("SLURM_ARRAY_TASK_ID") {
        let id = int("SLURM_ARRAY_TASK_ID", &id)?;
        let min = env("SLURM_ARRAY_TASK_MIN")
            .map(|m| int("SLURM_ARRAY_TASK_MIN", &m))
            .transpose()?
            .unwrap_or(0);
        let step = env("SLURM_ARRAY_TASK_STEP")
            .map(|m| int("SLURM_ARRAY_TASK_STEP", &m))
            .transpose()?
            .unwrap_or(1);
        if step == 0 {
            // Slurm never sets 0; reading it as 1 would guess the array's grid.
            return Err(RunError::BadInput(
                "SLURM_ARRAY_TASK_STEP = 0: a job array's step is at least 1".into(),
            ));
        }
        // The array's own size, when Slurm says it, and how it said it.
        let size = match (env("SLURM_ARRAY_TASK_COUNT"), env("SLURM_ARRAY_TASK_MAX")) {
            (Some(c), _) => {
                let c = int("SLURM_ARRAY_TASK_COUNT", &c)?;
                Some((c, format!("SLURM_ARRAY_TASK_COUNT = {c}")))
            }
            (None, Some(max)) => {
                let size = int("SLURM_ARRAY_TASK_MAX", &max)?
                    .checked_sub(min)
                    .and_then(|span| (span / step).checked_add(1))
                    .ok_or_else(|| {
                        RunError::BadInput(format!(
                            "SLURM_ARRAY_TASK_MAX = {max} and SLURM_ARRAY_TASK_MIN = {min}: the \
                             array's size overflows a 64-bit integer"
                        ))
                    })?;
                let said = format!(
                    "SLURM_ARRAY_TASK_MIN = {min} to SLURM_ARRAY_TASK_MAX = {}, step {step}",
                    max.trim()
                );
                Some((size, said))
            }
            (None, None) => None,
        };
        let src = format!("SLURM_ARRAY_TASK_ID = {}", id);
        let count = match (count_flag, size) {
            // The index is the task's place in *this* array, which is the split only when the
            // array is: a task resubmitted alone (`sbatch --array=5`) is an array of one.
            (Some(n), Some((a, said))) if count_of_flag(n)? != a => {
                return Err(RunError::BadInput(format!(
                    "--shard-count = {n}, but {src} belongs to a job array of {a} task{} \
                     ({said}), so its place in that array is not its shard of {n} (a task \
                     resubmitted alone, sbatch --array={id}, is an array of its own): give the \
                     split itself, {}",
                    if a == 1 { "" } else { "s" },
                    shard_hint(id, n)
                )))
            }
            (Some(n), _) => count_of_flag(n)?,
            (None, Some((a, _))) => a,
            (None, None) => {
                return Err(RunError::BadInput(
                    "SLURM_ARRAY_TASK_ID is set but neither SLURM_ARRAY_TASK_COUNT nor \
                     SLURM_ARRAY_TASK_MAX: give --shard-count N"
                        .into(),
                ))
            }
        };
        let Some(offset) = id.checked_sub(min) else {
            return Err(RunError::BadInput(format!(
                "{src} and SLURM_ARRAY_TASK_MIN = {min}: their difference overflows a 64-bit \
                 integer"
            )));
        };
        if offset % step != 0 {
            return Err(RunError::BadInput(format!(
                "{src} is not on the array's grid (SLURM_ARRAY_TASK_MIN = {min}, step {step})"
            )));
        }
        let from = ShardFrom::Slurm {
            task_id: id,
            count_given: count_flag.is_some(),
        };
        return Shard::new(offset / step, count, src, from).map(Some);
    }
    if let Some(idx) = env("JOB_COMPLETION_INDEX") {
        let idx = int("JOB_COMPLETION_INDEX", &idx)?;
        let count = match (count_flag, env(SHARD_COUNT_ENV)) {
            (Some(n), _) => count_of_flag(n)?,
            (None, Some(c)) => int(SHARD_COUNT_ENV, &c)?,
            (None, None) => {
                return Err(RunError::BadInput(format!(
                    "JOB_COMPLETION_INDEX is set (Kubernetes Indexed Job) but the shard count is \
                     not: give --shard-count N or set {SHARD_COUNT_ENV} to the Job's completions"
                )))
            }
        };
        let src = format!("JOB_COMPLETION_INDEX = {idx}");
        return Shard::new(idx, count, src, ShardFrom::Kubernetes).map(Some);
    }
    if count_flag.is_some() {
        return Err(RunError::BadInput(
            "--shard-count needs a shard index: --shard I/N, SLURM_ARRAY_TASK_ID or \
             JOB_COMPLETION_INDEX"
                .into(),
        ));
    }
    Ok(None)
}

/// `--shard I/n, I being ...`: what a Slurm task `task_id` should be given for a split of `n`.
fn shard_hint(task_id: i64, n: usize) -> String {
    let example = match usize::try_from(task_id) {
        Ok(i) if i < n => format!(
            " (for an array 0-{}, its SLURM_ARRAY_TASK_ID: --shard {i}/{n})",
            n - 1
        ),
        _ => String::new(),
    };
    format!("--shard I/{n}, I being this task's index in the original array{example}")
}

/// The shards `i/count` not in `present`, the first few then how many more (`None`: all
/// present). Looks at no more than `present.len()` + [`LISTED`] indices: `count` may come
/// from a manifest a user edited.
pub(crate) fn absent_shards(present: &BTreeSet<usize>, count: usize) -> Option<String> {
    let absent = count - present.range(..count).count();
    if absent == 0 {
        return None;
    }
    let first: Vec<String> = (0..count)
        .filter(|i| !present.contains(i))
        .take(LISTED)
        .map(|i| format!("{i}/{count}"))
        .collect();
    let more = absent - first.len();
    let mut text = first.join(", ");
    if more > 0 {
        text += &format!(" and {more} more");
    }
    Some(text)
}

/// The shard manifests of one split found in an output folder.
#[derive(Default)]
struct Recorded {
    names: Vec<String>,
    /// The indices whose manifest says `complete`.
    complete: BTreeSet<usize>,
}

/// The splits recorded in `out` by shards of this kind and identity, by shard count.
/// Manifests of another config or kind are the identity check's (refused, or deleted with
/// `--force`); unreadable ones are merge's to refuse.
fn recorded_splits(
    out: &Path,
    kind: RunKind,
    hash: &str,
) -> Result<BTreeMap<usize, Recorded>, RunError> {
    let mut splits: BTreeMap<usize, Recorded> = BTreeMap::new();
    if !out.is_dir() {
        return Ok(splits);
    }
    for p in shard_manifest_paths(out)? {
        let Ok(m) = read_manifest(&p) else { continue };
        let Some(id) = m
            .shard
            .filter(|_| m.kind == kind && m.config_sha256 == hash)
        else {
            continue;
        };
        let r = splits.entry(id.count).or_default();
        r.names
            .push(p.file_name().unwrap_or_default().to_string_lossy().into());
        if m.status == "complete" {
            r.complete.insert(id.index);
        }
    }
    Ok(splits)
}

/// `a split into 8 (7 manifests: `shard-0-of-8.json`, ...; not complete there: 5/8)`.
fn describe_split(count: usize, r: &Recorded) -> String {
    let names = match r.names.len() {
        1 => format!("`{}`", r.names[0]),
        k => format!("{k} manifests: `{}`, ...", r.names[0]),
    };
    let open = absent_shards(&r.complete, count)
        .map_or(String::new(), |a| format!("; not complete there: {a}"));
    format!("a split into {count} ({names}{open})")
}

/// Checks the split of a shard against the output folder `out` (whose items are `item`s,
/// identity `hash`), before anything is computed or written. A scheduler's split is refused
/// when a Slurm array of one task gave it (what a task resubmitted alone, `sbatch --array=5`,
/// sees: the original array's size and numbering are gone, so it would run as shard 0/1), or
/// when `out` holds shards of this run in another split (merge would refuse the mix, and the
/// task's own shard would stay undone). A `--shard` the user wrote is obeyed: its disagreement
/// is returned as a warning.
pub fn check_split(
    out: &Path,
    shard: Option<&Shard>,
    kind: RunKind,
    hash: &str,
    item: &str,
) -> Result<Option<String>, RunError> {
    let Some(s) = shard else { return Ok(None) };
    let splits = recorded_splits(out, kind, hash)?;
    let other = splits.keys().any(|&c| c != s.count);
    let lone = matches!(
        s.from,
        ShardFrom::Slurm {
            count_given: false,
            ..
        }
    ) && s.count == 1;
    if !other && !lone {
        return Ok(None);
    }
    let found: Vec<String> = splits.iter().map(|(&c, r)| describe_split(c, r)).collect();
    let found = found.join(" and ");
    let anew = format!(
        "to split anew, delete the shard-I-of-N.json manifests in `{}` first (the {item} files \
         stay and are reused)",
        out.display()
    );
    if s.from == ShardFrom::Flag {
        return Ok(Some(format!(
            "`{}` also holds shards of {found}, not of this split into {}: gyroemu merge needs \
             the shards of one split; {anew}",
            out.display(),
            s.count
        )));
    }
    let head = if lone {
        format!(
            "{} is the only task of its job array, so the array does not say the split (it \
             would run as shard {}/{}: a task resubmitted alone, sbatch --array={}, no longer \
             knows the original array's size and numbering)",
            s.source,
            s.index,
            s.count,
            match s.from {
                ShardFrom::Slurm { task_id, .. } => task_id.to_string(),
                _ => "ID".into(),
            }
        )
    } else {
        format!(
            "{} makes this shard {}/{}, but `{}` holds shards of {found}",
            s.source,
            s.index,
            s.count,
            out.display()
        )
    };
    let keep: Vec<usize> = splits.keys().copied().collect();
    let fix = match (s.from, keep.as_slice()) {
        (_, [a, b, ..]) => format!(
            "`{}` already mixes splits into {a} and {b} shards: keep one (delete the other's \
             shard-I-of-N.json manifests) and give this task its shard of that split with \
             --shard I/N",
            out.display()
        ),
        (ShardFrom::Slurm { task_id, .. }, [m]) => format!(
            "give this task its shard of that split: {}; or, {anew}",
            shard_hint(task_id, *m)
        ),
        (ShardFrom::Slurm { task_id, .. }, []) => format!(
            "give the split: --shard I/N, N the number of shards and I this task's index in \
             the array (for an array 0-(N-1), its SLURM_ARRAY_TASK_ID: --shard {task_id}/N), \
             as the job script of docs/cluster.md does"
        ),
        (_, [m]) => format!(
            "give every task the count of that split (GYROEMU_SHARD_COUNT = {m}, or \
             --shard-count {m}); or, {anew}"
        ),
        (_, []) => anew,
    };
    let lone_found = if lone && !splits.is_empty() {
        format!("; `{}` holds shards of {found}", out.display())
    } else {
        String::new()
    };
    Err(RunError::BadInput(format!("{head}{lone_found}: {fix}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env_of(vars: &'static [(&'static str, &'static str)]) -> impl Fn(&str) -> Option<String> {
        move |k| {
            vars.iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| v.to_string())
        }
    }

    #[test]
    fn flag_env_and_errors() {
        let none = env_of(&[]);
        assert_eq!(resolve_shard(None, None, &none).unwrap(), None);
        let s = resolve_shard(Some("2/4"), None, &none).unwrap().unwrap();
        assert_eq!((s.index, s.count), (2, 4));
        assert_eq!(s.points(11), vec![2, 6, 10]);
        for bad in ["4/4", "1", "-1/3", "a/2", "0/0"] {
            assert!(resolve_shard(Some(bad), None, &none).is_err(), "{bad}");
        }
        let slurm = env_of(&[
            ("SLURM_ARRAY_TASK_ID", "3"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ]);
        let s = resolve_shard(None, None, &slurm).unwrap().unwrap();
        assert_eq!((s.index, s.count), (3, 4));
        // An array 1-4: ids 1..=4 map to shards 0..=3.
        let slurm = env_of(&[
            ("SLURM_ARRAY_TASK_ID", "1"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
            ("SLURM_ARRAY_TASK_MAX", "4"),
        ]);
        let s = resolve_shard(None, None, &slurm).unwrap().unwrap();
        assert_eq!((s.index, s.count), (0, 4));
        // An array 10-16:2 (10, 12, 14, 16): id 14 is shard 2 of 4.
        let slurm = env_of(&[
            ("SLURM_ARRAY_TASK_ID", "14"),
            ("SLURM_ARRAY_TASK_MIN", "10"),
            ("SLURM_ARRAY_TASK_MAX", "16"),
            ("SLURM_ARRAY_TASK_STEP", "2"),
        ]);
        let s = resolve_shard(None, None, &slurm).unwrap().unwrap();
        assert_eq!((s.index, s.count), (2, 4));
        // A step of 0 is no grid: refused, not read as 1.
        let slurm = env_of(&[
            ("SLURM_ARRAY_TASK_ID", "14"),
            ("SLURM_ARRAY_TASK_MIN", "10"),
            ("SLURM_ARRAY_TASK_MAX", "16"),
            ("SLURM_ARRAY_TASK_STEP", "0"),
        ]);
        match resolve_shard(None, None, &slurm) {
            Err(RunError::BadInput(m)) => assert!(m.contains("SLURM_ARRAY_TASK_STEP = 0"), "{m}"),
            other => panic!("step 0 not refused: {other:?}"),
        }
        let k8s = env_of(&[("JOB_COMPLETION_INDEX", "5")]);
        assert!(resolve_shard(None, None, &k8s).is_err());
        let s = resolve_shard(None, Some(8), &k8s).unwrap().unwrap();
        assert_eq!((s.index, s.count), (5, 8));
        let k8s = env_of(&[("JOB_COMPLETION_INDEX", "5"), (SHARD_COUNT_ENV, "6")]);
        assert_eq!(resolve_shard(None, None, &k8s).unwrap().unwrap().count, 6);
        assert!(resolve_shard(None, Some(3), &none).is_err());
    }

    /// The message of `resolve_shard`'s refusal.
    fn refusal(
        flag: Option<&str>,
        count: Option<usize>,
        env: &dyn Fn(&str) -> Option<String>,
    ) -> String {
        match resolve_shard(flag, count, env) {
            Err(RunError::BadInput(m)) => m,
            other => panic!("not refused: {other:?}"),
        }
    }

    #[test]
    fn a_shard_count_beside_a_shard_must_agree_with_it() {
        let none = |_: &str| None;
        let s = resolve_shard(Some("0/3"), Some(3), &none).unwrap().unwrap();
        assert_eq!((s.index, s.count), (0, 3));
        for n in [4, 0] {
            let m = refusal(Some("0/3"), Some(n), &none);
            assert!(
                m.contains("splits into 3 shards but --shard-count = ")
                    && m.contains("--shard I/N alone"),
                "{n}: {m}"
            );
        }
        // Digits past the range are an integer, too large; letters are not an integer.
        let m = refusal(Some("0/18446744073709551615"), None, &none);
        assert!(m.contains("an integer out of range"), "{m}");
        let m = refusal(Some("0/x"), None, &none);
        assert!(m.contains("`x`: not an integer"), "{m}");
    }

    #[test]
    fn numbers_past_the_64_bit_range_are_refused_not_wrapped() {
        type Vars = &'static [(&'static str, &'static str)];
        /// The flag, `--shard-count`, the environment, what the refusal names.
        type Case = (Option<&'static str>, Option<usize>, Vars, [&'static str; 2]);
        // Before, the Slurm sums wrapped into a negative shard, refused under the wrong rule.
        let cases: [Case; 5] = [
            (
                Some("0/18446744073709551615"),
                None,
                &[],
                ["--shard count", "at most 9223372036854775807"],
            ),
            (
                None,
                None,
                &[
                    ("SLURM_ARRAY_TASK_ID", "0"),
                    ("SLURM_ARRAY_TASK_MIN", "-9223372036854775807"),
                    ("SLURM_ARRAY_TASK_MAX", "9223372036854775807"),
                ],
                ["SLURM_ARRAY_TASK_MAX", "overflows"],
            ),
            (
                // MAX - MIN fits, one more task does not.
                None,
                None,
                &[
                    ("SLURM_ARRAY_TASK_ID", "0"),
                    ("SLURM_ARRAY_TASK_MAX", "9223372036854775807"),
                ],
                ["SLURM_ARRAY_TASK_MAX", "overflows"],
            ),
            (
                None,
                None,
                &[
                    ("SLURM_ARRAY_TASK_ID", "9223372036854775807"),
                    ("SLURM_ARRAY_TASK_MIN", "-2"),
                    ("SLURM_ARRAY_TASK_COUNT", "4"),
                ],
                ["SLURM_ARRAY_TASK_ID", "overflows"],
            ),
            (
                None,
                Some(usize::MAX),
                &[("JOB_COMPLETION_INDEX", "1")],
                ["--shard-count = 18446744073709551615", "at most"],
            ),
        ];
        for (flag, count, vars, needles) in cases {
            let m = refusal(flag, count, &env_of(vars));
            assert!(needles.iter().all(|n| m.contains(n)), "{m}");
        }
    }

    #[test]
    fn a_shard_count_beside_a_slurm_array_of_another_size_is_refused() {
        // `sbatch --array=5` resubmitting task 5 of an array 0-7: an array of its own. Before,
        // `--shard-count 8` made it shard 0/8 (its place in that array), silently.
        let alone = env_of(&[
            ("SLURM_ARRAY_TASK_ID", "5"),
            ("SLURM_ARRAY_TASK_MIN", "5"),
            ("SLURM_ARRAY_TASK_MAX", "5"),
            ("SLURM_ARRAY_TASK_COUNT", "1"),
        ]);
        let m = refusal(None, Some(8), &alone);
        for needle in ["--shard-count = 8", "array of 1 task ", "--shard 5/8"] {
            assert!(m.contains(needle), "{needle}: {m}");
        }
        // Without the count the array is the split: 0/1, a lone task (`check_split` refuses it).
        let s = resolve_shard(None, None, &alone).unwrap().unwrap();
        assert_eq!((s.index, s.count), (0, 1));
        let lone = ShardFrom::Slurm {
            task_id: 5,
            count_given: false,
        };
        assert_eq!(s.from, lone);
        // The count equal to the array's size is the split it says.
        let whole = env_of(&[
            ("SLURM_ARRAY_TASK_ID", "5"),
            ("SLURM_ARRAY_TASK_MIN", "0"),
            ("SLURM_ARRAY_TASK_MAX", "7"),
        ]);
        let s = resolve_shard(None, Some(8), &whole).unwrap().unwrap();
        assert_eq!((s.index, s.count), (5, 8));
        assert!(refusal(None, Some(4), &whole).contains("array of 8 tasks"));
        assert_eq!(parse_shard("1/2").unwrap().from, ShardFrom::Flag);
    }

    #[test]
    fn a_count_past_the_items_and_the_sparse_bound_is_refused() {
        // Twenty shards of eight points: a uniform job array, its empty shards merge.
        assert!(parse_shard("0/20").unwrap().check_count(8, "point").is_ok());
        assert!(parse_shard("0/5000")
            .unwrap()
            .check_count(5000, "device")
            .is_ok());
        for text in ["1/1000000", "0/9223372036854775807"] {
            let Err(RunError::BadInput(m)) = parse_shard(text).unwrap().check_count(8, "point")
            else {
                panic!("{text} accepted");
            };
            assert!(m.contains(text) && m.contains("1024"), "{m}");
        }
    }

    #[test]
    fn absent_shards_are_listed_briefly_whatever_the_count() {
        let present: BTreeSet<usize> = [1, 3].into();
        assert_eq!(absent_shards(&present, 4).as_deref(), Some("0/4, 2/4"));
        assert_eq!(absent_shards(&[0, 1].into(), 2), None);
        // Before, merge built a string for each of these.
        let m = absent_shards(&present, usize::MAX).unwrap();
        let n = usize::MAX;
        assert_eq!(
            m,
            format!("0/{n}, 2/{n}, 4/{n}, 5/{n}, 6/{n} and {} more", n - 7)
        );
    }
}
