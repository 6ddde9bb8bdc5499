# A binary PLY grid of N x N quads (2 triangles each) with texture coordinates per vertex ("vertex") or
# per face corner ("corner", MeshLab's texcoord lists), the same coordinates either way, so both render
# to the same .glb: python3 benchmarks/ply_corner_grid.py N vertex|corner OUT.ply
import struct, sys
n, mode, out = int(sys.argv[1]), sys.argv[2], sys.argv[3]
m = n + 1
hdr = ["ply", "format binary_little_endian 1.0", "comment TextureFile none.png", "element vertex %d" % (m * m),
       "property float x", "property float y", "property float z"]
if mode == "vertex": hdr += ["property float texture_u", "property float texture_v"]
hdr += ["element face %d" % (2 * n * n), "property list uchar int vertex_indices"]
if mode == "corner": hdr += ["property list uchar float texcoord"]
hdr += ["end_header"]
b = bytearray(("\n".join(hdr) + "\n").encode())
for j in range(m):
    for i in range(m):
        z = 0.1 * ((i * 7 + j * 13) % 5)
        b += struct.pack("<fff", i / n, j / n, z)
        if mode == "vertex": b += struct.pack("<ff", i / n, j / n)
for j in range(n):
    for i in range(n):
        a, c, d, e = j * m + i, j * m + i + 1, (j + 1) * m + i + 1, (j + 1) * m + i
        for tri in ((a, c, d), (a, d, e)):
            b += struct.pack("<B3i", 3, *tri)
            if mode == "corner":
                b += struct.pack("<B", 6) + b"".join(struct.pack("<ff", (v % m) / n, (v // m) / n) for v in tri)
open(out, "wb").write(bytes(b))
