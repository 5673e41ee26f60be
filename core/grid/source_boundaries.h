// The boundary conditions an imported grid file carries (CGNS BC_t nodes), mapped to the
// boundary kinds of the fit (core/grid/boundary_kinds.h). They are kept with the source points
// and give the default kind of every face they cover; a fit's explicit FaceKindOverride for the
// same face wins.
#ifndef SPLINEGRID_CORE_GRID_SOURCE_BOUNDARIES_H_
#define SPLINEGRID_CORE_GRID_SOURCE_BOUNDARIES_H_

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/grid/boundary_kinds.h"
#include "core/grid/connectivity.h"

namespace splinegrid {

// One boundary condition: a rectangle of a block face (0-based, inclusive) and its kind.
struct SourceBoundary {
  FaceRange range;
  // Unset for a condition whose type says nothing about the kind (BCTypeUserDefined,
  // BCTypeNull): it is kept, and written back, but its points keep the detected kind.
  std::optional<BoundaryKind> kind = BoundaryKind::kOuter;
  std::string name;     // the file's name of the condition, e.g. "wall"
  std::string bc_type;  // e.g. "BCWallViscous" (a family's type when it came from one)
  std::string family;   // the family it came from; empty when given directly
};

struct SourceBoundaries {
  std::vector<std::string> block_names;  // empty or one per block
  std::vector<SourceBoundary> conditions;
  std::vector<FaceKindOverride> face_kinds;  // FaceKindsOf(conditions)
  std::vector<std::string> notes;            // choices made and content left out, one sentence each
  // A CGNS file's base: its name, its DataClass and DimensionalUnits (mass, length, time,
  // temperature, angle), by their SIDS names ("Dimensional", "Meter", ...); empty when the
  // file states none. The CGNS writer writes them back.
  std::string base_name;
  std::string data_class;
  std::vector<std::string> units;  // none or five

  bool empty() const {
    return block_names.empty() && conditions.empty() && notes.empty() && base_name.empty() &&
           data_class.empty() && units.empty();
  }
};

// A 1-to-1 connection a file states (CGNS GridConnectivity1to1_t): `range` of its block
// coincides with `donor`; transform[d] = +-(donor direction + 1) for each direction d of the
// range's block (CGNS convention). The server finds coinciding points itself; these are compared
// with what it found.
struct StatedConnection {
  std::string name;
  FaceRange range;
  FaceRange donor;
  std::array<int, 3> transform = {1, 2, 3};
};

// A grid file's content beyond points: what an importer read besides the blocks.
struct ImportedGrid {
  MultiBlockGrid grid;
  SourceBoundaries boundaries;
  std::vector<StatedConnection> connections;
  std::string format;  // e.g. "cgns hdf5, 2d, 1 zone, double"
};

// Notes for stated connections whose points the found connectivity does not cover (no match
// joins the same two faces), naming them; empty when all agree.
std::vector<std::string> CompareConnections(const std::vector<StatedConnection>& stated,
                                            const Connectivity& found,
                                            const std::vector<std::string>& block_names);

// Tightness order of the kinds for a face with conditions of several kinds: wall (the tightest
// tolerance), then interface, then outer.
int KindTightness(BoundaryKind kind);

// One kind per face that has conditions: the tightest of them. A face with conditions of
// different kinds gets a note in `notes` naming the face, the conditions and the kind chosen.
// `block_names` (may be empty) name the blocks in notes.
std::vector<FaceKindOverride> FaceKindsOf(const std::vector<SourceBoundary>& conditions,
                                          const std::vector<std::string>& block_names,
                                          std::vector<std::string>* notes);

// `explicit_kinds` plus every default whose face none of them names (explicit kinds win).
std::vector<FaceKindOverride> WithDefaultFaceKinds(std::vector<FaceKindOverride> explicit_kinds,
                                                   const std::vector<FaceKindOverride>& defaults);

// INVALID_ARGUMENT naming `field` and the value unless every condition and face kind names an
// existing block, a face of an active direction, and a range on that face inside the block;
// block_names is empty or has one entry per block. Checks input from files and stores.
absl::Status ValidateSourceBoundaries(const SourceBoundaries& boundaries,
                                      const std::vector<Extents>& blocks, const std::string& field);

// "block 2 ('wing') j=min i[0..64]" for messages.
std::string DescribeFaceRange(const FaceRange& range, const std::vector<std::string>& block_names);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GRID_SOURCE_BOUNDARIES_H_
