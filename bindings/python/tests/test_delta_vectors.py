"""The library over the map delta conformance vectors
(spec/conformance/deltas/manifest.json): the same verdicts as the
independent receiver of tests/conformance/python_reader/test_deltas.py."""
import json
import pathlib

import pytest

import sogmm

DIR = pathlib.Path(__file__).resolve().parents[3] / "spec" / "conformance" / "deltas"
CASES = json.loads((DIR / "manifest.json").read_text())["cases"]


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
            assert case["digest"].encode() in again
            return
        before = (receiver.revision, receiver.n_components_, len(receiver))
        with pytest.raises(sogmm.SogmmError):
            receiver.apply_delta((DIR / case["then"]).read_bytes())
        assert (receiver.revision, receiver.n_components_, len(receiver)) == before
