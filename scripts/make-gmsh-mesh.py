#!/usr/bin/env python3
"""Writes a Gmsh MSH 4.1 file (ASCII or binary) of separate boxes meshed with tetrahedra, without
Gmsh: each box is nx x ny x nz cubes of 6 tets (the Kuhn subdivision fdem's box generator uses),
its own volume entity and its own 3D physical group ("box1", "box2", ...), and every box is also
in the group "all".  Used for test meshes (tests/data/gmsh/two_blocks*.msh) and for the memory
benchmark at 10^6 tets (scripts/bench-gmsh-memory.sh).

  make-gmsh-mesh.py OUT.msh --box X0,Y0,Z0,X1,Y1,Z1,NX,NY,NZ [--box ...] [--binary]
                    [--interleave K] [--shuffle SEED] [--node-tag-stride S]

--interleave K   each box's tets in K element blocks, the blocks of the boxes alternating, so that
                 the pieces interleave in file order (the last box's first block comes first)
--shuffle SEED   tets in random order within each block, nodes in random order within each box
--node-tag-stride S  node tags 1, 1+S, 1+2S, ... (sparse tags; default 1: 1..N)
"""
import argparse
import random
import struct
import sys


def box_mesh(spec, node_base):
    x0, y0, z0, x1, y1, z1 = (float(v) for v in spec[:6])
    nx, ny, nz = (int(v) for v in spec[6:9])
    hx, hy, hz = (x1 - x0) / nx, (y1 - y0) / ny, (z1 - z0) / nz

    def coord(i, j, k):
        return (x1 if i == nx else x0 + i * hx, y1 if j == ny else y0 + j * hy,
                z1 if k == nz else z0 + k * hz)

    def node(i, j, k):
        return node_base + (k * (ny + 1) + j) * (nx + 1) + i

    coords = [coord(i, j, k) for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)]
    perms = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
    tets = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                for p in perms:
                    corner = [0, 0, 0]
                    tet = [node(i, j, k)]
                    for s in range(3):
                        corner[p[s]] = 1
                        tet.append(node(i + corner[0], j + corner[1], k + corner[2]))
                    a, b, c, d = (coords[n - node_base] for n in tet)
                    e = [[b[m] - a[m] for m in range(3)], [c[m] - a[m] for m in range(3)],
                         [d[m] - a[m] for m in range(3)]]
                    det = (e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                           e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                           e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]))
                    if det < 0:
                        tet[2], tet[3] = tet[3], tet[2]
                    tets.append(tet)
    return (x0, y0, z0, x1, y1, z1), coords, tets


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out")
    parser.add_argument("--box", action="append", required=True)
    parser.add_argument("--binary", action="store_true")
    parser.add_argument("--interleave", type=int, default=1)
    parser.add_argument("--shuffle", type=int, default=None)
    parser.add_argument("--node-tag-stride", type=int, default=1)
    args = parser.parse_args()
    rng = random.Random(args.shuffle)

    boxes = []  # (bounds, [(tag, xyz)], [tets as node tags])
    node_base = 0
    for spec in args.box:
        bounds, coords, tets = box_mesh(spec.split(","), node_base)
        tag = lambda n: 1 + n * args.node_tag_stride
        nodes = [(tag(node_base + i), xyz) for i, xyz in enumerate(coords)]
        if args.shuffle is not None:
            rng.shuffle(nodes)
            rng.shuffle(tets)
        boxes.append((bounds, nodes, [[tag(n) for n in t] for t in tets]))
        node_base += len(coords)

    blocks = []  # element blocks: (volume entity, tets)
    for part in range(args.interleave):
        for b in reversed(range(len(boxes))):
            tets = boxes[b][2]
            lo, hi = part * len(tets) // args.interleave, (part + 1) * len(tets) // args.interleave
            if hi > lo:
                blocks.append((b + 1, tets[lo:hi]))

    n_nodes = sum(len(b[1]) for b in boxes)
    n_tets = sum(len(b[2]) for b in boxes)
    all_group = len(boxes) + 1
    out = open(args.out, "wb")
    w = lambda text: out.write(text.encode())
    binary = args.binary
    size = lambda v: struct.pack("<Q", v)
    i32 = lambda v: struct.pack("<i", v)
    f64 = lambda v: struct.pack("<d", v)

    w("$MeshFormat\n4.1 %d 8\n" % (1 if binary else 0))
    if binary:
        out.write(i32(1))
        w("\n")
    w("$EndMeshFormat\n$PhysicalNames\n%d\n" % (len(boxes) + 1))
    for b in range(len(boxes)):
        w('3 %d "box%d"\n' % (b + 1, b + 1))
    w('3 %d "all"\n$EndPhysicalNames\n$Entities\n' % all_group)
    if binary:
        out.write(size(0) + size(0) + size(0) + size(len(boxes)))
        for b, (bounds, _, _) in enumerate(boxes):
            out.write(i32(b + 1) + b"".join(f64(v) for v in bounds) + size(2) + i32(b + 1) +
                      i32(all_group) + size(0))
        w("\n")
    else:
        w("0 0 0 %d\n" % len(boxes))
        for b, (bounds, _, _) in enumerate(boxes):
            w("%d %s 2 %d %d 0\n" % (b + 1, " ".join(repr(v) for v in bounds), b + 1, all_group))
    w("$EndEntities\n$Nodes\n")
    tags = [t for b in boxes for t, _ in b[1]]
    header = (len(boxes), n_nodes, min(tags), max(tags))
    if binary:
        out.write(b"".join(size(v) for v in header))
    else:
        w("%d %d %d %d\n" % header)
    for b, (_, nodes, _) in enumerate(boxes):
        if binary:
            out.write(i32(3) + i32(b + 1) + i32(0) + size(len(nodes)))
            out.write(struct.pack("<%dQ" % len(nodes), *(t for t, _ in nodes)))
            out.write(struct.pack("<%dd" % (3 * len(nodes)), *(v for _, xyz in nodes for v in xyz)))
        else:
            w("3 %d 0 %d\n" % (b + 1, len(nodes)))
            w("".join("%d\n" % t for t, _ in nodes))
            w("".join("%r %r %r\n" % xyz for _, xyz in nodes))
    if binary:
        w("\n")
    w("$EndNodes\n$Elements\n")
    header = (len(blocks), n_tets, 1, n_tets)
    if binary:
        out.write(b"".join(size(v) for v in header))
    else:
        w("%d %d %d %d\n" % header)
    element = 1
    for entity, tets in blocks:
        if binary:
            out.write(i32(3) + i32(entity) + i32(4) + size(len(tets)))
            flat = []
            for t in tets:
                flat.append(element)
                flat.extend(t)
                element += 1
            out.write(struct.pack("<%dQ" % len(flat), *flat))
        else:
            w("3 %d 4 %d\n" % (entity, len(tets)))
            lines = []
            for t in tets:
                lines.append("%d %d %d %d %d\n" % (element, t[0], t[1], t[2], t[3]))
                element += 1
            w("".join(lines))
    if binary:
        w("\n")
    w("$EndElements\n")
    out.close()
    print("%s: %d nodes, %d tets in %d boxes" % (args.out, n_nodes, n_tets, len(boxes)),
          file=sys.stderr)


if __name__ == "__main__":
    main()
