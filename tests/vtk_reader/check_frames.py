"""Reads a fracture run's ParaView frames with VTK's own reader
(vtkXMLUnstructuredGridReader, the one ParaView uses for .vtu) and checks what
a person would see: arrays, cell counts, the surface, the removed cells.

usage: check_frames.py FRAMES_DIR STDOUT_FILE END_TIME STRESS_POINTS ENCODING

FRAMES_DIR holds particles.pvd, stress_points.pvd and cracks.pvd of
`square_plate --case fracture --pressure 12e6 --frames`; STDOUT_FILE is what the example
printed ("... N damaged stress points ..."); END_TIME the --end-time given;
STRESS_POINTS the model's stress point count; ENCODING the frames' default
encoding (zlib, or binary for a build without zlib).
"""
import os
import re
import sys
import xml.etree.ElementTree as ElementTree

import vtk

VTK_VERTEX, VTK_LINE, VTK_QUAD = 1, 3, 9
failures = []


def check(condition, message):
    print(("ok    " if condition else "FAIL  ") + message)
    if not condition:
        failures.append(message)


def collection(path):
    """(time, file) of each DataSet of a .pvd, parsed as plain XML."""
    root = ElementTree.parse(path).getroot()
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def read(directory, name):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(os.path.join(directory, name))
    reader.Update()
    return reader.GetOutput()


def array_names(data):
    return sorted(data.GetArrayName(i) for i in range(data.GetNumberOfArrays()))


def cell_types(grid):
    return {grid.GetCellType(c) for c in range(grid.GetNumberOfCells())}


def surface_area(grid):
    sizes = vtk.vtkCellSizeFilter()
    sizes.SetInputData(grid)
    sizes.ComputeSumOn()
    sizes.Update()
    return sizes.GetOutput().GetFieldData().GetArray("Area").GetValue(0)


def boundary_edges(grid):
    """Edges on one cell only: the plate's rim plus the faces of every gap."""
    surface = vtk.vtkGeometryFilter()
    surface.SetInputData(grid)
    edges = vtk.vtkFeatureEdges()
    edges.SetInputConnection(surface.GetOutputPort())
    edges.BoundaryEdgesOn()
    edges.FeatureEdgesOff()
    edges.NonManifoldEdgesOff()
    edges.ManifoldEdgesOff()
    edges.Update()
    return edges.GetOutput().GetNumberOfCells()


def particles_count(directory, series):
    return read(directory, series["particles"][0][1]).GetNumberOfPoints()


def main(directory, stdout_file, end_time, stress_points, encoding):
    printed = open(stdout_file, encoding="utf-8").read()
    damaged = int(re.search(r"(\d+) damaged stress points", printed).group(1))
    series = {name: collection(os.path.join(directory, name + ".pvd"))
              for name in ("particles", "stress_points", "cracks")}
    times = [t for t, _ in series["particles"]]
    check(len(times) >= 3, f"particles.pvd lists {len(times)} frames")
    check(all([t for t, _ in entries] == times for entries in series.values()),
          "the three collections list the same frame times")
    check(len(set(times)) == len(times), "no frame listed twice")
    interval = times[1] - times[0]
    check(abs(times[-1] - end_time) < 0.01 * interval,
          f"the last frame is the end of the run: t = {times[-1]:.9g} s for --end-time {end_time:g}")

    first = read(directory, series["stress_points"][0][1])
    last = read(directory, series["stress_points"][-1][1])
    check(first.GetNumberOfCells() == stress_points,
          f"first stress-point frame: {first.GetNumberOfCells()} cells, one per stress point ({stress_points})")
    check(cell_types(first) == {VTK_QUAD}, "stress points are quads over their particles")
    removed = stress_points - last.GetNumberOfCells()
    check(damaged > 0, f"the run fractured: {damaged} damaged stress points printed")
    check(removed == damaged,
          f"last frame: {last.GetNumberOfCells()} cells, {removed} removed = the {damaged} damaged stress points")
    quads = sum(1 for c in range(last.GetNumberOfCells()) if last.GetCellType(c) == VTK_QUAD)
    vertices = sum(1 for c in range(last.GetNumberOfCells()) if last.GetCellType(c) == VTK_VERTEX)
    check(quads + vertices == last.GetNumberOfCells() and vertices == last.GetNumberOfPoints() - particles_count(directory, series),
          f"last frame: {quads} quads and {vertices} vertex cells (stress points whose cell a crack cuts, "
          f"each at a point after the particles)")
    kept = last.GetCellData().GetArray("stress_point")
    kept_indices = {int(kept.GetTuple1(c)) for c in range(kept.GetNumberOfTuples())}
    check(len(kept_indices) == last.GetNumberOfCells() and max(kept_indices) < stress_points,
          "cell array stress_point names distinct stress points")
    check(array_names(last.GetCellData()) == sorted(["equivalent_stress", "equivalent_plastic_strain", "damage",
                                                     "membrane_force", "bending_moment", "thickness",
                                                     "stress_point"]),
          f"stress-point cell data: {array_names(last.GetCellData())}")
    stress = last.GetCellData().GetArray("equivalent_stress")
    components = [stress.GetComponentName(k) for k in range(stress.GetNumberOfComponents())]
    check(components[0].startswith("bottom zeta=-") and components[-1].startswith("top zeta=+"),
          f"through-thickness components named bottom to top: {components}")
    check(stress.GetDataType() == vtk.VTK_FLOAT, "default precision: Float32")
    check(last.GetFieldData().GetArray("TimeValue").GetValue(0) == series["stress_points"][-1][0],
          "TimeValue of the last file equals its collection time")

    area = surface_area(first)
    check(abs(area - 0.25) < 1e-6, f"first frame: the cells cover the 0.5 m x 0.5 m plate ({area:.9g} m^2)")
    rim, torn = boundary_edges(first), boundary_edges(last)
    check(rim == 4 * 20, f"first frame: {rim} boundary edges, the plate's rim of 4 x 20")
    check(torn > rim, f"last frame: {torn} boundary edges, the removed cells open gaps (cracks)")

    particles_first = read(directory, series["particles"][0][1])
    particles_last = read(directory, series["particles"][-1][1])
    check(array_names(particles_last.GetPointData()) ==
          sorted(["displacement", "velocity", "rotation", "director", "fragment"]),
          f"particle point data: {array_names(particles_last.GetPointData())}")
    check(particles_last.GetNumberOfPoints() == particles_first.GetNumberOfPoints(), "particle count constant")
    # Deformed coordinates: Points(t) - Points(0) is the displacement array
    # (to Float32 rounding), so Warp By Vector must not be applied.
    displacement = particles_last.GetPointData().GetArray("displacement")
    worst, largest = 0.0, 0.0
    for i in range(particles_last.GetNumberOfPoints()):
        moved = [a - b for a, b in zip(particles_last.GetPoint(i), particles_first.GetPoint(i))]
        worst = max(worst, max(abs(m - u) for m, u in zip(moved, displacement.GetTuple3(i))))
        largest = max(largest, max(abs(u) for u in displacement.GetTuple3(i)))
    check(largest > 1e-3 and worst < 1e-6,
          f"points are deformed positions: |Points - Points(0) - displacement| <= {worst:.2g} m "
          f"(largest displacement {largest:.3g} m)")
    cracks = read(directory, series["cracks"][-1][1])
    check(cracks.GetNumberOfCells() > 0 and cell_types(cracks) == {VTK_LINE},
          f"last crack frame: {cracks.GetNumberOfCells()} line segments")
    with open(os.path.join(directory, series["stress_points"][-1][1]), "rb") as head:
        compressed = b'compressor="vtkZLibDataCompressor"' in head.read(4000)
        check(compressed == (encoding == "zlib"), f"default encoding: {encoding}")
    print(f"{len(failures)} failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4]), sys.argv[5]))
