//! `gyroemu`: emulate a MEMS gyroscope readout board sample by sample and reproduce the
//! figures of Casinovi et al., "Electrostatic Self-Calibration of Vibratory Gyroscopes"
//! (MEMS 2012).

/// `eprintln!` that never panics: a closed stderr (`2>&-`, or a pipe whose reader has left)
/// must not turn a finished run into a panic's exit code 101.
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// `println!` that never panics, for the same reason (`gyroemu selfcal ... | head -1`: a
/// reader that closed the pipe ends the output quietly), and whose other failures are the
/// command's (`> /dev/full` lost selfcal's headline with exit 0): `?` in a function returning
/// `anyhow::Result`, as [`input::print_out`].
macro_rules! say {
    ($($arg:tt)*) => {
        $crate::input::print_out(&format!("{}\n", format_args!($($arg)*)))?
    };
}

mod cmd;
mod cpu_check;
mod input;
mod lot_text;
mod progress;
mod signals;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "gyroemu",
    version,
    about = "Sample-level emulator of a MEMS gyroscope readout board and its electrostatic self-calibration"
)]
struct Cli {
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long, global = true)]
    threads: Option<usize>,
    /// For tests and benchmarks: the widest lane group, 4 or 8 operating points, for every
    /// chain (default: chosen per chain, 8 on a CPU with AVX-512 except where 4 run faster,
    /// else 4). Results do not depend on it.
    #[arg(long, global = true, hide = true)]
    lanes: Option<usize>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Reproduce Figs. 4, 5, 6, 8 and 9 on the embedded default configs.
    Reproduce {
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Shorten the averaging (Fig. 9: 15 s instead of 500 s) for a fast look.
        #[arg(long)]
        quick: bool,
    },
    /// Run one experiment described by a TOML config.
    Run {
        /// The config file (see `gyroemu config`).
        config: PathBuf,
        #[command(flatten)]
        out: cmd::out_args::OutArgs,
    },
    /// A production lot: devices drawn from the tolerances of the config's [montecarlo]
    /// section, each self-calibrated on the emulated board; writes the distribution of the
    /// self-calibration error and the yield within the spec.
    Montecarlo {
        /// The config file (the nominal device, board and sweeps, plus [montecarlo]).
        config: PathBuf,
        /// Devices in the lot (device i is the same in a lot of any size).
        #[arg(long, value_name = "N", required_unless_present = "print_device")]
        devices: Option<usize>,
        #[command(flatten)]
        out: cmd::out_args::OutArgs,
        /// Print the config of device I (for `gyroemu selfcal`) instead of running the lot.
        #[arg(long, value_name = "I", conflicts_with_all = ["shard", "shard_count", "force"])]
        print_device: Option<u64>,
    },
    /// Check the shards in DIR (all present, one config, every point or device once) and
    /// write the results a one-machine run would have written.
    Merge {
        /// The output folder the shards wrote into.
        dir: PathBuf,
    },
    /// Self-calibrate: the scale factor from the rotating excitation alone, checked against
    /// the virtual rate table on the same board (plus the analyses of the [selfcal] section).
    Selfcal {
        /// The config file (the same as `run` takes; its rates are used for both sweeps).
        config: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Run even when the plan exceeds the cap of 1e11 point-samples.
        #[arg(long)]
        force: bool,
    },
    /// Characterise the device as the lab does: a stepped-sine frequency response of each
    /// mode through the board (Bode plot, CSV) and a resonance fit (f0, Q, mode split)
    /// checked against the configured device.
    Sweep {
        /// The config file (its [sweep] section, or the defaults derived from the device).
        config: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Run even when the plan exceeds the cap of 1e11 point-samples.
        #[arg(long)]
        force: bool,
    },
    /// Measure throughput: the whole chain on 1 and on all threads, and each stage.
    Bench {
        /// Preset whose board is measured (the rotating one exercises every stage).
        #[arg(long, default_value = "m2tfg-rotating")]
        preset: String,
        /// Input samples per lane group.
        #[arg(long, default_value_t = 1 << 24)]
        samples: u64,
        /// Runs of each measurement; the best and the median are printed (a shared machine
        /// varies by 10 % or more from run to run).
        #[arg(long, default_value_t = 5)]
        repeats: usize,
    },
    /// Print each channel's RMS, peak and strongest tones of a signal dump, and render its
    /// signals.png (nodes in time) and spectrum.png (Welch spectra, carrier and sidebands
    /// marked).
    Inspect {
        /// The dump: a .sigmf-meta, .sigmf-data or .csv file, their common stem, the stem of
        /// a `_fullrate`/`_decimated` pair (e.g. out/dump), or a folder holding dump_*.
        dump: PathBuf,
        /// Folder for the figures (default: the dump's own folder).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Print a preset's commented config that `run` accepts (its keys; the guide's section 3 lists every optional one).
    Config {
        /// Preset name (default: m2tfg-coriolis); `--list` shows them.
        #[arg(long)]
        preset: Option<String>,
        /// List the presets.
        #[arg(long, conflicts_with = "preset")]
        list: bool,
        /// Print FILE with every key filled in: the derived defaults and their rules.
        #[arg(long, value_name = "FILE", conflicts_with_all = ["preset", "list"])]
        resolved: Option<PathBuf>,
    },
}

/// Exit code for a config or usage the emulator refuses.
pub const EXIT_BAD_INPUT: u8 = 2;

/// The most worker threads `--threads` accepts: more than the hardware threads of any
/// machine this runs on (a two-socket server has a few hundred).
pub const MAX_THREADS: usize = 1024;

/// The exit code of a failed command: 2 for refused input, 130 for an interrupted run, 1 for
/// a failure while running.
fn exit_code(e: &anyhow::Error) -> u8 {
    use gyroemu_runs::RunError;
    match e.downcast_ref::<RunError>() {
        Some(RunError::BadInput(_) | RunError::Locked(_)) => return EXIT_BAD_INPUT,
        Some(RunError::Interrupted(_)) => return signals::EXIT_INTERRUPTED,
        _ => {}
    }
    if e.downcast_ref::<input::BadInput>().is_some() {
        EXIT_BAD_INPUT
    } else {
        1
    }
}

fn main() -> ExitCode {
    // Nothing but the CPU check may run before it: the rest is out of line.
    if let Err(e) = cpu_check::cpu_supports_build() {
        // Static bytes only: formatting could already use AVX to copy them.
        let mut err = std::io::stderr();
        std::io::Write::write_all(&mut err, b"error: ").ok();
        std::io::Write::write_all(&mut err, e.as_bytes()).ok();
        return ExitCode::FAILURE;
    }
    run_cli()
}

#[inline(never)]
fn run_cli() -> ExitCode {
    let cli = Cli::parse();
    if let Some(t) = cli.threads {
        if !(1..=MAX_THREADS).contains(&t) {
            // A mistyped count would otherwise start that many OS threads before anything.
            note!("error: --threads = {t}: must be from 1 to {MAX_THREADS}");
            return ExitCode::from(EXIT_BAD_INPUT);
        }
        // No pool exists this early, so only the OS can refuse the threads.
        if let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build_global()
        {
            note!("error: --threads = {t}: the worker threads could not be started ({e})");
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    }
    if let Some(n) = cli.lanes {
        if let Err(e) = gyroemu_board::set_max_lanes(n) {
            note!("error: {e}");
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    }
    let result = match cli.command {
        Command::Reproduce { out, quick } => cmd::reproduce::reproduce_command(&out, quick),
        Command::Run { config, out } => cmd::run::run_command(&config, &out),
        Command::Montecarlo {
            config,
            devices,
            out,
            print_device,
        } => cmd::montecarlo::montecarlo_command(&cmd::montecarlo::MonteCarloArgs {
            config: &config,
            devices,
            out: &out,
            print_device,
        }),
        Command::Merge { dir } => cmd::merge::merge_command(&dir),
        Command::Selfcal { config, out, force } => {
            cmd::selfcal::selfcal_command(&config, &out, force)
        }
        Command::Sweep { config, out, force } => cmd::sweep::sweep_command(&config, &out, force),
        Command::Config {
            preset,
            list,
            resolved,
        } => match resolved {
            Some(path) => cmd::config::resolved_command(&path),
            None => cmd::config::config_command(preset.as_deref(), list),
        },
        Command::Inspect { dump, out } => cmd::inspect::inspect_command(&dump, out.as_deref()),
        Command::Bench {
            preset,
            samples,
            repeats,
        } => cmd::bench::bench_command(&preset, samples, repeats),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            note!("error: {e:#}");
            ExitCode::from(exit_code(&e))
        }
    }
}
