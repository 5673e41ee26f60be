#include "core/grid/source_boundaries.h"

#include <algorithm>
#include <map>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace splinegrid {
namespace {

constexpr char kDirectionNames[] = "ijk";

// Faces ordered for a deterministic result.
std::pair<int, int> FaceKey(const Face& face) {
  return {face.block, 2 * face.normal + (face.upper ? 1 : 0)};
}

}  // namespace

std::vector<std::string> CompareConnections(const std::vector<StatedConnection>& stated,
                                            const Connectivity& found,
                                            const std::vector<std::string>& block_names) {
  std::vector<std::string> notes;
  for (const StatedConnection& c : stated) {
    const bool covered =
        std::any_of(found.matches.begin(), found.matches.end(), [&](const BoundaryMatch& m) {
          return (m.a.face == c.range.face && m.b.face == c.donor.face) ||
                 (m.b.face == c.range.face && m.a.face == c.donor.face);
        });
    if (!covered) {
      notes.push_back(absl::StrCat("the file's 1-to-1 connection '", c.name, "' (",
                                   DescribeFaceRange(c.range, block_names), " ~ ",
                                   DescribeFaceRange(c.donor, block_names),
                                   ") joins points that do not coincide; they are fitted by "
                                   "their own kinds, not as an interface"));
    }
  }
  return notes;
}

int KindTightness(BoundaryKind kind) {
  switch (kind) {
    case BoundaryKind::kWall:
      return 0;
    case BoundaryKind::kInterface:
      return 1;
    case BoundaryKind::kOuter:
      return 2;
  }
  return 3;
}

std::string DescribeFaceRange(const FaceRange& range, const std::vector<std::string>& block_names) {
  const int b = range.face.block;
  std::string s = absl::StrCat("block ", b);
  if (b >= 0 && b < static_cast<int>(block_names.size())) {
    absl::StrAppend(&s, " ('", block_names[b], "')");
  }
  absl::StrAppend(&s, " ", FaceName(range.face));
  for (int d = 0; d < 3; ++d) {
    if (d != range.face.normal && range.end[d] > range.begin[d]) {
      absl::StrAppend(&s, " ", std::string(1, kDirectionNames[d]), "[", range.begin[d], "..",
                      range.end[d], "]");
    }
  }
  return s;
}

std::vector<FaceKindOverride> FaceKindsOf(const std::vector<SourceBoundary>& conditions,
                                          const std::vector<std::string>& block_names,
                                          std::vector<std::string>* notes) {
  std::map<std::pair<int, int>, std::vector<const SourceBoundary*>> by_face;
  for (const SourceBoundary& c : conditions) {
    if (c.kind) by_face[FaceKey(c.range.face)].push_back(&c);  // untyped ones set no kind
  }
  std::vector<FaceKindOverride> kinds;
  for (const auto& [key, list] : by_face) {
    BoundaryKind tightest = *list.front()->kind;
    bool mixed = false;
    for (const SourceBoundary* c : list) {
      if (*c->kind != tightest) mixed = true;
      if (KindTightness(*c->kind) < KindTightness(tightest)) tightest = *c->kind;
    }
    const Face face = list.front()->range.face;
    kinds.push_back({face, tightest});
    if (mixed && notes != nullptr) {
      std::vector<std::string> parts;
      for (const SourceBoundary* c : list) {
        parts.push_back(absl::StrCat("'", c->name, "' ", c->bc_type, " (",
                                     std::string(BoundaryKindName(*c->kind)), ")"));
      }
      FaceRange whole{face, {0, 0, 0}, {0, 0, 0}};
      std::string where = DescribeFaceRange(whole, block_names);
      notes->push_back(
          absl::StrCat(where, " has conditions of different kinds: ", absl::StrJoin(parts, ", "),
                       "; the whole face is fitted as ", std::string(BoundaryKindName(tightest)),
                       ", the tightest of them"));
    }
  }
  return kinds;
}

std::vector<FaceKindOverride> WithDefaultFaceKinds(std::vector<FaceKindOverride> explicit_kinds,
                                                   const std::vector<FaceKindOverride>& defaults) {
  const size_t given = explicit_kinds.size();
  for (const FaceKindOverride& d : defaults) {
    const auto end = explicit_kinds.begin() + given;
    if (std::none_of(explicit_kinds.begin(), end,
                     [&](const FaceKindOverride& e) { return e.face == d.face; })) {
      explicit_kinds.push_back(d);
    }
  }
  return explicit_kinds;
}

namespace {

absl::Status ValidateFace(const Face& face, const std::vector<Extents>& blocks,
                          const std::string& field) {
  if (face.block < 0 || face.block >= static_cast<int>(blocks.size())) {
    return absl::InvalidArgumentError(absl::StrCat(field, ".block = ", face.block,
                                                   " is outside [0, ",
                                                   static_cast<int>(blocks.size()) - 1, "]"));
  }
  if (face.normal < 0 || face.normal > 2 || blocks[face.block][face.normal] < 2) {
    return absl::InvalidArgumentError(absl::StrCat(field, ": ", FaceName(face),
                                                   " is not a face of block ", face.block,
                                                   " (its direction has one point)"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ValidateSourceBoundaries(const SourceBoundaries& boundaries,
                                      const std::vector<Extents>& blocks,
                                      const std::string& field) {
  if (!boundaries.block_names.empty() && boundaries.block_names.size() != blocks.size()) {
    return absl::InvalidArgumentError(absl::StrCat(field,
                                                   ".block_names: ", boundaries.block_names.size(),
                                                   " names for ", blocks.size(), " blocks"));
  }
  for (size_t q = 0; q < boundaries.conditions.size(); ++q) {
    const std::string at = absl::StrCat(field, ".conditions[", q, "].range");
    const FaceRange& r = boundaries.conditions[q].range;
    if (absl::Status s = ValidateFace(r.face, blocks, at); !s.ok()) return s;
    const Extents& e = blocks[r.face.block];
    for (int d = 0; d < 3; ++d) {
      const bool on_face = d != r.face.normal ||
                           (r.begin[d] == r.end[d] && r.begin[d] == (r.face.upper ? e[d] - 1 : 0));
      if (r.begin[d] < 0 || r.end[d] < r.begin[d] || r.end[d] >= e[d] || !on_face) {
        return absl::InvalidArgumentError(
            absl::StrCat(at, ": ", std::string(1, kDirectionNames[d]), "[", r.begin[d], "..",
                         r.end[d], "] is not on ", FaceName(r.face), " inside block ", r.face.block,
                         " of ", e[0], " x ", e[1], " x ", e[2], " points"));
      }
    }
  }
  for (size_t q = 0; q < boundaries.face_kinds.size(); ++q) {
    if (absl::Status s = ValidateFace(boundaries.face_kinds[q].face, blocks,
                                      absl::StrCat(field, ".face_kinds[", q, "]"));
        !s.ok()) {
      return s;
    }
  }
  return absl::OkStatus();
}

}  // namespace splinegrid
