"""A map delta receiver written from spec/format.md section 2.5 alone, on top of
the independent reader (sogmm_reader.read(..., delta=True)).

A Receiver holds the map state the section names (components as float32
values, support size S, frame lines, identity and revision) and applies a
delta's steps to a copy; a refused delta raises Refused and leaves it as it
was."""
import math
import struct

import sogmm_reader

FNV_OFFSET = 14695981039346656037
FNV_PRIME = 1099511628211
DELTA_KEYS = ("delta_map_id", "delta_base_revision", "delta_revision", "delta_frames_before", "delta_frames_from",
              "delta_frames", "delta_ops", "delta_digest")


class Refused(Exception):
    """The receiver must refuse the delta (section 2.5's MUST list, or a file a delta reader rejects)."""


def f32(x):
    """Round a binary64 value to binary32 (round to nearest), back as a Python float."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def _count(text, key):
    if not text or len(text) > 19 or not text.isdigit() or not text.isascii():
        raise Refused(f"{key}: {text!r} is not a decimal count")
    return int(text)


def _full(cov):
    """A covariance as returned by the reader (4 x 4 rows) -> 16 values row-major."""
    return [x for row in cov for x in row]


class Receiver:
    def __init__(self):
        self.map_id = None
        self.revision = 0
        self.weights, self.means, self.covs = [], [], []  # float32 values; means 4, covs 16 per component
        self.support = 0
        self.frames = []  # frame lines, each ending with "\n"

    def _fresh(self):
        return self.revision == 0 and not self.frames and not self.weights

    def digest(self):
        h = FNV_OFFSET

        def feed(data):
            nonlocal h
            for b in data:
                h = ((h ^ b) * FNV_PRIME) & 0xFFFFFFFFFFFFFFFF

        for values in (self.weights, [x for m in self.means for x in m], [x for c in self.covs for x in c]):
            feed(struct.pack(f"<{len(values)}f", *values))
        feed(struct.pack("<Q", self.support))
        feed("".join(self.frames).encode())
        return h

    def apply(self, data):
        try:
            d = sogmm_reader.read(data, delta=True)
        except sogmm_reader.SogmmError as e:
            raise Refused(f"not a valid delta file: {e}") from e
        kv = {}
        for k, v in d["key_values"]:
            kv.setdefault(k, v)
        for key in DELTA_KEYS:
            if key not in kv:
                raise Refused(f"{key} missing")
        map_id = kv["delta_map_id"]
        if len(map_id) != 32 or any(c not in "0123456789abcdef" for c in map_id):
            raise Refused("delta_map_id is not 32 lowercase hex digits")
        base, rev = _count(kv["delta_base_revision"], "base"), _count(kv["delta_revision"], "revision")
        before, start = _count(kv["delta_frames_before"], "frames_before"), _count(kv["delta_frames_from"], "from")
        digest = kv["delta_digest"]
        if len(digest) != 16 or any(c not in "0123456789abcdef" for c in digest):
            raise Refused("delta_digest is not 16 lowercase hex digits")
        if rev < base or start > before:
            raise Refused("revision below its base, or frame lines after the receiver's")
        if not self._fresh() and map_id != self.map_id:
            raise Refused("another map's delta")
        if base != self.revision:
            raise Refused(f"the delta starts at revision {base}, the receiver is at {self.revision}")
        if before != len(self.frames):
            raise Refused("frames_before is not the receiver's number of frame lines")

        carried = list(zip(d.get("weights", []), d.get("means", []), [_full(c) for c in d.get("covariances", [])]))
        w, mu, cov, s = list(self.weights), list(self.means), list(self.covs), self.support
        used = 0

        def take(n):
            nonlocal used
            if n > len(carried) - used:
                raise Refused("the steps use more explicit components than carried")
            out = carried[used:used + n]
            used += n
            return out

        def positions(ids, ascending):
            if any(i >= len(w) for i in ids):
                raise Refused("a step names a position beyond the map")
            if ascending and any(b <= a for a, b in zip(ids, ids[1:])):
                raise Refused("positions not ascending")

        for line in kv["delta_ops"].split("\n"):
            if not line:
                continue
            fields = line.split(" ")
            name, numbers = fields[0], [_count(t, "delta_ops") for t in fields[1:]]
            if name == "merge" and len(numbers) == 2:
                batch, support = take(numbers[0]), numbers[1]
                if not w:
                    w, mu, cov, s = [b[0] for b in batch], [b[1] for b in batch], [b[2] for b in batch], support
                else:
                    total = s + support
                    fa, fb = s / total, support / total
                    w = [f32(x * fa) for x in w] + [f32(b[0] * fb) for b in batch]
                    mu, cov, s = mu + [b[1] for b in batch], cov + [b[2] for b in batch], total
            elif name == "remove" and numbers:
                positions(numbers, True)
                gone = set(numbers)
                kept = 0.0
                for k, x in enumerate(w):
                    if k not in gone:
                        kept += x
                keep = [k for k in range(len(w)) if k not in gone]
                w = [f32(w[k] / kept) for k in keep] if keep else []
                mu, cov = [mu[k] for k in keep], [cov[k] for k in keep]
                s = max(1, math.floor(s * min(kept, 1.0) + 0.5)) if keep else s
            elif name == "set" and numbers:
                positions(numbers, False)
                for k, (bw, bm, bc) in zip(numbers, take(len(numbers))):
                    w[k], mu[k], cov[k] = bw, bm, bc
            elif name == "drop" and numbers:
                positions(numbers, True)
                gone = set(numbers)
                keep = [k for k in range(len(w)) if k not in gone]
                w, mu, cov = [w[k] for k in keep], [mu[k] for k in keep], [cov[k] for k in keep]
            else:
                raise Refused(f"malformed step {line!r}")
        if used != len(carried):
            raise Refused("explicit components left unused")
        frames = self.frames[:start] + kv["delta_frames"].splitlines(keepends=True)

        after = Receiver()
        after.map_id, after.revision = map_id, rev
        after.weights, after.means, after.covs, after.support, after.frames = w, mu, cov, s, frames
        if after.digest() != int(digest, 16):
            raise Refused("the result's digest differs from the delta's")
        self.__dict__.update(after.__dict__)
