// CGNS files (Debian libcgns 3.4, HDF5 or ADF) as structured multi-block grids with their
// boundary conditions and 1-to-1 connectivity. This library links libcgns; the kernel
// (splinegrid_core) does not. The server never calls the reader in its own process (a hostile
// file can crash libcgns or HDF5): it runs splinegrid-cgns-decode (decode_main.cc) as a child.
//
// Reference: CGNS Standard Interface Data Structures (SIDS), sections 6 (Zone_t), 7
// (GridCoordinates_t), 8 (ZoneGridConnectivity_t), 9 (ZoneBC_t), 12.6 (FamilyBC_t); the
// mid-level library (cgnslib.h) documentation for the calls.
#ifndef SPLINEGRID_IO_CGNS_CGNS_IO_H_
#define SPLINEGRID_IO_CGNS_CGNS_IO_H_

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "core/grid/source_boundaries.h"

namespace splinegrid {

// The boundary kind of a CGNS BCType_t name: BCWall* -> wall; far field, inflow, outflow,
// tunnel, extrapolate, degenerate, Dirichlet/Neumann/general -> outer; symmetry planes and
// polar/wedge symmetry -> interface (a symmetry plane is the interface with the grid's mirror
// image: held to the interface tolerance, tighter than outer boundaries). nullopt for
// BCTypeNull, BCTypeUserDefined and names that are not BC types.
std::optional<BoundaryKind> KindOfBcType(const std::string& bc_type);

// Reads the first base of a CGNS file: every zone must be structured (else INVALID_ARGUMENT
// naming it); CellDim 2 with PhysDim 2 (planar) or 3 (surfaces), or CellDim 3 with PhysDim 3;
// CoordinateX/Y(/Z) in single or double precision (read as double); no rind planes. Boundary
// conditions given as vertex or face-centre point ranges, directly typed or FamilySpecified
// (resolved through the base's Family_t FamilyBC), become SourceBoundary entries; 1-to-1
// connections become StatedConnection. Everything left out (further bases, point lists,
// general connectivity, overset holes, untyped conditions) is named in boundaries.notes.
absl::StatusOr<ImportedGrid> ReadCgnsFile(const std::string& path);

struct CgnsWriteOptions {
  // Source index i of every direction is written at i * index_scale (2^level of an evaluation
  // at a refinement level); block extents must be (source extent - 1) * index_scale + 1.
  int index_scale = 1;
  // The source block of every written block (empty: 0, 1, ...) and the source extents, by
  // source index (empty: conditions and matches are not written).
  std::vector<int> source_blocks;
  std::vector<Extents> source_extents;
  // By source index; empty: "block_<index>", the index zero-padded to the widest (block_07 of
  // 12), so that the zones, which libcgns lists by name, come back in the same order.
  std::vector<std::string> block_names;
  std::vector<SourceBoundary> conditions;  // at source indices
  std::vector<BoundaryMatch> matches;      // at source indices, written as 1-to-1 both ways
  bool single_precision = false;           // RealSingle coordinates
  // The base's name ("" : "Base"), DataClass and DimensionalUnits (SourceBoundaries: a CGNS
  // source's, written back). No DataClass (a Plot3D source): NormalizedByUnknownDimensional,
  // coordinates in an unstated unit.
  std::string base_name;
  std::string data_class;
  std::vector<std::string> units;  // none or five: mass, length, time, temperature, angle
};

// Writes `grid` as one CGNS (HDF5) base: a structured zone per block, its coordinates, the
// boundary conditions (a Family_t with FamilyBC per family, FamilySpecified conditions) and a
// GridConnectivity1to1_t on both sides of every point-matched match. Matches with hanging nodes
// (step 2) have no 1-to-1 form: they are left out and named in `notes`.
absl::Status WriteCgnsFile(const std::string& path, const MultiBlockGrid& grid,
                           const CgnsWriteOptions& options, std::vector<std::string>* notes);

// True when `bytes` (a file's first bytes, 8 KiB suffice) are those of a CGNS file: the HDF5
// signature at offset 0 or after a user block (512, 1024, ... 8192), or an ADF header.
bool LooksLikeCgns(std::string_view bytes);

}  // namespace splinegrid

#endif  // SPLINEGRID_IO_CGNS_CGNS_IO_H_
