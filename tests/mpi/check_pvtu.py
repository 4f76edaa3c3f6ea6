"""Reads a distributed run's frames with VTK's own parallel reader.

    python3 check_pvtu.py FRAMES_DIR RANKS FRAMES REFERENCE_CSV STRESS_REFERENCE_CSV

FRAMES_DIR holds particles.pvd, one particles_NNNNNN.pvtu per frame and one
piece per rank and frame. The series must list FRAMES frames, each .pvtu RANKS
pieces; the last frame, read whole by vtkXMLPUnstructuredGridReader, must hold
every particle (global_id 0 .. N-1; a piece also holds the ghosts its cells
reach, so a particle may be there more than once) at the positions of
REFERENCE_CSV (one "x,y,z" line per particle, the serial run's final
positions, written with 17 significant digits; the frames are Float64, so
they must agree exactly). Likewise stress_points.pvd: FRAMES frames of RANKS
pieces; the last one must hold every stress point once as a cell (cell array
stress_point 0 .. M-1), with the serial frame's cell arrays; STRESS_REFERENCE_CSV
(the serial run's stress-point positions) gives M.
Exit status 0 when all holds; the first failure is printed.
"""
import os
import sys
import xml.etree.ElementTree as ElementTree

import vtk


def fail(message):
    print("check_pvtu: " + message)
    sys.exit(1)


def last_frame(frames_dir, series_name, ranks, frames):
    """The last frame of a series, read whole, after checking the series' length and pieces."""
    series = ElementTree.parse(os.path.join(frames_dir, series_name)).getroot()
    files = [d.get("file") for d in series.iter("DataSet")]
    if len(files) != frames:
        fail("%s lists %d frames, expected %d" % (series_name, len(files), frames))
    for name in files:
        pieces = list(ElementTree.parse(os.path.join(frames_dir, name)).getroot().iter("Piece"))
        if len(pieces) != ranks:
            fail("%s names %d pieces, expected %d" % (name, len(pieces), ranks))
    reader = vtk.vtkXMLPUnstructuredGridReader()
    reader.SetFileName(os.path.join(frames_dir, files[-1]))
    reader.Update()
    return reader.GetOutput()


def read_csv(path):
    return [tuple(float(v) for v in line.split(",")) for line in open(path) if line.strip()]


def check_stress_points(frames_dir, ranks, frames, reference_csv):
    grid = last_frame(frames_dir, "stress_points.pvd", ranks, frames)
    reference = read_csv(reference_csv)
    m = grid.GetNumberOfCells()
    if m != len(reference):
        fail("the last stress-point frame has %d cells, expected %d" % (m, len(reference)))
    index = grid.GetCellData().GetArray("stress_point")
    ids = [int(index.GetValue(k)) for k in range(m)]
    if sorted(ids) != list(range(m)):
        fail("stress_point is not every stress point once")
    for name, components in (("equivalent_stress", None), ("membrane_force", 3), ("bending_moment", 3),
                             ("thickness", 1)):
        array = grid.GetCellData().GetArray(name)
        if array is None or (components and array.GetNumberOfComponents() != components):
            fail("stress-point cell array %s missing or of the wrong size" % name)
    return m


def main():
    frames_dir, ranks, frames, reference_csv = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    stress_reference_csv = sys.argv[5]
    grid = last_frame(frames_dir, "particles.pvd", ranks, frames)
    reference = read_csv(reference_csv)
    n = grid.GetNumberOfPoints()
    id_array = grid.GetPointData().GetArray("global_id")
    ids = [int(id_array.GetValue(k)) for k in range(n)]
    if sorted(set(ids)) != list(range(len(reference))):
        fail("global_id is not every particle")
    for name in ("displacement", "velocity", "director"):
        array = grid.GetPointData().GetArray(name)
        if array is None or array.GetNumberOfComponents() != 3:
            fail("array %s missing or not a vector" % name)
    points = grid.GetPoints()
    for k in range(n):
        expected = reference[ids[k]]
        if tuple(points.GetPoint(k)) != expected:
            fail("particle %d at %s, the serial run has %s" % (ids[k], points.GetPoint(k), expected))
    m = check_stress_points(frames_dir, ranks, frames, stress_reference_csv)
    print("check_pvtu: %d frames, %d pieces each, %d particles and %d stress points in the last frame at the "
          "serial positions" % (frames, ranks, len(reference), m))


main()
