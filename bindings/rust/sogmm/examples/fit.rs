//! Fits a model to a synthetic frame (a tilted plane with three gray bands),
//! samples it, regresses gray, and round-trips it through a .sogmm file.
//! Run: SOGMM_LIB_DIR=<build>/capi cargo run --example fit [scratch-dir]
use sogmm::{Color, Frame, Model, Options, Queryable};

fn main() -> Result<(), sogmm::Error> {
    let (w, h) = (160u32, 120u32);
    let depth: Vec<u16> = (0..w * h).map(|i| (1000 + 500 * (i % w) / w) as u16).collect();
    let gray: Vec<u8> = (0..w * h)
        .map(|i| match i % w {
            u if u < w / 3 => 30,
            u if u < 2 * w / 3 => 120,
            _ => 230,
        })
        .collect();
    let frame = Frame {
        depth: &depth,
        color: Color::Gray8(&gray),
        width: w,
        height: h,
        fx: 140.0,
        fy: 140.0,
        cx: 79.5,
        cy: 59.5,
    };
    let opts = Options::builder().bandwidth(0.05).decimation(4).seed(1).build()?;
    let mut model = Model::fit_rgbd(&frame, Some(&opts))?;
    println!("libsogmm {}: {} components", sogmm::version(), model.n_components());

    let samples = model.sample(1000, 42, 4, None)?;
    println!("first sample: {:?}", &samples[..4]);
    let (g, var) = model.regress_gray(&[-0.4516, 0.0, 1.0625, 0.6207, 0.0, 1.4375], None)?;
    println!("gray at two points: {g:?} (variance {var:?})");

    model.set_value("example", "synthetic plane")?;
    let dir = std::env::args().nth(1).unwrap_or_else(|| ".".into());
    let path = std::path::Path::new(&dir).join("example-rust.sogmm");
    model.save(&path, None)?;
    let loaded = Model::load(&path, None)?;
    std::fs::remove_file(&path).ok();
    println!(
        "saved and reloaded {}: {} components",
        path.display(),
        loaded.n_components()
    );
    Ok(())
}
