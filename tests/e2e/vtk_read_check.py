#!/usr/bin/python3
"""Reads VTK XML files with VTK 9 (python3-vtk9) and prints what a ParaView user would see.

usage: vtk_read_check.py FILE...   (.vts, .vtm or .pvd; a .pvd's DataSets are read in turn)

One line per dataset: "<file> <block name> points=N cells=M point:<name>/<components>/<min>/<max>
... cell:..." with exit 1 when a file fails to read or holds no points. The C++ e2e tests compare
these lines with what they wrote.
"""
import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import vtk
from vtk.util.numpy_support import vtk_to_numpy


def describe(name, label, grid):
    if grid is None or grid.GetNumberOfPoints() == 0:
        print(f"{name} {label}: no points")
        sys.exit(1)
    words = [name, label, f"points={grid.GetNumberOfPoints()}", f"cells={grid.GetNumberOfCells()}"]
    for kind, data in (("point", grid.GetPointData()), ("cell", grid.GetCellData())):
        for i in range(data.GetNumberOfArrays()):
            values = vtk_to_numpy(data.GetArray(i))
            components = 1 if values.ndim == 1 else values.shape[1]
            words.append(f"{kind}:{data.GetArrayName(i)}/{components}/{values.min():.6g}/{values.max():.6g}")
    print(" ".join(words))


def read(path):
    path = Path(path)
    if path.suffix == ".pvd":
        root = ElementTree.parse(path).getroot()
        for dataset in root.iter("DataSet"):
            print(f"{path} timestep={float(dataset.get('timestep')):.6g} file={dataset.get('file')}")
            read(path.parent / dataset.get("file"))
        return
    if path.suffix == ".vts":
        reader = vtk.vtkXMLStructuredGridReader()
    elif path.suffix == ".vtm":
        reader = vtk.vtkXMLMultiBlockDataReader()
    else:
        print(f"{path}: not a VTK XML file")
        sys.exit(1)
    reader.SetFileName(str(path))
    reader.Update()
    if reader.GetErrorCode() != 0:
        print(f"{path}: VTK error {reader.GetErrorCode()}")
        sys.exit(1)
    output = reader.GetOutput()
    if path.suffix == ".vts":
        describe(str(path), "-", output)
        return
    for b in range(output.GetNumberOfBlocks()):
        label = output.GetMetaData(b).Get(vtk.vtkCompositeDataSet.NAME())
        describe(str(path), label, output.GetBlock(b))


if __name__ == "__main__":
    print(f"VTK {vtk.vtkVersion.GetVTKVersion()}")
    for argument in sys.argv[1:]:
        read(argument)
