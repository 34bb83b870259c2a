#!/usr/bin/env python3
"""Merge the pieces of a .pvtu written by `parafront mesh -o x.pvtu` into one
.vtu, by their GlobalPointIds, so that ../shared/tools/meshcheck.py can check
the whole mesh:

    python3 scripts/merge_pvtu.py x.pvtu merged.vtu
    python3 ../shared/tools/meshcheck.py --surface SURFACE merged.vtu

Reads and writes with meshio (needs numpy and meshio).
"""
import os
import re
import sys

import meshio
import numpy as np


def read_piece(path):
    """GlobalPointIds, points, tets and their regions of one piece."""
    m = meshio.read(path)
    k = [i for i, c in enumerate(m.cells) if c.type == "tetra"]
    conn = np.concatenate([m.cells[i].data for i in k]).astype(np.int64)
    region = np.concatenate([np.asarray(m.cell_data["region"][i]) for i in k])
    return m.point_data["GlobalPointIds"].astype(np.int64), m.points, conn, region


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    index, out = sys.argv[1], sys.argv[2]
    names = re.findall(r'Source="([^"]+)"', open(index).read())
    pts, cells, regions = {}, [], []
    for n in names:
        gid, p, conn, region = read_piece(os.path.join(os.path.dirname(index), n))
        for i, g in enumerate(gid):
            pts[int(g)] = p[i]
        cells.append(gid[conn])
        regions.append(region)
    n = max(pts) + 1
    if len(pts) != n:
        sys.exit(f"{index}: global point ids are not 0..{n - 1}")
    tets = np.concatenate(cells)
    # The regions, so that meshcheck accepts faces between two of them.
    mesh = meshio.Mesh(np.array([pts[i] for i in range(n)]), [("tetra", tets)],
                       cell_data={"region": [np.concatenate(regions)]})
    meshio.write(out, mesh)
    print(f"{out}: {len(tets)} tets, {n} points from {len(names)} pieces")


if __name__ == "__main__":
    main()
