//! A dump written early (`SweepOptions::on_dump_early`): the same files as one written after
//! the sweep, the hook's files listed apart, the dump's group passed on only after both, and a
//! failing hook stops the sweep without saving that group.

use gyroemu_board::{LaneResult, DUMP_NODES};
use gyroemu_config::{presets::preset, Config};
use gyroemu_experiment::{
    run_sweep_with, DumpPlan, OnDump, OnGroup, SweepError, SweepOptions, SweepRun,
};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

fn small() -> Config {
    let mut cfg = preset("m2tfg-coriolis").unwrap();
    cfg.experiment.average_s = 0.1;
    cfg.experiment.settle_s = Some(0.02);
    cfg.experiment.rates_dps = vec![25.0, 50.0, 75.0, 100.0, 125.0, 150.0];
    cfg
}

fn plan() -> DumpPlan {
    DumpPlan {
        rate_dps: 75.0,
        start_s: 0.03,
        duration_s: 0.001,
        decimated_duration_s: 0.05,
        nodes: DUMP_NODES.map(String::from).to_vec(),
    }
}

/// Index of the dumped point (75 deg/s) in the emulated rates.
const DUMPED: usize = 2;

fn names(files: &[PathBuf]) -> Vec<String> {
    files
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect()
}

fn sweep(dir: &Path, opts: SweepOptions) -> Result<SweepRun, SweepError> {
    run_sweep_with(&small(), &|_, _| {}, Some(dir), opts)
}

/// The sweep with the dump written early through `hook`, each group passed to `on_group`.
fn early_sweep(dir: &Path, on_group: OnGroup, hook: OnDump) -> Result<SweepRun, SweepError> {
    sweep(
        dir,
        SweepOptions {
            dump: Some(plan()),
            on_group: Some(on_group),
            on_dump_early: Some(hook),
            ..Default::default()
        },
    )
}

#[test]
fn an_early_dump_writes_the_same_files_and_lists_the_hooks_apart() {
    let late_dir = tempfile::tempdir().unwrap();
    let late = sweep(
        late_dir.path(),
        SweepOptions {
            dump: Some(plan()),
            ..Default::default()
        },
    )
    .unwrap();

    let dir = tempfile::tempdir().unwrap();
    let hooked = AtomicBool::new(false);
    let given = Mutex::new(Vec::new());
    let hook = |files: &[PathBuf]| -> Result<Vec<PathBuf>, String> {
        // The dump is on disk when the hook runs.
        assert!(files.iter().all(|f| f.exists()));
        given.lock().unwrap().extend(names(files));
        let made = dir.path().join("made.txt");
        std::fs::write(&made, "from the dump").map_err(|e| e.to_string())?;
        hooked.store(true, Ordering::SeqCst);
        Ok(vec![made])
    };
    let passed = Mutex::new(Vec::new());
    let on_group = |pts: &[(usize, LaneResult)]| {
        let after = hooked.load(Ordering::SeqCst);
        passed
            .lock()
            .unwrap()
            .extend(pts.iter().map(|p| (p.0, after)));
        Ok(())
    };
    let early = early_sweep(dir.path(), &on_group, &hook).unwrap();

    assert_eq!(early.lanes, late.lanes);
    assert_eq!(names(&early.dump_files), names(&late.dump_files));
    assert_eq!(*given.lock().unwrap(), names(&late.dump_files));
    assert_eq!(names(&early.dump_made), ["made.txt"]);
    assert!(late.dump_made.is_empty());
    assert_eq!(early.dump_bytes, late.dump_bytes);
    assert_eq!(early.written().files, 8);
    for (a, b) in early.dump_files.iter().zip(&late.dump_files) {
        assert_eq!(
            std::fs::read(a).unwrap(),
            std::fs::read(b).unwrap(),
            "{a:?}"
        );
    }
    let passed = passed.into_inner().unwrap();
    assert!(passed.contains(&(DUMPED, true)), "{passed:?}");
    assert_eq!(passed.len(), small().emulated_rates_dps().len());
}

#[test]
fn a_failing_hook_stops_the_sweep_and_leaves_its_group_unsaved() {
    let dir = tempfile::tempdir().unwrap();
    let hook = |_: &[PathBuf]| -> Result<Vec<PathBuf>, String> { Err("no figures".into()) };
    let passed = Mutex::new(Vec::new());
    let on_group = |pts: &[(usize, LaneResult)]| {
        passed.lock().unwrap().extend(pts.iter().map(|p| p.0));
        Ok(())
    };
    let err = early_sweep(dir.path(), &on_group, &hook).unwrap_err();
    assert!(err.to_string().contains("no figures"), "{err}");
    assert!(!passed.into_inner().unwrap().contains(&DUMPED));
}
