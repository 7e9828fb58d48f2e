//! The Rust participant of the cross-language matrix test (protocol:
//! bindings/matrix/run_matrix.py).
//!   matrix write <points.f32> <out.sogmm>
//!   matrix read <in.sogmm> <query.f32> <out.bin>
//!   matrix frame <depth.png> <color image> <out.sogmm>
use std::io::Write;
use std::path::Path;

use sogmm::{ImageFrame, Model, Options, Queryable};

fn floats(path: &str) -> Vec<f32> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("cannot read {path}: {e}"));
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    match args.iter().map(String::as_str).collect::<Vec<_>>()[1..] {
        ["write", points, out] => {
            let opts = Options::builder().bandwidth(0.05).seed(16).threads(1).build()?;
            Model::fit(&floats(points), Some(&opts))?.save(out, None)?;
        }
        ["frame", depth, color, out] => {
            // The library's decoder, not the `image` crate.
            let image = ImageFrame::read(depth, Some(Path::new(color)))?;
            let opts = Options::builder().bandwidth(0.05).seed(16).threads(1).decimation(2).build()?;
            Model::fit_rgbd(&image.frame(525.0, 525.0, 319.5, 239.5), Some(&opts))?.save(out, None)?;
        }
        ["read", model, query, out] => {
            let q = floats(query);
            let m = Model::load(model, None)?;
            let (mean, var) = m.regress_gray(&q, None)?;
            let mut f = std::io::BufWriter::new(std::fs::File::create(out)?);
            for a in [
                m.weights()?,
                m.means()?,
                m.covariances()?,
                m.sample(256, 2024, 4, None)?,
                mean,
                var,
            ] {
                for x in a {
                    f.write_all(&x.to_le_bytes())?;
                }
            }
            for x in m.score_samples(&q, 3, None)? {
                f.write_all(&x.to_le_bytes())?;
            }
            f.flush()?;
        }
        _ => return Err("usage: matrix write <points.f32> <out.sogmm> | read <in.sogmm> <query.f32> <out.bin> | frame <depth.png> <color> <out.sogmm>".into()),
    }
    Ok(())
}
