"""FlatBuffers tables of the .sogmm metadata (spec/format.md section 4) that
every spec-side Python writer builds the same way: the conformance vector
generators here and tests/bench/format_memory_bound.py. Written from the spec
with the `flatbuffers` builder, not by the library.
"""


def string_vector(b, items):
    """A vector of strings (the axis labels and units)."""
    offs = [b.CreateString(s) for s in items]
    b.StartVector(4, len(offs), 4)
    for o in reversed(offs):
        b.PrependUOffsetTRelative(o)
    return b.EndVector()


def array_table(b, rec, offset, stored_length):
    """One ArrayInfo table: `rec` holds dtype, order, filter, codec,
    decoded_length and crc32c; the array's bytes stand at `offset` and are
    `stored_length` long."""
    b.StartObject(8)
    b.PrependUint8Slot(0, rec["dtype"], 0)
    b.PrependUint8Slot(1, rec["order"], 0)
    b.PrependUint8Slot(2, rec["filter"], 0)
    b.PrependUint8Slot(3, rec["codec"], 0)
    b.PrependUint64Slot(4, offset, 0)
    b.PrependUint64Slot(5, stored_length, 0)
    b.PrependUint64Slot(6, rec["decoded_length"], 0)
    b.PrependUint32Slot(7, rec["crc32c"], 0)
    return b.EndObject()
