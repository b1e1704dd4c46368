#!/usr/bin/env python3
"""Makes the 3D unstructured specimens shipped in meshes/ (issue 19) with Gmsh's
Python API (`pip install gmsh`, tested with 4.15.2):

    python3 meshes/make_specimens.py

writes meshes/cylinder_d50_h100_s6mm.msh: a cylinder of diameter 50 mm and height
100 mm (SI: 0.05 x 0.1 m), the standard UCS specimen, meshed with tetrahedra of
target size 6 mm (Delaunay 3D, optimised with Netgen); MSH 4.1 ASCII, which
pcdc_mesh::gmsh reads. Physical groups: volume "rock", surfaces "bottom" (z = 0),
"top" (z = h) and "side". Gmsh seeds its meshers deterministically, so the same
version gives the same file.

Also writes meshes/bolted_block_s50mm.msh (issue 18): a 0.4 x 0.4 x 0.6 m block of
tetrahedra (target size 50 mm) with a bolt drilled along a polyline embedded in the
volume, so that its line elements share the tetrahedra's nodes: physical volume
"rock", surfaces "bottom" (z = 0) and "top" (z = 0.6), and curve "bolt" from the
collar (0.2, 0.2, 0.6) down to (0.2, 0.2, 0.3) and on to (0.25, 0.22, 0.1), in
segments of at most 50 mm. pcdc_mesh::gmsh returns the curve's lines in
`MshImport::lines`; `Bolt::from_line_group` chains them into a bolt.
"""
import os

import gmsh

HERE = os.path.dirname(os.path.abspath(__file__))


def cylinder(diameter, height, size, name):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)
    tag = gmsh.model.occ.addCylinder(0, 0, 0, 0, 0, height, diameter / 2)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)  # Delaunay
    gmsh.option.setNumber("Mesh.OptimizeNetgen", 1)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.model.addPhysicalGroup(3, [tag], name="rock")
    bottom, top, side = [], [], []
    for dim, s in gmsh.model.getEntities(2):
        x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(dim, s)
        # Gmsh pads bounding boxes by 1e-7.
        if z1 < 1e-6:
            bottom.append(s)
        elif z0 > height - 1e-6:
            top.append(s)
        else:
            side.append(s)
    gmsh.model.addPhysicalGroup(2, bottom, name="bottom")
    gmsh.model.addPhysicalGroup(2, top, name="top")
    gmsh.model.addPhysicalGroup(2, side, name="side")
    gmsh.model.mesh.generate(3)
    path = os.path.join(HERE, name + ".msh")
    gmsh.write(path)
    gmsh.finalize()
    return path


def bolted_block(size, name):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)
    box = gmsh.model.occ.addBox(0, 0, 0, 0.4, 0.4, 0.6)
    p = [
        gmsh.model.occ.addPoint(*xyz)
        for xyz in [(0.2, 0.2, 0.6), (0.2, 0.2, 0.3), (0.25, 0.22, 0.1)]
    ]
    lines = [gmsh.model.occ.addLine(p[0], p[1]), gmsh.model.occ.addLine(p[1], p[2])]
    # Fragment the block by the lines: they become edges inside the volume (its
    # tetrahedra share their nodes) and the collar a vertex of the top face.
    _, children = gmsh.model.occ.fragment([(3, box)], [(1, l) for l in lines])
    gmsh.model.occ.synchronize()
    box = children[0][0][1]
    lines = [t for c in children[1:] for (dim, t) in c if dim == 1]
    gmsh.option.setNumber("Mesh.MeshSizeMin", size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.model.addPhysicalGroup(3, [box], name="rock")
    bottom, top = [], []
    for dim, s in gmsh.model.getEntities(2):
        x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(dim, s)
        if z1 < 1e-6:
            bottom.append(s)
        elif z0 > 0.6 - 1e-6:
            top.append(s)
    gmsh.model.addPhysicalGroup(2, bottom, name="bottom")
    gmsh.model.addPhysicalGroup(2, top, name="top")
    gmsh.model.addPhysicalGroup(1, lines, name="bolt")
    gmsh.model.mesh.generate(3)
    path = os.path.join(HERE, name + ".msh")
    gmsh.write(path)
    gmsh.finalize()
    return path


if __name__ == "__main__":
    print(cylinder(0.05, 0.1, 0.006, "cylinder_d50_h100_s6mm"))
    print(bolted_block(0.05, "bolted_block_s50mm"))
