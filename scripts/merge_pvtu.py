#!/usr/bin/env python3
"""Merge the pieces of a .pvtu written by `parafront mesh -o x.pvtu` into one
.vtu, by their GlobalPointIds, so that ../shared/tools/meshcheck.py can check
the whole mesh:

    python3 scripts/merge_pvtu.py x.pvtu merged.vtu
    python3 ../shared/tools/meshcheck.py --surface SURFACE merged.vtu

Reads the pieces itself (parafront's layout: appended raw data, UInt64
headers, zlib blocks or none): meshio 5.3 misreads some compressed pieces
and every piece with no cells. Writes with meshio (needs numpy and meshio).
"""
import os
import re
import sys
import zlib

import meshio
import numpy as np

TYPES = {"Int64": "<i8", "Int32": "<i4", "UInt8": "u1", "Float64": "<f8", "UInt32": "<u4"}


def read_piece(path):
    """GlobalPointIds, points, tets and their regions of one piece."""
    raw = open(path, "rb").read()
    head_end = raw.index(b"<AppendedData")
    head = raw[:head_end].decode()
    data = raw[raw.index(b"_", head_end) + 1:]
    zipped = "vtkZLibDataCompressor" in head

    def array(name):
        m = re.search(r'<DataArray type="(\w+)" Name="%s"[^>]*offset="(\d+)"' % name, head)
        dtype, at = TYPES[m.group(1)], int(m.group(2))
        h = np.frombuffer(data, "<u8", count=1, offset=at)
        if not zipped:
            return np.frombuffer(data, dtype, count=int(h[0]) // np.dtype(dtype).itemsize,
                                 offset=at + 8)
        nblocks = int(h[0])
        sizes = np.frombuffer(data, "<u8", count=3 + nblocks, offset=at)[3:]
        pos, out = at + 8 * (3 + nblocks), []
        for s in sizes:
            out.append(zlib.decompress(data[pos:pos + int(s)]))
            pos += int(s)
        return np.frombuffer(b"".join(out), dtype)

    n_cells = int(re.search(r'NumberOfCells="(\d+)"', head).group(1))
    if n_cells == 0:
        return None
    gid = array("GlobalPointIds").astype(np.int64)
    pts = array("Points").reshape(-1, 3)
    conn = array("connectivity").astype(np.int64).reshape(-1, 4)
    return gid, pts, conn, array("region")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    index, out = sys.argv[1], sys.argv[2]
    names = re.findall(r'Source="([^"]+)"', open(index).read())
    pts, cells, regions = {}, [], []
    for n in names:
        piece = read_piece(os.path.join(os.path.dirname(index), n))
        if piece is None:
            continue
        gid, p, conn, region = piece
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
