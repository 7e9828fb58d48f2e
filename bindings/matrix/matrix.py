"""The Python participant of the cross-language matrix test (protocol: run_matrix.py).

    python matrix.py write <points.f32> <out.sogmm>
    python matrix.py read <in.sogmm> <query.f32> <out.bin>
    python matrix.py frame <depth.png> <color image> <out.sogmm>
"""
import sys

import numpy as np

import sogmm


def write(points_path: str, out_path: str) -> None:
    pts = np.fromfile(points_path, dtype="<f4").reshape(-1, 4)
    sogmm.SOGMM(bandwidth=0.05, seed=16, n_threads=1).fit(pts).save(out_path)


def frame(depth_path: str, color_path: str, out_path: str) -> None:
    depth, color = sogmm.read_frame(depth_path, color_path)  # the library's decoder, not Pillow
    cam = sogmm.Camera(width=depth.shape[1], height=depth.shape[0], fx=525.0, fy=525.0, cx=319.5, cy=239.5)
    sogmm.SOGMM(bandwidth=0.05, seed=16, n_threads=1).fit_rgbd(depth, color, cam, decimate=2).save(out_path)


def read(model_path: str, query_path: str, out_path: str) -> None:
    q = np.fromfile(query_path, dtype="<f4").reshape(-1, 3)
    m = sogmm.load(model_path)
    mean, var = m.regress_gray(q)
    parts = [m.weights_, m.means_, m.covariances_, m.sample(256, seed=2024), mean, var]
    with open(out_path, "wb") as f:
        for a in parts:
            f.write(np.ascontiguousarray(a, dtype="<f4").tobytes())
        f.write(np.ascontiguousarray(m.score_samples(q), dtype="<f8").tobytes())


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "write":
        write(*sys.argv[2:])
    elif len(sys.argv) == 5 and sys.argv[1] == "read":
        read(*sys.argv[2:])
    elif len(sys.argv) == 5 and sys.argv[1] == "frame":
        frame(*sys.argv[2:])
    else:
        sys.exit(__doc__)
