"""sogmm.register (issue 32): points sampled from a corner of three planes, and
the corner model itself (model to model, D2D), moved by a known pose register
back to it; a single plane is degenerate in its three in-plane directions; bad
input raises."""
import numpy as np
import pytest

import sogmm


def planes(normals, support_size=1):
    """Flat components tiling the unit square of each plane (0: x = 0, 1: y = 0, 2: z = 0)."""
    w, mu, cov = [], [], []
    for axis in normals:
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for a in range(5):
            for b in range(5):
                m = np.zeros(4)
                m[u], m[v], m[3] = 0.1 + 0.2 * a, 0.1 + 0.2 * b, 0.5
                c = np.zeros((4, 4))
                c[u, u] = c[v, v] = 0.08**2
                c[axis, axis] = 0.003**2
                c[3, 3] = 0.01
                w.append(1.0)
                mu.append(m)
                cov.append(c)
    w = np.array(w) / len(w)
    return sogmm.GMM.from_arrays(w.astype(np.float32), np.array(mu, np.float32), np.array(cov, np.float32),
                                 support_size)


def rigid(deg, axis, t):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    a = np.radians(deg)
    p = np.eye(4)
    p[:3, :3] = np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * k @ k
    p[:3, 3] = t
    return p


def moved(points, pose):
    out = points.copy()
    out[:, :3] = (points[:, :3].astype(np.float64) @ pose[:3, :3].T + pose[:3, 3]).astype(np.float32)
    return out


def test_recovers_a_known_pose():
    model = planes([0, 1, 2])
    truth = rigid(5.0, [1, 2, 3], [0.02, -0.01, 0.03])
    src = moved(model.sample(3000, seed=1), np.linalg.inv(truth))
    pose, info = sogmm.register(src, model)
    assert info["status"] == "converged" and info["converged"]
    # Noise: 3 mm / sqrt(1000) per plane normal, far below 1 mm.
    assert np.abs(pose - truth).max() < 1e-3
    assert info["inlier_ratio"] > 0.95 and info["unobservable"] == 0
    assert info["information"].shape == (6, 6)
    # A start near the truth gives the same answer.
    pose2, _ = sogmm.register(src, model, init=rigid(4.0, [1, 2, 3], [0.01, 0, 0.02]))
    assert np.abs(pose2 - pose).max() < 1e-3


def test_single_plane_is_degenerate():
    model = planes([2])
    src = moved(model.sample(3000, seed=2), rigid(0, [0, 0, 1], [0, 0, -0.01]))
    pose, info = sogmm.register(src, model)
    assert info["status"] == "degenerate" and info["unobservable"] == 3
    i = info["information"]
    # tx, ty and rz carry (almost) no information; tz does.
    assert max(abs(i[3, 3]), abs(i[4, 4]), abs(i[2, 2])) < 1e-3 * i[5, 5]
    assert abs(pose[2, 3] - 0.01) < 1e-3


def test_bad_input():
    model = planes([0, 1, 2])
    src = model.sample(500, seed=3)
    with pytest.raises(sogmm.InvalidArgumentError, match="init"):
        sogmm.register(src, model, init=np.full((4, 4), np.nan))
    with pytest.raises(sogmm.InvalidDataError, match="min_points"):
        sogmm.register(src[:50], model)
    with pytest.raises(sogmm.InvalidArgumentError):
        sogmm.register(src[:, :3], model)
    with pytest.raises(sogmm.InvalidArgumentError, match="outlier_ratio"):
        sogmm.register(src, model, outlier_ratio=1.0)


def test_model_to_model_recovers_a_known_pose():
    model = planes([0, 1, 2], support_size=30000)
    truth = rigid(5.0, [1, 2, 3], [0.02, -0.01, 0.03])
    pose, info = sogmm.register(model.transform(np.linalg.inv(truth)), model)
    assert info["status"] == "converged"
    # The optimum of a model against its own moved copy, up to the copy's
    # float rounding (< 1 um in the core's test).
    assert np.abs(pose - truth).max() < 1e-4
    assert info["inlier_ratio"] > 0.95 and info["unobservable"] == 0
    # A source model standing for one point: fewer than min_points.
    with pytest.raises(sogmm.InvalidDataError, match="min_points"):
        sogmm.register(planes([0, 1, 2]), model)


def test_the_old_keyword_still_works_with_a_warning():
    model = planes([0, 1, 2])
    src = model.sample(500, seed=4)
    with pytest.warns(DeprecationWarning, match="source_points"):
        old, _ = sogmm.register(source_points=src, target_model=model)
    new, _ = sogmm.register(src, model)
    assert np.array_equal(old, new)
    with pytest.raises(TypeError, match="both"):
        sogmm.register(src, model, source_points=src)
    with pytest.raises(TypeError, match="target_model"):
        sogmm.register(src)


def test_depth_noise_reaches_the_library():
    """depth_noise (SOGMM_OPT_REGISTRATION_DEPTH_NOISE): refused out of range,
    a reweighting that still recovers the pose of unbiased points, and
    ignored by a model source (bitwise the same pose)."""
    model = planes([0, 1, 2], support_size=30000)
    truth = rigid(5.0, [1, 2, 3], [0.02, -0.01, 0.03])
    src = moved(model.sample(3000, seed=1), np.linalg.inv(truth))
    src[:, 2] += 1.0  # in front of a sensor at the origin (z > 0), as frames are
    shifted = np.eye(4)
    shifted[2, 3] = -1.0
    truth = truth @ shifted
    with pytest.raises(sogmm.InvalidArgumentError, match="DEPTH_NOISE"):
        sogmm.register(src, model, depth_noise=-1.0)
    plain, _ = sogmm.register(src, model, init=truth)
    noisy, info = sogmm.register(src, model, init=truth, depth_noise=0.002)
    assert info["status"] == "converged"
    assert np.abs(noisy - truth).max() < 1e-3
    assert not np.array_equal(noisy, plain)  # it did reach the scoring
    source = model.transform(np.linalg.inv(truth))
    a, _ = sogmm.register(source, model)
    b, _ = sogmm.register(source, model, depth_noise=0.01)
    assert np.array_equal(a, b)
