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


if __name__ == "__main__":
    print(cylinder(0.05, 0.1, 0.006, "cylinder_d50_h100_s6mm"))
