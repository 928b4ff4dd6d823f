"""The relief region's own triangles, without bpy: what the viewport tints (region_view.py).

    local_vertices, local_triangles = region_triangles(triangles, relief_vertices, num_vertices)

A triangle belongs to the region when its three corners are relief vertices. Works on the flat
buffers the engine was given (triangles: 3*#T ints) in a few passes done in C (bytes, big
integers), so 300k triangles take a fraction of a second even in plain Python.
"""

__all__ = ["region_triangles"]


def region_triangles(triangles, relief_vertices, num_vertices):
    """triangles: flat 3*#T vertex indices (any int sequence); relief_vertices: indices in
    [0, num_vertices). Returns (local_vertices, local_triangles): local_vertices the relief
    vertices used by a region triangle, ascending; local_triangles a list of (a, b, c) indices
    into local_vertices, one per region triangle, in mesh order."""
    flags = bytearray(num_vertices)
    for v in relief_vertices:
        flags[v] = 1
    corners = bytes(map(flags.__getitem__, triangles))  # 1 where a corner is a relief vertex
    nt = len(corners) // 3
    if not nt:
        return [], []
    inside = (int.from_bytes(corners[0::3], "little") & int.from_bytes(corners[1::3], "little")
              & int.from_bytes(corners[2::3], "little")).to_bytes(nt, "little")
    chosen, t = [], inside.find(1)
    while t >= 0:  # bytes.find skips the runs outside the region in C
        chosen.append(t)
        t = inside.find(1, t + 1)
    used = sorted({triangles[3 * t + k] for t in chosen for k in range(3)})
    local = {v: i for i, v in enumerate(used)}
    return used, [(local[triangles[3 * t]], local[triangles[3 * t + 1]], local[triangles[3 * t + 2]]) for t in chosen]
