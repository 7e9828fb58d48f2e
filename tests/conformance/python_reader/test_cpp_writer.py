"""Files from today's C++ writer are read by the independent Python reader and
give the C++ library's own canonical dump."""
import json
import os
import pathlib
import subprocess

import pytest

import sogmm_reader

WRITER = os.environ.get("SOGMM_WRITE_SAMPLES")


@pytest.mark.skipif(not WRITER, reason="SOGMM_WRITE_SAMPLES not set (run through ctest)")
def test_cpp_written_files(tmp_path: pathlib.Path):
    subprocess.run([WRITER, str(tmp_path)], check=True)
    files = sorted(tmp_path.glob("*.sogmm"))
    assert len(files) >= 4
    for f in files:
        got = sogmm_reader.read(f.read_bytes())
        assert got == json.loads(f.with_suffix(".json").read_text()), f.name
