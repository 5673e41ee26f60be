// ParaView data (.pvd) collections: a time series of VTK XML files, one per time value.
//
// <VTKFile type="Collection" version="0.1"><Collection><DataSet timestep="T" group=""
// part="0" file="relative/path.vtm"/>...</Collection></VTKFile>, as ParaView's
// vtkPVDReader reads it (https://www.paraview.org/Wiki/ParaView/Data_formats#PVD_File_Format).
// Times are written with shortest round-trip decimals.
#ifndef SPLINEGRID_CORE_IO_VTK_PVD_H_
#define SPLINEGRID_CORE_IO_VTK_PVD_H_

#include <span>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace splinegrid {

// One time step of a collection.
struct PvdEntry {
  double time = 0.0;  // TimeValue (finite)
  std::string file;   // path relative to the .pvd, e.g. "run/run_12.vtm"
};

// The .pvd text for `entries` (in the given order; ParaView sorts by time). INVALID_ARGUMENT
// when there are no entries, a time is not finite, times repeat, or a file name is empty.
absl::StatusOr<std::string> EncodePvd(std::span<const PvdEntry> entries);

// Writes EncodePvd(entries) to `path` atomically.
absl::Status WritePvd(const std::string& path, std::span<const PvdEntry> entries);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_VTK_PVD_H_
