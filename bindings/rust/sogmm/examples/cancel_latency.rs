//! Measures how long `Model::fit` with a progress closure takes to return once a cancel
//! is requested (from another thread) about 1 s into a d = 1 fit (issue 16).
//! Input: a frame's points as raw float32 rows (x, y, z, gray), as written by
//! tools/sogmm-perf/cancel_latency.py --dump FILE.
//! Run: SOGMM_LIB_DIR=<build>/capi cargo run --release --example cancel_latency -- FILE [runs] [delay-s]
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use sogmm::{Model, Options, Status};

fn main() -> Result<(), sogmm::Error> {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .expect("usage: cancel_latency POINTS.f32 [runs] [delay-seconds]");
    let raw = std::fs::read(path).expect("cannot read the points file");
    assert!(raw.len() % 16 == 0, "not n x 4 float32 values");
    let pts: Vec<f32> = raw
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let runs: usize = args.get(2).map_or(5, |s| s.parse().unwrap());
    let delay: f64 = args.get(3).map_or(1.0, |s| s.parse().unwrap());
    let base = Options::builder().bandwidth(0.02).seed(0);
    println!(
        "rust: d = 1 fit of {} points, cancel requested after {delay} s",
        pts.len() / 4
    );
    let mut lat = Vec::new();
    for r in 0..runs {
        let stop = Arc::new(AtomicBool::new(false));
        let sent: Arc<Mutex<Option<Instant>>> = Arc::new(Mutex::new(None));
        let (stop2, sent2) = (stop.clone(), sent.clone());
        let timer = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_secs_f64(delay));
            *sent2.lock().unwrap() = Some(Instant::now());
            stop2.store(true, Ordering::SeqCst);
        });
        let opts = base
            .clone()
            .on_progress(move |_| {
                if stop.load(Ordering::SeqCst) {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            })
            .build()?;
        let result = Model::fit(&pts, Some(&opts));
        let done = Instant::now();
        timer.join().unwrap();
        match result {
            Err(e) if e.status() == Status::Cancelled => {}
            other => panic!("the fit ended before the cancel: {other:?}"),
        }
        let ms = done.duration_since(sent.lock().unwrap().unwrap()).as_secs_f64() * 1e3;
        println!("  run {}: {ms:.1} ms", r + 1);
        lat.push(ms);
    }
    lat.sort_by(f64::total_cmp);
    println!(
        "rust cancel latency: median {:.1} ms, max {:.1} ms over {runs} runs",
        lat[lat.len() / 2],
        lat[lat.len() - 1]
    );
    Ok(())
}
