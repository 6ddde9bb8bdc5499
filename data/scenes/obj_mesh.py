"""The vertices and triangles of an OBJ file (v and f lines; 0-based corner indices, the first
three of each face), for the scripts in this folder that write glTF scenes."""


def read_obj(path):
    verts, faces = [], []
    for line in open(path):
        parts = line.split()
        if not parts or parts[0].startswith("#"):
            continue
        if parts[0] == "v":
            verts.append(tuple(float(x) for x in parts[1:4]))
        elif parts[0] == "f":
            faces.append(tuple(int(x.split("/")[0]) - 1 for x in parts[1:4]))
    return verts, faces
