#!/bin/sh
# The quarter plates of cli/tests/run_split_meshes.rs, made with gmsh 4.15 (pip install gmsh):
# gmsh's default triangles, a mixed mesh, and second-order triangles and quadrilaterals.
set -e
cd "$(dirname "$0")"
gmsh -setnumber lc 2.8 -2 -format msh41 quarter.geo -o tri.msh
gmsh -setnumber lc 2 -2 -format msh41 quarter-mixed.geo -o mixed.msh
gmsh -setnumber lc 4 -2 -order 2 -format msh41 quarter.geo -o tri6.msh
gmsh -setnumber lc 4 -setnumber quads 1 -2 -order 2 -format msh41 quarter.geo -o quad9.msh
gmsh -setnumber lc 4 -setnumber quads 1 -2 -order 2 -setnumber Mesh.SecondOrderIncomplete 1 -format msh41 quarter.geo -o quad8.msh
