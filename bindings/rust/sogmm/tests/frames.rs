//! The library's frame reader and .log reader/writer from Rust.
use std::path::PathBuf;
use std::ptr;

use sogmm::{sys, ColorPixels, ImageFrame, Model, Options, Status, Trajectory};

/// CRC-32 of PNG chunks (bitwise, polynomial 0xEDB88320).
fn crc32(data: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in data {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
        }
    }
    !c
}

/// A PNG built here byte by byte (filter 0 rows, a stored zlib block): the
/// test's own truth, independent of the decoder under test.
fn png(width: u32, height: u32, bit_depth: u8, color_type: u8, samples: &[u8]) -> Vec<u8> {
    let row = samples.len() / height as usize;
    let mut raw = Vec::new();
    for r in samples.chunks(row) {
        raw.push(0);
        raw.extend_from_slice(r);
    }
    let (mut a, mut b) = (1u32, 0u32);
    for &x in &raw {
        a = (a + x as u32) % 65521;
        b = (b + a) % 65521;
    }
    let len = raw.len() as u16;
    let mut z = vec![0x78, 0x01, 0x01];
    z.extend_from_slice(&len.to_le_bytes());
    z.extend_from_slice(&(!len).to_le_bytes());
    z.extend_from_slice(&raw);
    z.extend_from_slice(&((b << 16) | a).to_be_bytes());
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&width.to_be_bytes());
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[bit_depth, color_type, 0, 0, 0]);
    for (kind, data) in [(&b"IHDR"[..], ihdr), (&b"IDAT"[..], z), (&b"IEND"[..], Vec::new())] {
        out.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let mut body = kind.to_vec();
        body.extend_from_slice(&data);
        out.extend_from_slice(&body);
        out.extend_from_slice(&crc32(&body).to_be_bytes());
    }
    out
}

#[test]
fn decoded_frame_has_the_pixels_of_the_files() {
    let depth: Vec<u16> = vec![0, 1, 255, 256, 65535, 1234];
    let be: Vec<u8> = depth.iter().flat_map(|d| d.to_be_bytes()).collect();
    let rgb: Vec<u8> = (0..18).map(|i| (i * 14 + 3) as u8).collect();
    let f = ImageFrame::decode(&png(3, 2, 16, 0, &be), Some(&png(3, 2, 8, 2, &rgb))).unwrap();
    assert_eq!((f.width, f.height), (3, 2));
    assert_eq!(f.depth, depth);
    assert_eq!(f.color, ColorPixels::Rgb8(rgb));
    let gray = ImageFrame::decode(&png(3, 2, 16, 0, &be), None).unwrap();
    assert_eq!(gray.color, ColorPixels::Gray8(vec![0; 6]));
}

#[test]
fn hostile_frames_give_the_documented_status() {
    let good = png(3, 2, 16, 0, &[7u8; 12]);
    let e = ImageFrame::decode(&good[..good.len() - 10], None).unwrap_err();
    assert_eq!(e.status(), Status::Format, "{e}");
    let e = ImageFrame::decode(&png(3, 2, 8, 2, &[1u8; 18]), None).unwrap_err();
    assert_eq!(e.status(), Status::InvalidData, "{e}");
    assert!(e.message().contains("one channel"), "{e}");
    let e = ImageFrame::read("/nonexistent/depth.png", None).unwrap_err();
    assert_eq!(e.status(), Status::Io);
    assert!(e.message().contains("/nonexistent/depth.png"), "{e}");
}

#[test]
fn trajectory_round_trip_is_bitwise() {
    let (c, s) = (0.3f64.cos(), 0.3f64.sin());
    let poses = vec![
        [
            c,
            -s,
            0.0,
            1.0 / 3.0,
            s,
            c,
            0.0,
            -2.0,
            0.0,
            0.0,
            1.0,
            1e-9,
            0.0,
            0.0,
            0.0,
            1.0,
        ],
        [
            1.0, 0.0, 0.0, 4.0, 0.0, 1.0, 0.0, 5.0, 0.0, 0.0, 1.0, 6.0, 0.0, 0.0, 0.0, 1.0,
        ],
    ];
    let dir = std::env::temp_dir().join(format!("sogmm-rs-traj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("t.log");
    Trajectory::write(&path, &poses).unwrap();
    let t = Trajectory::read(&path).unwrap();
    assert_eq!(t.ids, vec![0, 1]);
    assert_eq!(t.poses, poses);
    std::fs::write(&path, "0 0 1\n2 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n").unwrap();
    let e = Trajectory::read(&path).unwrap_err();
    assert_eq!(e.status(), Status::InvalidData);
    assert!(e.message().contains("t.log:5: pose 0 is not a rigid"), "{e}");
    assert_eq!(Trajectory::write(&path, &[]).unwrap_err().status(), Status::InvalidArg);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The read frame fitted through `Model::fit_rgbd` and through the C API's
/// own `sogmm_fit_frame` gives bitwise the same model.
#[test]
fn livingroom_frame_fits_as_sogmm_fit_frame() {
    let room = std::env::var_os("SOGMM_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../../shared/data"))
        .join("rgbd/livingroom");
    if !room.is_dir() {
        eprintln!(
            "SKIP: {} is absent (the real frames live in ../shared/data)",
            room.display()
        );
        return;
    }
    let (d, c) = (room.join("depth/00000.png"), room.join("color/00000.jpg"));
    let image = ImageFrame::read(&d, Some(&c)).unwrap();
    assert!(matches!(image.color, ColorPixels::Rgb8(_)));
    let opts = Options::builder()
        .bandwidth(0.05)
        .seed(16)
        .threads(1)
        .decimation(4)
        .build()
        .unwrap();
    let a = Model::fit_rgbd(&image.frame(525.0, 525.0, 319.5, 239.5), Some(&opts)).unwrap();

    let dp = std::ffi::CString::new(d.to_str().unwrap()).unwrap();
    let cp = std::ffi::CString::new(c.to_str().unwrap()).unwrap();
    let (mut frame, mut model, mut o) = (ptr::null_mut(), ptr::null_mut(), ptr::null_mut());
    // SAFETY: valid paths and handles, freed below.
    let b = unsafe {
        assert_eq!(sys::sogmm_options_create(&mut o), 0);
        assert_eq!(sys::sogmm_options_set_f64(o, sys::SOGMM_OPT_BANDWIDTH, 0.05), 0);
        assert_eq!(sys::sogmm_options_set_i64(o, sys::SOGMM_OPT_SEED, 16), 0);
        assert_eq!(sys::sogmm_options_set_i64(o, sys::SOGMM_OPT_THREADS, 1), 0);
        assert_eq!(sys::sogmm_options_set_i64(o, sys::SOGMM_OPT_DECIMATION, 4), 0);
        assert_eq!(sys::sogmm_frame_read(&mut frame, dp.as_ptr(), cp.as_ptr()), 0);
        assert_eq!(sys::sogmm_frame_set_intrinsics(frame, 525.0, 525.0, 319.5, 239.5), 0);
        assert_eq!(sys::sogmm_fit_frame(&mut model, frame, o), 0);
        sys::sogmm_options_free(o);
        let mut k = 0usize;
        sys::sogmm_model_n_components(model, &mut k);
        let mut w = vec![0f32; k];
        sys::sogmm_model_get_weights_f32(model, w.as_mut_ptr(), k);
        sys::sogmm_model_free(model);
        sys::sogmm_frame_free(frame);
        w
    };
    assert!(b.len() > 1);
    assert_eq!(a.weights().unwrap(), b);
}
