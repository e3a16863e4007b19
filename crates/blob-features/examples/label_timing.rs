//! Wall and CPU time of labelling a 4000 x 4000 map with 1 and 2 threads; complements the
//! criterion bench on a shared machine, where wall time alone says more about the neighbours.
//!
//! `cargo run --release -p blob-features --example label_timing`

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use blob_features::{Connectivity, Labeler};

/// User + system CPU time of this process in ms (Linux `/proc`, 10 ms ticks), if readable.
fn process_cpu_ms() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let f: Vec<&str> = stat.rsplit(')').next()?.split_whitespace().collect();
    Some((f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?) * 10.0)
}

fn main() {
    let (w, h, runs) = (4000, 4000, 20);
    for (name, mask) in [
        ("floor_plan", common::floor_plan(w, h, 120, 7)),
        ("random_50pct", common::random_mask(w, h, 0.5, 7)),
    ] {
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut labeler = Labeler::new(Connectivity::Eight);
            let mut labels = Vec::new();
            let n = pool.install(|| labeler.label(&mask, w, h, &mut labels).unwrap());
            let (c0, t0) = (process_cpu_ms(), Instant::now());
            let mut best = f64::INFINITY;
            for _ in 0..runs {
                let t = Instant::now();
                pool.install(|| labeler.label(&mask, w, h, &mut labels).unwrap());
                best = best.min(t.elapsed().as_secs_f64() * 1e3);
            }
            let wall = t0.elapsed().as_secs_f64() * 1e3 / runs as f64;
            let cpu = match (c0, process_cpu_ms()) {
                (Some(a), Some(b)) => format!("{:.1} ms", (b - a) / runs as f64),
                _ => "n/a".into(),
            };
            println!(
                "{name:12} {threads} thread(s): {n} components, wall mean {wall:.1} ms, min {best:.1} ms, CPU {cpu} per labelling"
            );
        }
    }
}
