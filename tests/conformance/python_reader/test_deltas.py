"""The independent delta receiver (delta_receiver.py, from spec/format.md 2.5
alone) over spec/conformance/deltas/manifest.json: every chain ends at the
recorded revision, component count and digest; every refused case is refused
with the receiver unchanged. bindings/python/tests/test_delta_vectors.py
runs the same cases through the library."""
import json
import os
import pathlib

import pytest

import delta_receiver
import sogmm_reader

DIR = pathlib.Path(os.environ.get("SOGMM_CONFORMANCE_DIR",
                                  pathlib.Path(__file__).resolve().parents[3] / "spec" / "conformance")) / "deltas"
CASES = json.loads((DIR / "manifest.json").read_text())["cases"]


def test_the_vectors_use_every_step_and_every_refusal():
    steps = set().union(*(c.get("steps", []) for c in CASES))
    assert steps == {"merge", "remove", "set", "drop"}
    assert {c["name"] for c in CASES if c["expect"] == "refused"} >= {
        "gap", "duplicate", "another_map", "wrong_digest", "position_beyond", "model_file"}
    # Format 1.2 (section 2.5.1): chains of packed deltas, and a refusal of each step-20 reason.
    assert {c["reason"] for c in CASES if "reason" in c} == {
        "checksum_mismatch", "bad_metadata", "bad_layout", "decompression_failed"}
    assert any(c["name"].startswith("rgbd_packed") for c in CASES if c["expect"] == "applied")


@pytest.mark.parametrize("case", CASES, ids=[c["name"] for c in CASES])
def test_case(case):
    r = delta_receiver.Receiver()
    for name in case["apply"]:
        r.apply((DIR / name).read_bytes())
    if case["expect"] == "applied":
        assert (r.revision, len(r.weights), "%016x" % r.digest()) == (
            case["revision"], case["n_components"], case["digest"])
        return
    before = dict(r.__dict__)
    with pytest.raises(delta_receiver.Refused):
        r.apply((DIR / case["then"]).read_bytes())
    assert r.__dict__ == before
    if "reason" in case:  # a file a delta reader rejects, for this reason
        with pytest.raises(sogmm_reader.SogmmError) as err:
            sogmm_reader.read((DIR / case["then"]).read_bytes(), delta=True)
        assert err.value.reason == case["reason"]


def test_a_model_reader_rejects_a_delta():
    data = (DIR / "points_1.sogmm").read_bytes()
    with pytest.raises(sogmm_reader.SogmmError) as err:
        sogmm_reader.read(data)
    assert err.value.reason == "unsupported_feature"
    with pytest.raises(sogmm_reader.SogmmError) as err:
        sogmm_reader.read((DIR / "../valid/one_component.sogmm").read_bytes(), delta=True)
    assert err.value.reason == "not_a_delta"
    # Nor does a model reader know bit 1 (packed key/values, section 2.5.1).
    with pytest.raises(sogmm_reader.SogmmError) as err:
        sogmm_reader.read((DIR / "points_packed_1.sogmm").read_bytes())
    assert err.value.reason == "unsupported_feature"
