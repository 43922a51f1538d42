#!/usr/bin/python3
"""The reconstruct-then-simplify peer of issue 27 (bench only, as FLANN is for k-NN).

What a user with a point set and no mesh would do instead of building domain primitives:
screened Poisson surface reconstruction (Kazhdan and Hoppe 2013) of the oriented points with
Debian's python3-open3d, the low-density skirt trimmed, then quadric edge-collapse decimation
(Garland and Heckbert 1997, open3d's simplify_quadric_decimation) to exactly the level's primitive
count in triangles. Vertex colours are kept where the points have them (Poisson interpolates them
to its vertices; the decimation carries them along).

    bench/poisson_peer.py POINTS.ply OUT_PREFIX COUNT [COUNT...]

POINTS.ply is what `amgsplat sample` writes (binary PLY: x y z, nx ny nz, and red green blue
alpha when the mesh has colours). Writes OUT_PREFIX-COUNT.ply (binary PLY with faces and vertex
colours, which `amgsplat render` and bench_fit read through the mesh loader) and prints one CSV
line per count on stdout: count,triangles,vertices,poisson_s,decimate_s.
"""
import sys
import time

import numpy as np
import open3d as o3d

# Octree depth 8 (open3d's default): a 256^3 grid resolves features of 1/256 of the extent, far
# finer than the few hundred triangles it is decimated to, and it leaves the reconstruction
# closed over the spacing of 100k samples. Depth 9 (the open3d tutorial's) took 177 s on the cow
# at load ~4 on this 2-core machine against 13.5 s at depth 8, for a mesh that is decimated to <= 400 triangles.
DEPTH = 8
# Trim the vertices whose density (the number of samples supporting them) is in the lowest 1%:
# the open3d tutorial's value. It removes the skirt Poisson extends over holes in the samples
# (the bunny's open base) and leaves a closed model (cow, spot, fandisk) whole; a larger quantile
# started to eat into thin parts.
TRIM_QUANTILE = 0.01


def main(argv):
    if len(argv) < 4:
        sys.stderr.write(__doc__)
        return 2
    src, prefix, counts = argv[1], argv[2], [int(c) for c in argv[3:]]
    pcd = o3d.io.read_point_cloud(src)
    if not pcd.has_points():
        sys.stderr.write(f"poisson_peer: {src}: no points\n")
        return 1
    if not pcd.has_normals():
        sys.stderr.write(f"poisson_peer: {src}: points without normals (sample writes them)\n")
        return 1
    t0 = time.perf_counter()
    with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
        mesh, density = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(pcd, depth=DEPTH)
    density = np.asarray(density)
    mesh.remove_vertices_by_mask(density < np.quantile(density, TRIM_QUANTILE))
    mesh.remove_unreferenced_vertices()
    t_poisson = time.perf_counter() - t0
    for n in counts:
        t1 = time.perf_counter()
        low = mesh.simplify_quadric_decimation(target_number_of_triangles=n)
        low.remove_unreferenced_vertices()
        low.compute_vertex_normals()
        t_dec = time.perf_counter() - t1
        out = f"{prefix}-{n}.ply"
        if not o3d.io.write_triangle_mesh(out, low, write_ascii=False, write_vertex_colors=pcd.has_colors(),
                                          write_vertex_normals=True):
            sys.stderr.write(f"poisson_peer: cannot write {out}\n")
            return 1
        print(f"{n},{len(low.triangles)},{len(low.vertices)},{t_poisson:.2f},{t_dec:.2f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
