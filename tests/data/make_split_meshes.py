"""Makes the triangle, mixed and second-order fixtures of tests/mesh_split.rs and tests/io_gmsh.rs.

Run from tests/data with the gmsh Python module (pip install gmsh): python3 make_split_meshes.py
"""
import gmsh


def holed(name, lc, order=1, recombine=False, incomplete=False, binary=False):
    """A 4 x 3 plate with a hole of radius 0.7 at (2, 1.5)."""
    gmsh.clear()
    gmsh.model.add(name)
    occ = gmsh.model.occ
    r = occ.addRectangle(0, 0, 0, 4, 3)
    d = occ.addDisk(2, 1.5, 0, 0.7, 0.7)
    occ.cut([(2, r)], [(2, d)])
    occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", lc)
    curves = gmsh.model.getEntities(1)
    hole = [c for _, c in curves if abs(gmsh.model.occ.getMass(1, c) - 2 * 3.141592653589793 * 0.7) < 1e-6]
    outer = [c for _, c in curves if c not in hole]
    gmsh.model.addPhysicalGroup(1, hole, 11, "hole")
    gmsh.model.addPhysicalGroup(1, outer, 12, "outer")
    gmsh.model.addPhysicalGroup(2, [s for _, s in gmsh.model.getEntities(2)], 13, "plate")
    pts = gmsh.model.getEntities(0)
    origin = [p for _, p in pts if max(abs(x) for x in gmsh.model.getValue(0, p, [])) < 1e-9]
    gmsh.model.addPhysicalGroup(0, origin, 14, "origin")
    if recombine:
        gmsh.option.setNumber("Mesh.RecombineAll", 1)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1 if incomplete else 0)
    gmsh.model.mesh.generate(2)
    if order > 1:
        gmsh.model.mesh.setOrder(order)
    gmsh.option.setNumber("Mesh.Binary", 1 if binary else 0)
    gmsh.write(name)
    gmsh.option.setNumber("Mesh.RecombineAll", 0)


def mixed(name):
    """A 2 x 1 plate of two squares: the left one triangles, the right one quadrilaterals."""
    gmsh.clear()
    gmsh.model.add(name)
    geo = gmsh.model.geo
    p = [geo.addPoint(x, y, 0, 0.35) for x, y in [(0, 0), (1, 0), (2, 0), (2, 1), (1, 1), (0, 1)]]
    l = [geo.addLine(p[i], p[(i + 1) % 6]) for i in range(6)]
    mid = geo.addLine(p[1], p[4])
    left = geo.addPlaneSurface([geo.addCurveLoop([l[0], mid, l[4], l[5]])])
    right = geo.addPlaneSurface([geo.addCurveLoop([l[1], l[2], l[3], -mid])])
    geo.mesh.setRecombine(2, right)
    geo.synchronize()
    gmsh.model.addPhysicalGroup(1, [l[0], l[1]], 1, "bottom")
    gmsh.model.addPhysicalGroup(1, [l[5]], 2, "left")
    gmsh.model.addPhysicalGroup(2, [left, right], 3, "plate")
    gmsh.model.addPhysicalGroup(0, [p[3]], 4, "corner")
    gmsh.model.mesh.generate(2)
    gmsh.write(name)


def cube(name):
    gmsh.clear()
    gmsh.model.add(name)
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 1.0)
    gmsh.model.mesh.generate(3)
    gmsh.write(name)


gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
holed("holed_tri.msh", 0.6)
holed("holed_tri_bin.msh", 0.6, binary=True)
holed("holed_tri6.msh", 1.0, order=2)
holed("holed_quad9.msh", 1.0, order=2, recombine=True)
holed("holed_quad8.msh", 1.0, order=2, recombine=True, incomplete=True)
mixed("mixed.msh")
gmsh.finalize()
