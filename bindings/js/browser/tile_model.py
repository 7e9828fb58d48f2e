"""Tiles a model into a grid of translated copies, merged into one model
(the Python binding's transform and merge), for the viewer's load-time
measurement on a large map. TURN (degrees, default 0) turns copy i by i x TURN
about the vertical (y) axis: every copy's covariances then differ, so the
arrays compress like a real map's instead of as repeats of one tile.

    SOGMM_LIBRARY_PATH=build/capi/libsogmm.so PYTHONPATH=bindings/python/src \
      python3 tile_model.py IN.sogmm COPIES SPACING OUT.sogmm [TURN]
"""
import math
import sys

import sogmm


def main():
    src, copies, spacing, out = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
    turn = math.radians(float(sys.argv[5])) if len(sys.argv) > 5 else 0.0
    model = sogmm.load(src)
    side = math.ceil(math.sqrt(copies))
    tiles = []
    for i in range(copies):
        c, s = math.cos(turn * i), math.sin(turn * i)
        pose = [[c, 0, s, spacing * (i % side)], [0, 1, 0, 0], [-s, 0, c, spacing * (i // side)], [0, 0, 0, 1]]
        tiles.append(model.transform(pose))
    while len(tiles) > 1:  # pairwise, so each component is copied O(log n) times
        tiles = [tiles[i].merge(tiles[i + 1]) if i + 1 < len(tiles) else tiles[i] for i in range(0, len(tiles), 2)]
    tiles[0].save(out)
    print(f"{out}: {copies} copies of {src}")


if __name__ == "__main__":
    main()
