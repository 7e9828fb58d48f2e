"""The library over the map delta conformance vectors
(spec/conformance/deltas/manifest.json): the same verdicts as the
independent receiver of tests/conformance/python_reader/test_deltas.py."""
import json
import pathlib
import re

import pytest
import zstandard

import sogmm

DIR = pathlib.Path(__file__).resolve().parents[3] / "spec" / "conformance" / "deltas"
CASES = json.loads((DIR / "manifest.json").read_text())["cases"]


def key_value_text(delta: bytes) -> bytes:
    """The key/value bytes of a delta: those packed at the end of its body
    (format 1.2, spec/format.md 2.5.1: located by the metadata entry
    `packed_key_values` = "codec stored decoded crc"), else its metadata."""
    found = re.search(rb"(\d) (\d+) \d+ \d+\x00", delta)
    if b"packed_key_values" not in delta or found is None:
        return delta
    codec, stored = int(found.group(1)), int(found.group(2))
    packed = delta[len(delta) - 4 - stored:len(delta) - 4]
    return zstandard.ZstdDecompressor().decompress(packed) if codec == 1 else packed


@pytest.mark.parametrize("case", CASES, ids=[c["name"] for c in CASES])
def test_case(case):
    with sogmm.Map() as receiver:
        for name in case["apply"]:
            receiver.apply_delta((DIR / name).read_bytes())
        if case["expect"] == "applied":
            assert (receiver.revision, receiver.n_components_) == (case["revision"], case["n_components"])
            # The digest the library computes is the one the delta carries; the
            # receiver checked it, and a re-export from here carries it again.
            again = receiver.export_delta(case["revision"])
            assert case["digest"].encode() in key_value_text(again)
            return
        before = (receiver.revision, receiver.n_components_, len(receiver))
        with pytest.raises(sogmm.SogmmError):
            receiver.apply_delta((DIR / case["then"]).read_bytes())
        assert (receiver.revision, receiver.n_components_, len(receiver)) == before


def test_a_receiver_of_the_livingroom_map_is_bitwise_equal_after_every_delta(livingroom):
    # Issue 33: the shared livingroom frames 0-2 (their trajectory, d = 5),
    # read by the library's frame reader; after each insert the receiver
    # applies the delta and holds the sender's components bit for bit.
    _, _, cam, folder = livingroom
    _, poses = sogmm.read_trajectory(folder / "trajectory.log")
    with sogmm.Map(decimate=5, n_threads=2) as sender, sogmm.Map() as receiver:
        for k in range(3):
            depth, color = sogmm.read_frame(folder / "depth" / f"{k:05d}.png", folder / "color" / f"{k:05d}.jpg")
            since = sender.revision
            sender.insert_rgbd(depth, color, cam, poses[k])
            if k == 2:
                sender.flush()
            receiver.apply_delta(sender.export_delta(since))
            assert (receiver.revision, len(receiver)) == (sender.revision, len(sender))
            if sender.n_components_:
                a, b = sender.export(), receiver.export()
                for x, y in ((a.weights_, b.weights_), (a.means_, b.means_), (a.covariances_, b.covariances_)):
                    assert x.tobytes() == y.tobytes()
        assert receiver.n_components_ > 0
