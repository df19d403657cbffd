//! divan benchmark of writing a signal dump (`cargo bench -p gyroemu-io`): one second of the
//! full-rate nodes at 240 kHz (12 channels, the size `[dump] duration_s = 1` gives on the
//! M^2-TFG presets), as CSV alone and as every format. Throughput is in bytes of CSV.

use divan::counter::BytesCount;
use divan::Bencher;
use gyroemu_io::SignalRecorder;

const FRAMES: u64 = 240_000;
const CHANNELS: usize = 12;

fn main() {
    divan::main();
}

/// A recorder holding one second of twelve carrier-like channels.
fn recorder() -> SignalRecorder {
    let names = (0..CHANNELS).map(|k| format!("ch{k}_v")).collect();
    let mut r = SignalRecorder::new(names, 240_000.0, 1_000_000, FRAMES);
    let mut frame = [0.0; CHANNELS];
    for n in 1_000_000..1_000_000 + FRAMES {
        for (k, v) in frame.iter_mut().enumerate() {
            *v = 1e-3 * (k + 1) as f64 * (std::f64::consts::FRAC_PI_8 * n as f64 + k as f64).cos();
        }
        r.record(n, &frame);
    }
    r
}

#[divan::bench(sample_count = 3, sample_size = 1)]
fn csv_one_second_12_channels(b: Bencher) {
    let r = recorder();
    let dir = tempfile::tempdir().expect("temporary folder");
    let path = dir.path().join("d.csv");
    r.write_csv(&path).expect("write");
    let bytes = std::fs::metadata(&path).expect("written").len();
    b.counter(BytesCount::new(bytes))
        .bench(|| r.write_csv(&path).expect("write"));
}

#[divan::bench(sample_count = 3, sample_size = 1)]
fn all_formats_one_second_12_channels(b: Bencher) {
    let r = recorder();
    let dir = tempfile::tempdir().expect("temporary folder");
    b.bench(|| r.write(dir.path(), "d").expect("write"));
}
