//! Which share of a sweep's operating points this process runs: `--shard i/n`, or the index a
//! scheduler gives an array task (Slurm job arrays, Kubernetes Indexed Jobs). Point `p` belongs
//! to shard `p % n`, so the assignment depends on nothing but the config and `n`.

use crate::error::RunError;

/// Shard `index` of `count` (0-based), and where that came from (for messages).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
    pub source: String,
}

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
            Some(s) => format!(
                "shard {}/{} ({}): {} of the {n} {item}s",
                s.index,
                s.count,
                s.source,
                s.points(n).len()
            ),
            None => format!("{n} {item}s"),
        }
    }

    /// The manifest name of this shard inside the output folder.
    pub fn manifest_name(&self) -> String {
        format!("shard-{}-of-{}.json", self.index, self.count)
    }

    fn new(index: i64, count: i64, source: String) -> Result<Self, RunError> {
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
        })
    }
}

/// `--shard-count N` as the signed count the rules compare (an `N` past `i64::MAX` refused).
fn count_of_flag(n: usize) -> Result<i64, RunError> {
    i64::try_from(n).map_err(|_| {
        RunError::BadInput(format!("--shard-count = {n}: must be at most {}", i64::MAX))
    })
}

fn int(name: &str, text: &str) -> Result<i64, RunError> {
    text.trim().parse().map_err(|_| {
        RunError::BadInput(format!(
            "{name} = `{text}`: not an integer (at most {})",
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
    Shard::new(int("--shard index", i)?, int("--shard count", n)?, src)
}

/// The shard of this process: `--shard` if given, else the Slurm array task
/// (`SLURM_ARRAY_TASK_ID` minus `SLURM_ARRAY_TASK_MIN`, over `SLURM_ARRAY_TASK_STEP`, of
/// `SLURM_ARRAY_TASK_COUNT` shards, or of those `MIN` to `SLURM_ARRAY_TASK_MAX`), else a Kubernetes Indexed Job
/// (`JOB_COMPLETION_INDEX` with `--shard-count` or `GYROEMU_SHARD_COUNT`); `None`: no sharding.
pub fn resolve_shard(
    flag: Option<&str>,
    count_flag: Option<usize>,
    env: &dyn Fn(&str) -> Option<String>,
) -> Result<Option<Shard>, RunError> {
    if let Some(f) = flag {
        return parse_shard(f).map(Some);
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
            .unwrap_or(1)
            .max(1);
        let count = match (
            count_flag,
            env("SLURM_ARRAY_TASK_COUNT"),
            env("SLURM_ARRAY_TASK_MAX"),
        ) {
            (Some(n), _, _) => count_of_flag(n)?,
            (None, Some(c), _) => int("SLURM_ARRAY_TASK_COUNT", &c)?,
            (None, None, Some(max)) => int("SLURM_ARRAY_TASK_MAX", &max)?
                .checked_sub(min)
                .and_then(|span| (span / step).checked_add(1))
                .ok_or_else(|| {
                    RunError::BadInput(format!(
                        "SLURM_ARRAY_TASK_MAX = {max} and SLURM_ARRAY_TASK_MIN = {min}: the \
                         array's size overflows a 64-bit integer"
                    ))
                })?,
            _ => {
                return Err(RunError::BadInput(
                    "SLURM_ARRAY_TASK_ID is set but neither SLURM_ARRAY_TASK_COUNT nor \
                     SLURM_ARRAY_TASK_MAX: give --shard-count N"
                        .into(),
                ))
            }
        };
        let src = format!("SLURM_ARRAY_TASK_ID = {}", id);
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
        return Shard::new(offset / step, count, src).map(Some);
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
        return Shard::new(idx, count, src).map(Some);
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
}
