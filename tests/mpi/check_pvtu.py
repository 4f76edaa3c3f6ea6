"""Reads a distributed run's frames with VTK's own parallel reader.

    python3 check_pvtu.py FRAMES_DIR RANKS FRAMES REFERENCE_CSV

FRAMES_DIR holds particles.pvd, one particles_NNNNNN.pvtu per frame and one
piece per rank and frame. The series must list FRAMES frames, each .pvtu RANKS
pieces; the last frame, read whole by vtkXMLPUnstructuredGridReader, must hold
every particle once (global_id 0 .. N-1) at the positions of REFERENCE_CSV
(one "x,y,z" line per particle, the serial run's final positions, written with
17 significant digits; the frames are Float64, so they must agree exactly).
Exit status 0 when all holds; the first failure is printed.
"""
import os
import sys
import xml.etree.ElementTree as ElementTree

import vtk


def fail(message):
    print("check_pvtu: " + message)
    sys.exit(1)


def main():
    frames_dir, ranks, frames, reference_csv = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    series = ElementTree.parse(os.path.join(frames_dir, "particles.pvd")).getroot()
    files = [d.get("file") for d in series.iter("DataSet")]
    if len(files) != frames:
        fail("particles.pvd lists %d frames, expected %d" % (len(files), frames))
    for name in files:
        pieces = list(ElementTree.parse(os.path.join(frames_dir, name)).getroot().iter("Piece"))
        if len(pieces) != ranks:
            fail("%s names %d pieces, expected %d" % (name, len(pieces), ranks))
    reader = vtk.vtkXMLPUnstructuredGridReader()
    reader.SetFileName(os.path.join(frames_dir, files[-1]))
    reader.Update()
    grid = reader.GetOutput()
    reference = [tuple(float(v) for v in line.split(",")) for line in open(reference_csv) if line.strip()]
    n = grid.GetNumberOfPoints()
    if n != len(reference):
        fail("the last frame has %d points, expected %d" % (n, len(reference)))
    id_array = grid.GetPointData().GetArray("global_id")
    ids = [int(id_array.GetValue(k)) for k in range(n)]
    if sorted(ids) != list(range(n)):
        fail("global_id is not every particle once")
    for name in ("displacement", "velocity", "director"):
        array = grid.GetPointData().GetArray(name)
        if array is None or array.GetNumberOfComponents() != 3:
            fail("array %s missing or not a vector" % name)
    points = grid.GetPoints()
    for k in range(n):
        expected = reference[ids[k]]
        if tuple(points.GetPoint(k)) != expected:
            fail("particle %d at %s, the serial run has %s" % (ids[k], points.GetPoint(k), expected))
    print("check_pvtu: %d frames, %d pieces each, %d particles in the last frame at the serial positions"
          % (frames, ranks, n))


main()
