"""Map.merge_map (sogmm_map_merge_map; two robots, one map): into an empty
map it gives the other map, with a copy of itself it adds nothing, disjoint
maps keep every component with its mass in points (closed-form weights), a
receiver of the deltas follows the merge, and bad input changes nothing."""

from __future__ import annotations

import numpy as np
import pytest

import sogmm

from test_map import FIT, POSES, frames


def fitted():
    m = sogmm.Map(novelty=False, **FIT)
    for pts, pose in zip(frames(), POSES):
        m.insert_points(pts, pose)
    return m


def same(a: sogmm.GMM, b: sogmm.GMM) -> bool:
    return all(x.tobytes() == y.tobytes() for x, y in
               ((a.weights_, b.weights_), (a.means_, b.means_), (a.covariances_, b.covariances_))) and \
        a.support_size_ == b.support_size_


def test_into_an_empty_map_gives_the_other_map():
    with fitted() as other, sogmm.Map() as m:
        st = m.merge_map(other)
        assert st == {"n_kept": 0, "n_removed": 0, "n_added": other.n_components_, "n_skipped": 0, "n_frames": 2}
        assert same(m.export(), other.export())
        assert m.revision == 1
        for a, b in zip(m.frames(), other.frames()):
            np.testing.assert_array_equal(a["pose"], b["pose"])


def test_a_copy_of_itself_adds_no_component(tmp_path):
    with fitted() as m:
        m.save(tmp_path / "m.sogmm")
        before = m.export()
        with sogmm.Map.load(tmp_path / "m.sogmm") as copy:
            st = m.merge_map(copy, np.eye(4))
        assert st["n_added"] == 0 and st["n_removed"] == 0 and st["n_skipped"] == len(before.weights_)
        assert same(m.export(), before)
        assert m.stats()["n_frames"] == 4  # both provenances


def test_disjoint_maps_keep_every_component_with_its_mass():
    with fitted() as a, fitted() as b:
        ga, gb = a.export(), b.export()
        far = np.eye(4)
        far[0, 3] = 10.0
        receiver = sogmm.Map()
        receiver.apply_delta(a.export_delta(0))
        since = a.revision
        st = a.merge_map(b, far)
        assert st["n_removed"] == 0 and st["n_skipped"] == 0
        g = a.export()
        sa, sb = ga.support_size_, gb.support_size_
        assert g.support_size_ == sa + sb
        np.testing.assert_allclose(g.weights_, np.concatenate([ga.weights_ * sa, gb.weights_ * sb]) / (sa + sb),
                                   rtol=1e-6)
        np.testing.assert_allclose(g.means_[len(ga.weights_):, 0], gb.means_[:, 0] + 10.0, atol=1e-5)
        receiver.apply_delta(a.export_delta(since))  # the merge is one revision a receiver follows
        assert receiver.revision == a.revision and same(receiver.export(), g)
        receiver.close()


@pytest.mark.parametrize("pose, error, why", [
    (np.full((4, 4), np.nan), sogmm.InvalidArgumentError, "not finite"),
    (np.diag([2.0, 1.0, 1.0, 1.0]), sogmm.InvalidArgumentError, "rigid"),
])
def test_a_bad_pose_raises_and_changes_nothing(pose, error, why):
    with fitted() as m, fitted() as other:
        before, revision = m.export(), m.revision
        with pytest.raises(error, match=why):
            m.merge_map(other, pose)
        assert m.revision == revision and same(m.export(), before)


def test_bad_maps_raise_and_change_nothing():
    with fitted() as m, sogmm.Map() as empty, sogmm.Map(batch_size=100000, **FIT) as busy:
        before, revision = m.export(), m.revision
        with pytest.raises(sogmm.InvalidArgumentError, match="itself"):
            m.merge_map(m)
        with pytest.raises(sogmm.InvalidArgumentError, match="needs a Map"):
            m.merge_map(before)
        with pytest.raises(sogmm.InvalidDataError, match="no component"):
            m.merge_map(empty)
        busy.insert_points(frames()[0], np.eye(4))
        assert busy.n_pending_ > 0
        with pytest.raises(sogmm.InvalidArgumentError, match="pending"):
            m.merge_map(busy)
        assert m.revision == revision and same(m.export(), before)
