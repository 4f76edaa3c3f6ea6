"""Reads a rigid-body impact run's ParaView frames with VTK's own reader and
checks what a person opening particles.pvd would see: at every time the plate
(part 0) and the striker's surface (part 1), the striker drawn as the body it
is, where it is, with its arrays.

usage: check_body_frames.py FRAMES_DIR HISTORY_CSV SIDE THICKNESS RADIUS

FRAMES_DIR holds particles.pvd of `mass_impact --frames` (a flat-ended
cylinder of radius RADIUS striking the centre of a SIDE x SIDE plate of
THICKNESS); HISTORY_CSV is its history.csv (t, striker z, striker vz, ...).
"""
import csv
import math
import os
import sys
import xml.etree.ElementTree as ElementTree

import vtk

VTK_TRIANGLE = 5
coordinate_rounding = 1e-7  # m: float32 coordinates of a model about 0.2 m across
failures = []


def check(condition, message):
    print(("ok    " if condition else "FAIL  ") + message)
    if not condition:
        failures.append(message)


def read(directory, name):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(os.path.join(directory, name))
    reader.Update()
    return reader.GetOutput()


def main():
    directory, history_path = sys.argv[1], sys.argv[2]
    side, thickness, radius = (float(v) for v in sys.argv[3:6])
    root = ElementTree.parse(os.path.join(directory, "particles.pvd")).getroot()
    parts = {}
    for entry in root.iter("DataSet"):
        parts.setdefault(float(entry.get("timestep")), {})[int(entry.get("part"))] = entry.get("file")
    check(len(parts) >= 3, f"particles.pvd lists {len(parts)} frame times (at least 3)")
    check(all(sorted(p) == [0, 1] for p in parts.values()), "every frame time lists the plate (part 0) and the bodies (part 1)")

    with open(history_path) as f:
        rows = [[float(v) for v in row] for row in csv.reader(f) if row and not row[0].startswith(("#", "t"))]
    last_time = max(parts)
    body = read(directory, parts[last_time][1])
    plate = read(directory, parts[last_time][0])
    check(plate.GetNumberOfPoints() > 0, f"the plate has {plate.GetNumberOfPoints()} points")
    cells = body.GetNumberOfCells()
    types = {body.GetCellType(c) for c in range(cells)}
    check(cells > 0 and types == {VTK_TRIANGLE}, f"the striker is drawn as {cells} triangles")
    cell_arrays = sorted(body.GetCellData().GetArrayName(i) for i in range(body.GetCellData().GetNumberOfArrays()))
    point_arrays = sorted(body.GetPointData().GetArrayName(i) for i in range(body.GetPointData().GetNumberOfArrays()))
    check(cell_arrays == ["body", "contact_force"], f"cell arrays {cell_arrays}")
    check(point_arrays == ["velocity"], f"point arrays {point_arrays}")

    # Where it is: the history's row nearest the frame's time gives the
    # striker's centre height; the drawn surface's lowest point is its face,
    # half the body's length below the centre, and its axis is the plate's centre.
    points = [body.GetPoint(i) for i in range(body.GetNumberOfPoints())]
    zs = [p[2] for p in points]
    length = max(zs) - min(zs)
    drawn_centre = 0.5 * (max(zs) + min(zs))
    row = min(rows, key=lambda r: abs(r[0] - last_time))
    step_tolerance = abs(row[2]) * abs(row[0] - last_time) + 1e-9
    check(abs(drawn_centre - row[1]) <= step_tolerance + 1e-6 * length,
          f"the drawn centre height {drawn_centre:.9g} m is the history's {row[1]:.9g} m at t = {row[0]:.6g} s")
    largest_radius = max(math.hypot(p[0] - 0.5 * side, p[1] - 0.5 * side) for p in points)
    # Coordinates are stored as float32 by default: about 1e-8 m at 0.1 m.
    check(abs(largest_radius - radius) <= coordinate_rounding,
          f"the drawn radius {largest_radius:.9g} m is the striker's {radius:.9g} m about the plate's centre")

    # The area of a closed, flat-ended cylinder drawn with m segments round:
    # the side 2 r sin(pi/m) m L and the two ends m r^2 sin(2 pi/m) / 2 each.
    sizes = vtk.vtkCellSizeFilter()
    sizes.SetInputData(body)
    sizes.ComputeSumOn()
    sizes.Update()
    area = sizes.GetOutput().GetFieldData().GetArray("Area").GetValue(0)
    exact = 2.0 * math.pi * radius * length + 2.0 * math.pi * radius * radius
    check(abs(area - exact) <= 0.02 * exact, f"the drawn area {area:.6g} m^2 is the cylinder's {exact:.6g} m^2 within 2 %")

    # The point velocities are the body's: the history's vz at that time.
    velocity = body.GetPointData().GetArray("velocity")
    vz = [velocity.GetTuple3(i)[2] for i in range(body.GetNumberOfPoints())]
    acceleration_bound = 0.05 * max(abs(row[2]), 1e-3)
    check(all(abs(v - row[2]) <= acceleration_bound for v in vz),
          f"every drawn point moves at the striker's vz {row[2]:.6g} m/s (within 5 %)")

    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)


if __name__ == "__main__":
    main()
