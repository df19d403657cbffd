// Scratch (not committed).
fn main() {
    let names = [
        "m2tfg-coriolis",
        "m2tfg-rotating",
        "baw-coriolis",
        "baw-rotating",
        "m2tfg-ratetable",
    ];
    for _ in 0..2 {
        let mut line = String::new();
        for n in names {
            let c = gyroemu_config::presets::preset(n).unwrap();
            let t = std::time::Instant::now();
            c.validate().unwrap();
            line += &format!("{n} {:.2} ms; ", t.elapsed().as_secs_f64() * 1e3);
        }
        let rt = gyroemu_config::presets::preset("m2tfg-ratetable").unwrap();
        let mut tot = 0.0;
        for f in &gyroemu_analysis::bandwidth::BANDWIDTH_FREQS_HZ {
            let t = std::time::Instant::now();
            gyroemu_analysis::bandwidth::bandwidth_config(&rt, *f).unwrap();
            let e = t.elapsed().as_secs_f64() * 1e3;
            tot += e;
            line += &format!("bw{f} {e:.2}; ");
        }
        println!("{line} bw total {tot:.1}");
    }
    let rt = gyroemu_config::presets::preset("m2tfg-ratetable").unwrap();
    for _ in 0..40 {
        for f in &gyroemu_analysis::bandwidth::BANDWIDTH_FREQS_HZ {
            gyroemu_analysis::bandwidth::bandwidth_config(&rt, *f).unwrap();
        }
    }
}
