"""Metadata strings and hostile files through the Python binding (issue 13).

One rule for strings (spec/format.md section 4.4): valid UTF-8 without NUL.
Files that break it are refused on load with FormatError (they used to raise
UnicodeDecodeError on access, or cut a value at its NUL); a repeated key gives
its first pair, as in the C API; a FIFO is refused instead of blocking.
"""

from __future__ import annotations

import os
import threading

import pytest

import sogmm
from conftest import REPO_ROOT

VECTORS = REPO_ROOT / "spec" / "conformance"


@pytest.mark.parametrize("name", ["string_not_utf8", "string_nul", "string_surrogate", "string_overlong",
                                  "shared_strings_over_block"])
def test_files_breaking_the_string_rule_are_refused(name):
    path = VECTORS / "invalid" / f"{name}.sogmm"
    with pytest.raises(sogmm.FormatError, match="bad_metadata"):
        sogmm.load(path)
    with pytest.raises(sogmm.FormatError, match="bad_metadata"):
        sogmm.from_bytes(path.read_bytes())


def test_repeated_key_gives_its_first_pair_as_in_c():
    g = sogmm.load(VECTORS / "valid" / "all_metadata.sogmm")
    assert g.metadata["note"] == "unicode \u03bb \u2713"  # the first "note"; the second says "repeated key"
    assert g.metadata[""] == "empty key"


def test_control_characters_survive_as_text():
    g = sogmm.load(VECTORS / "valid" / "control_characters.sogmm")
    assert g.metadata["note"] == "\x1b[2J\x1b[31mred\r\nforged: line\u202e\u009b"


def test_set_metadata_refuses_what_no_file_may_hold():
    g = sogmm.load(VECTORS / "valid" / "one_component.sogmm")
    for key, value in (("k", "\ud800"), ("\udfff", "v"), ("k", "a\0b")):
        with pytest.raises(sogmm.InvalidArgumentError):
            g.set_metadata(key, value)
    assert g.metadata == {}
    g.set_metadata("k", "\U0010ffff")
    assert sogmm.from_bytes(g.to_bytes()).metadata == {"k": "\U0010ffff"}


def test_a_fifo_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "pipe.sogmm"
    os.mkfifo(fifo)
    result = []
    t = threading.Thread(target=lambda: result.append(pytest.raises(sogmm.SogmmIOError, sogmm.load, fifo)),
                         daemon=True)
    t.start()
    t.join(20)
    if t.is_alive():  # unblock the reader, then fail
        with open(fifo, "wb"):
            pass
        pytest.fail("loading a FIFO blocked")
    assert "FIFO" in str(result[0].value)
