//! Fits two cubes of 64 points, 1 m apart, one dark (gray 0.2) and one
//! bright (0.8), saves and loads the model and regresses gray at the cubes'
//! centres. With a bandwidth of 0.05 m, far below the gap and above the
//! cubes' 0.03 m size, mean shift finds exactly two modes, and each centre's
//! gray is its cube's. Exits non-zero unless all of that holds.
//! Usage: sogmm-consumer <scratch-dir>
use std::path::PathBuf;
use std::process::ExitCode;

use sogmm::Queryable;

fn cubes() -> Vec<f32> {
    let mut points = Vec::new();
    for (c, gray) in [0.2f32, 0.8].into_iter().enumerate() {
        for i in 0..4 {
            for j in 0..4 {
                for k in 0..4 {
                    let (i, j, k) = (i as f32, j as f32, k as f32);
                    points.extend([c as f32 + 0.01 * i, 0.01 * j, 1.0 + 0.01 * k, gray]);
                }
            }
        }
    }
    points
}

fn run(path: PathBuf) -> Result<(), Box<dyn std::error::Error>> {
    let opts = sogmm::Options::builder().bandwidth(0.05).seed(1).build()?;
    let model = sogmm::Model::fit(&cubes(), Some(&opts))?;
    model.save(&path, None)?;
    let loaded = sogmm::Model::load(&path, None)?;
    let (gray, _) = loaded.regress_gray(&[0.015, 0.015, 1.015, 1.015, 0.015, 1.015], None)?;
    let (fitted, m) = (model.n_components(), loaded.n_components());
    println!(
        "{fitted} components fitted, {m} loaded from {}, gray {:.3} and {:.3}",
        path.display(),
        gray[0],
        gray[1]
    );
    if fitted != 2 || m != 2 || (gray[0] - 0.2).abs() > 0.01 || (gray[1] - 0.8).abs() > 0.01 {
        return Err("wrong result: expected 2 components and gray 0.2 / 0.8".into());
    }
    Ok(())
}

fn main() -> ExitCode {
    let Some(dir) = std::env::args_os().nth(1) else {
        eprintln!("usage: sogmm-consumer <scratch-dir>");
        return ExitCode::from(2);
    };
    match run(PathBuf::from(dir).join("consumer_rust.sogmm")) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}
