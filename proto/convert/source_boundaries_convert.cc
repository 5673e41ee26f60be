#include "proto/convert/source_boundaries_convert.h"

#include <algorithm>
#include <cstdlib>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"

namespace splinegrid {
namespace {

// Names from files are short (CGNS: 32 characters); a longer one is not a CGNS name.
constexpr size_t kMaxName = 256;

absl::Status CheckName(const std::string& name, const std::string& field) {
  if (name.size() > kMaxName) {
    return absl::InvalidArgumentError(absl::StrCat(field, " is longer than ", kMaxName, " bytes"));
  }
  return absl::OkStatus();
}

}  // namespace

void EncodeSourceBoundaries(const SourceBoundaries& boundaries, v1::SourceBoundaries* out) {
  for (const std::string& name : boundaries.block_names) out->add_block_names(name);
  for (const SourceBoundary& c : boundaries.conditions) {
    v1::SourceBoundary* entry = out->add_conditions();
    EncodeFaceRange(c.range, entry->mutable_range());
    // UNSPECIFIED: a condition whose type says nothing about the kind (SourceBoundary::kind).
    if (c.kind) entry->set_kind(EncodeBoundaryKind(*c.kind));
    entry->set_name(c.name);
    entry->set_bc_type(c.bc_type);
    entry->set_family(c.family);
  }
  for (const FaceKindOverride& k : boundaries.face_kinds) {
    v1::FaceKind* entry = out->add_face_kinds();
    entry->set_block(k.face.block);
    entry->set_face(EncodeBlockFace(k.face.normal, k.face.upper));
    entry->set_kind(EncodeBoundaryKind(k.kind));
  }
  for (const std::string& note : boundaries.notes) out->add_notes(note);
  out->set_base_name(boundaries.base_name);
  out->set_data_class(boundaries.data_class);
  for (const std::string& unit : boundaries.units) out->add_dimensional_units(unit);
}

absl::StatusOr<SourceBoundaries> ParseSourceBoundaries(const v1::SourceBoundaries& in,
                                                       const std::vector<Extents>& blocks,
                                                       const std::string& field) {
  SourceBoundaries out;
  for (int q = 0; q < in.block_names_size(); ++q) {
    SG_RETURN_IF_ERROR(CheckName(in.block_names(q), absl::StrCat(field, ".block_names[", q, "]")));
    out.block_names.push_back(in.block_names(q));
  }
  SG_RETURN_IF_ERROR(CheckName(in.base_name(), field + ".base_name"));
  if (in.base_name().size() > 32) {  // a CGNS name: the writer could not write it back
    return absl::InvalidArgumentError(absl::StrCat(field, ".base_name is ", in.base_name().size(),
                                                   " bytes; a CGNS name has at most 32"));
  }
  SG_RETURN_IF_ERROR(CheckName(in.data_class(), field + ".data_class"));
  out.base_name = in.base_name();
  out.data_class = in.data_class();
  if (in.dimensional_units_size() != 0 && in.dimensional_units_size() != 5) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".dimensional_units has ", in.dimensional_units_size(),
                     " entries; give none or five (mass, length, time, temperature, angle)"));
  }
  for (int q = 0; q < in.dimensional_units_size(); ++q) {
    SG_RETURN_IF_ERROR(
        CheckName(in.dimensional_units(q), absl::StrCat(field, ".dimensional_units[", q, "]")));
    out.units.push_back(in.dimensional_units(q));
  }
  for (int q = 0; q < in.conditions_size(); ++q) {
    const v1::SourceBoundary& entry = in.conditions(q);
    const std::string at = absl::StrCat(field, ".conditions[", q, "]");
    SourceBoundary c;
    SG_ASSIGN_OR_RETURN(c.range, ParseFaceRange(entry.range(), at + ".range"));
    if (entry.kind() == v1::BOUNDARY_KIND_UNSPECIFIED) {
      c.kind = std::nullopt;
    } else {
      const std::optional<BoundaryKind> kind = ParseBoundaryKind(entry.kind());
      if (!kind) {
        return absl::InvalidArgumentError(
            absl::StrCat(at, ".kind = ", static_cast<int>(entry.kind()),
                         " is not UNSPECIFIED (a condition that sets no kind), WALL, INTERFACE or "
                         "OUTER"));
      }
      c.kind = *kind;
    }
    SG_RETURN_IF_ERROR(CheckName(entry.name(), at + ".name"));
    SG_RETURN_IF_ERROR(CheckName(entry.bc_type(), at + ".bc_type"));
    SG_RETURN_IF_ERROR(CheckName(entry.family(), at + ".family"));
    c.name = entry.name();
    c.bc_type = entry.bc_type();
    c.family = entry.family();
    out.conditions.push_back(std::move(c));
  }
  for (int q = 0; q < in.face_kinds_size(); ++q) {
    const v1::FaceKind& entry = in.face_kinds(q);
    const std::string at = absl::StrCat(field, ".face_kinds[", q, "]");
    SG_ASSIGN_OR_RETURN(const Face face, ParseBlockFace(entry.block(), entry.face(), at));
    const std::optional<BoundaryKind> kind = ParseBoundaryKind(entry.kind());
    if (!kind) {
      return absl::InvalidArgumentError(absl::StrCat(at, ".kind = ", static_cast<int>(entry.kind()),
                                                     " is not WALL, INTERFACE or OUTER"));
    }
    out.face_kinds.push_back({face, *kind});
  }
  for (int q = 0; q < in.notes_size(); ++q) {
    if (in.notes(q).size() > 4096) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".notes[", q, "] is longer than 4096 bytes"));
    }
    out.notes.push_back(in.notes(q));
  }
  SG_RETURN_IF_ERROR(ValidateSourceBoundaries(out, blocks, field));
  return out;
}

void EncodeCgnsDecoded(const ImportedGrid& grid, v1::CgnsDecoded* out) {
  out->set_spatial_dim(grid.grid.blocks.empty() ? 0 : grid.grid.blocks.front().spatial_dim());
  out->set_format(grid.format);
  for (const StructuredBlock& block : grid.grid.blocks) {
    v1::CgnsZone* zone = out->add_zones();
    EncodeExtents(block.extents(), zone->mutable_extents());
    zone->mutable_coords()->Add(block.coords().begin(), block.coords().end());
  }
  EncodeSourceBoundaries(grid.boundaries, out->mutable_boundaries());
  for (const StatedConnection& c : grid.connections) {
    v1::CgnsConnection* entry = out->add_connections();
    entry->set_name(c.name);
    EncodeFaceRange(c.range, entry->mutable_range());
    EncodeFaceRange(c.donor, entry->mutable_donor());
    for (int t : c.transform) entry->add_transform(t);
  }
}

absl::StatusOr<ImportedGrid> ParseCgnsDecoded(const v1::CgnsDecoded& in) {
  ImportedGrid out;
  const int s = in.spatial_dim();
  if (s != 2 && s != 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("decoded.spatial_dim = ", s, "; must be 2 or 3"));
  }
  if (in.zones_size() == 0) return absl::InvalidArgumentError("the CGNS file has no zone");
  SG_RETURN_IF_ERROR(CheckName(in.format(), "decoded.format"));
  out.format = in.format();
  std::vector<Extents> extents;
  for (int z = 0; z < in.zones_size(); ++z) {
    const v1::CgnsZone& zone = in.zones(z);
    const std::string at = absl::StrCat("zone ", z);
    const Extents e = ParseExtents(zone.extents());
    SG_RETURN_IF_ERROR(ValidateExtents(e, at));
    if (static_cast<int64_t>(zone.coords_size()) != s * NumPoints(e)) {
      return absl::InvalidArgumentError(absl::StrCat(at, ": ", zone.coords_size(),
                                                     " coordinates for ", NumPoints(e),
                                                     " points of dimension ", s));
    }
    StructuredBlock block(e, s);
    std::copy(zone.coords().begin(), zone.coords().end(), block.coords().begin());
    SG_RETURN_IF_ERROR(ValidateFinite(block, at));
    out.grid.blocks.push_back(std::move(block));
    extents.push_back(e);
  }
  SG_ASSIGN_OR_RETURN(out.boundaries,
                      ParseSourceBoundaries(in.boundaries(), extents, "boundaries"));
  for (int q = 0; q < in.connections_size(); ++q) {
    const v1::CgnsConnection& entry = in.connections(q);
    const std::string at = absl::StrCat("connections[", q, "]");
    StatedConnection c;
    SG_RETURN_IF_ERROR(CheckName(entry.name(), at + ".name"));
    c.name = entry.name();
    SG_ASSIGN_OR_RETURN(c.range, ParseFaceRange(entry.range(), at + ".range"));
    SG_ASSIGN_OR_RETURN(c.donor, ParseFaceRange(entry.donor(), at + ".donor"));
    // Checked like boundary conditions: both ranges on faces inside their blocks.
    SourceBoundaries check;
    check.conditions.resize(2);
    check.conditions[0].range = c.range;
    check.conditions[1].range = c.donor;
    SG_RETURN_IF_ERROR(ValidateSourceBoundaries(check, extents, at));
    if (entry.transform_size() != 3) {
      return absl::InvalidArgumentError(
          absl::StrCat(at, ".transform: ", entry.transform_size(), " entries; must be 3"));
    }
    for (int d = 0; d < 3; ++d) {
      const int t = entry.transform(d);
      if (t == 0 || std::abs(t) > 3) {
        return absl::InvalidArgumentError(
            absl::StrCat(at, ".transform[", d, "] = ", t, "; must be +-1, +-2 or +-3"));
      }
      c.transform[d] = t;
    }
    out.connections.push_back(std::move(c));
  }
  return out;
}

}  // namespace splinegrid
