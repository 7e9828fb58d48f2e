"""Runs the independent Python reader over spec/conformance/manifest.json."""
import json
import os
import pathlib

import pytest

import sogmm_reader

DIR = pathlib.Path(os.environ.get("SOGMM_CONFORMANCE_DIR",
                                  pathlib.Path(__file__).resolve().parents[3] / "spec" / "conformance"))
MANIFEST = json.loads((DIR / "manifest.json").read_text())
VECTORS = MANIFEST["vectors"]


def test_manifest_covers_the_required_cases():
    reasons = {v.get("reason") for v in VECTORS}
    for r in ["bad_magic", "truncated", "unsupported_version", "unsupported_feature", "checksum_mismatch",
              "bad_metadata", "limit", "non_finite", "not_spd", "bad_weights", "empty", "length_mismatch"]:
        assert r in reasons, r
    assert sum(v["expect"] == "valid" for v in VECTORS) >= 5


@pytest.mark.parametrize("vector", VECTORS, ids=[v["file"] for v in VECTORS])
def test_vector(vector):
    data = (DIR / vector["file"]).read_bytes()
    if vector["expect"] == "valid":
        got = sogmm_reader.read(data)
        expected = json.loads((DIR / vector["json"]).read_text())
        assert got == expected
        meta = sogmm_reader.read(data, metadata_only=True)
        assert meta["producer_name"] == expected["producer_name"]
    else:
        with pytest.raises(sogmm_reader.SogmmError) as err:
            sogmm_reader.read(data)
        assert (err.value.category, err.value.reason) == (vector["category"], vector["reason"]), str(err.value)


def test_crc32c_check_value():
    assert sogmm_reader.crc32c(b"123456789") == 0xE3069283
