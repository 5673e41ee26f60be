// ReadCgnsFile: the first base of a CGNS file through the mid-level library (cgnslib.h).
#include <cgnslib.h>

#include <algorithm>
#include <map>
#include <set>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/io/planar_view.h"
#include "core/util/status_macros.h"
#include "io/cgns/cgns_file.h"
#include "io/cgns/cgns_io.h"

namespace splinegrid {
namespace {

// Point ranges of BCs and connections: CGNS gives 1-based [begin, end] per index direction,
// possibly with begin > end; this is the 0-based, ordered rectangle on the face it lies on.
// nullopt when the rectangle lies on no face or on several (an edge or a corner).
std::optional<FaceRange> RangeOnFace(int block, const Extents& extents, const Extents& begin1,
                                     const Extents& end1) {
  FaceRange r;
  r.face.block = block;
  int faces = 0;
  for (int d = 0; d < 3; ++d) {
    r.begin[d] = std::min(begin1[d], end1[d]) - 1;
    r.end[d] = std::max(begin1[d], end1[d]) - 1;
    if (r.begin[d] < 0 || r.end[d] >= extents[d]) return std::nullopt;
  }
  for (int d = 0; d < 3; ++d) {
    if (extents[d] < 2 || r.begin[d] != r.end[d]) continue;
    if (r.begin[d] != 0 && r.begin[d] != extents[d] - 1) continue;
    // Along the other active directions the range must extend (else it is an edge/corner).
    bool extends = true;
    for (int t = 0; t < 3; ++t) {
      if (t != d && extents[t] > 1 && r.end[t] == r.begin[t]) extends = false;
    }
    if (!extends) continue;
    ++faces;
    r.face.normal = d;
    r.face.upper = r.begin[d] == extents[d] - 1;
  }
  if (faces != 1) return std::nullopt;
  return r;
}

class Reader {
 public:
  explicit Reader(CgnsFile* file) : file_(*file) {}

  absl::StatusOr<ImportedGrid> Read() {
    int nbases = 0;
    SG_RETURN_IF_ERROR(file_.Check(cg_nbases(file_.fn(), &nbases), "counting bases"));
    if (nbases < 1) return absl::InvalidArgumentError("the CGNS file has no base (CGNSBase_t)");
    char base_name[33] = {};
    SG_RETURN_IF_ERROR(file_.Check(
        cg_base_read(file_.fn(), kBase, base_name, &cell_dim_, &phys_dim_), "reading base 1"));
    out_.boundaries.base_name = base_name;
    SG_RETURN_IF_ERROR(ReadBaseUnits());
    if (nbases > 1) {
      Note(absl::StrCat("the file has ", nbases, " bases; only the first ('", base_name,
                        "') is read"));
    }
    const bool dims_ok = (cell_dim_ == 2 && (phys_dim_ == 2 || phys_dim_ == 3)) ||
                         (cell_dim_ == 3 && phys_dim_ == 3);
    if (!dims_ok) {
      return absl::InvalidArgumentError(absl::StrCat(
          "base '", base_name, "': CellDimension = ", cell_dim_, ", PhysicalDimension = ",
          phys_dim_, "; splinegrid reads CellDimension 2 (PhysicalDimension 2 or 3) or 3 (3)"));
    }
    SG_RETURN_IF_ERROR(ReadFamilies());
    int nzones = 0;
    SG_RETURN_IF_ERROR(file_.Check(cg_nzones(file_.fn(), kBase, &nzones), "counting zones"));
    if (nzones < 1)
      return absl::InvalidArgumentError(absl::StrCat("base '", base_name, "' has no zone"));
    for (int z = 1; z <= nzones; ++z) SG_RETURN_IF_ERROR(ReadZone(z));
    NoteTwoPlaneZones();
    for (int z = 1; z <= nzones; ++z) {
      SG_RETURN_IF_ERROR(ReadConditions(z));
      SG_RETURN_IF_ERROR(ReadConnections(z));
    }
    out_.boundaries.face_kinds = FaceKindsOf(out_.boundaries.conditions,
                                             out_.boundaries.block_names, &out_.boundaries.notes);
    int file_type = 0;
    cg_get_file_type(file_.fn(), &file_type);
    const char* precision = singles_ == 0 ? "double" : doubles_ == 0 ? "single" : "mixed precision";
    out_.format = absl::StrCat("cgns ", file_type == CG_FILE_ADF ? "adf" : "hdf5", ", ",
                               cell_dim_ == 3   ? "3d"
                               : phys_dim_ == 3 ? "surface"
                                                : "2d",
                               ", ", nzones, nzones == 1 ? " zone, " : " zones, ", precision);
    return std::move(out_);
  }

 private:
  static constexpr int kBase = 1;

  void Note(std::string note) { out_.boundaries.notes.push_back(std::move(note)); }

  std::string ZoneName(int z) const { return out_.boundaries.block_names[z - 1]; }

  // The base's DataClass and DimensionalUnits, kept so that a written evaluation states what
  // the file did (the coordinates are not converted); absent ones stay empty.
  absl::Status ReadBaseUnits() {
    SG_RETURN_IF_ERROR(file_.Check(cg_goto(file_.fn(), kBase, "end"), "opening base 1"));
    CGNS_ENUMT(DataClass_t) data_class;
    if (const int status = cg_dataclass_read(&data_class); status != CG_NODE_NOT_FOUND) {
      SG_RETURN_IF_ERROR(file_.Check(status, "reading the base's DataClass"));
      out_.boundaries.data_class = cg_DataClassName(data_class);
    }
    CGNS_ENUMT(MassUnits_t) mass;
    CGNS_ENUMT(LengthUnits_t) length;
    CGNS_ENUMT(TimeUnits_t) time;
    CGNS_ENUMT(TemperatureUnits_t) temperature;
    CGNS_ENUMT(AngleUnits_t) angle;
    if (const int status = cg_units_read(&mass, &length, &time, &temperature, &angle);
        status != CG_NODE_NOT_FOUND) {
      SG_RETURN_IF_ERROR(file_.Check(status, "reading the base's DimensionalUnits"));
      out_.boundaries.units = {cg_MassUnitsName(mass), cg_LengthUnitsName(length),
                               cg_TimeUnitsName(time), cg_TemperatureUnitsName(temperature),
                               cg_AngleUnitsName(angle)};
    }
    return absl::OkStatus();
  }

  // A 2D case stored as a 3D volume of two planes (as CFL3D writes them) is a volume to
  // splinegrid: the planar view (planar_view.h) is a Plot3D reading, whose write-back restores
  // the planes; a CGNS file's conditions and connections would need it too. Say so, and how to
  // get the 2D grid, rather than let a 2D case pass as a volume one unit thick.
  void NoteTwoPlaneZones() {
    if (cell_dim_ != 3) return;
    constexpr char kIndices[] = "ijk", kAxes[] = "xyz";
    for (size_t b = 0; b < out_.grid.blocks.size(); ++b) {
      const absl::StatusOr<TwoPlaneLayout> layout = DetectTwoPlaneBlock(out_.grid.blocks[b]);
      if (!layout.ok()) continue;
      Note(absl::StrCat(
          "zone '", out_.boundaries.block_names[b], "' is two planes (",
          std::string(1, kIndices[layout->plane_direction]), " = 1, 2) at ",
          std::string(1, kAxes[layout->normal_coordinate]), " = ", layout->plane_values[0], " and ",
          layout->plane_values[1],
          ", a 2D case stored as a 3D volume: it is read as a volume (fitted across the planes "
          "too, its reference length and evaluations 3D); for the 2D grid convert the file to "
          "Plot3D (cgns_to_plot3d), whose two-plane blocks are read as their 2D view"));
    }
  }

  absl::Status ReadFamilies() {
    int nfamilies = 0;
    SG_RETURN_IF_ERROR(
        file_.Check(cg_nfamilies(file_.fn(), kBase, &nfamilies), "counting families"));
    for (int f = 1; f <= nfamilies; ++f) {
      char name[33] = {};
      int nboco = 0, ngeos = 0;
      SG_RETURN_IF_ERROR(file_.Check(cg_family_read(file_.fn(), kBase, f, name, &nboco, &ngeos),
                                     absl::StrCat("reading family ", f)));
      if (nboco < 1) continue;
      char bc_name[33] = {};
      CGNS_ENUMT(BCType_t) type;
      SG_RETURN_IF_ERROR(file_.Check(cg_fambc_read(file_.fn(), kBase, f, 1, bc_name, &type),
                                     absl::StrCat("reading the FamilyBC of family '", name, "'")));
      family_types_[name] = cg_BCTypeName(type);
    }
    return absl::OkStatus();
  }

  absl::Status ReadZone(int z) {
    CGNS_ENUMT(ZoneType_t) type;
    SG_RETURN_IF_ERROR(file_.Check(cg_zone_type(file_.fn(), kBase, z, &type),
                                   absl::StrCat("reading the type of zone ", z)));
    char name[33] = {};
    cgsize_t size[9] = {};
    SG_RETURN_IF_ERROR(file_.Check(cg_zone_read(file_.fn(), kBase, z, name, size),
                                   absl::StrCat("reading zone ", z)));
    if (type != CGNS_ENUMV(Structured)) {
      return absl::InvalidArgumentError(absl::StrCat("zone ", z, " ('", name, "') is ",
                                                     cg_ZoneTypeName(type),
                                                     ": splinegrid reads structured zones only"));
    }
    Extents extents = {1, 1, 1};
    for (int d = 0; d < cell_dim_; ++d) extents[d] = static_cast<int>(size[d]);
    SG_RETURN_IF_ERROR(ValidateExtents(extents, absl::StrCat("zone ", z, " ('", name, "')")));
    out_.boundaries.block_names.push_back(name);
    int ngrids = 0;
    SG_RETURN_IF_ERROR(
        file_.Check(cg_ngrids(file_.fn(), kBase, z, &ngrids),
                    absl::StrCat("counting the coordinate nodes of zone '", name, "'")));
    if (ngrids < 1) {
      return absl::InvalidArgumentError(absl::StrCat("zone '", name, "' has no GridCoordinates"));
    }
    if (ngrids > 1) {
      Note(absl::StrCat("zone '", name, "' has ", ngrids,
                        " GridCoordinates_t nodes; the first (GridCoordinates) is read"));
    }
    if (cg_goto(file_.fn(), kBase, "Zone_t", z, "GridCoordinates_t", 1, "end") == CG_OK) {
      int rind[6] = {};
      if (cg_rind_read(rind) == CG_OK &&
          std::any_of(rind, rind + 2 * cell_dim_, [](int r) { return r != 0; })) {
        return absl::InvalidArgumentError(absl::StrCat(
            "zone '", name, "': its coordinates have rind planes; splinegrid reads grids without"));
      }
    }
    StructuredBlock block(extents, phys_dim_);
    static constexpr const char* kNames[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    int ncoords = 0;
    SG_RETURN_IF_ERROR(file_.Check(cg_ncoords(file_.fn(), kBase, z, &ncoords),
                                   absl::StrCat("counting the coordinates of zone '", name, "'")));
    std::map<std::string, CGNS_ENUMT(DataType_t)> present;
    for (int c = 1; c <= ncoords; ++c) {
      char coord_name[33] = {};
      CGNS_ENUMT(DataType_t) data_type;
      SG_RETURN_IF_ERROR(
          file_.Check(cg_coord_info(file_.fn(), kBase, z, c, &data_type, coord_name),
                      absl::StrCat("reading coordinate ", c, " of zone '", name, "'")));
      present[coord_name] = data_type;
    }
    const cgsize_t rmin[3] = {1, 1, 1};
    const cgsize_t rmax[3] = {extents[0], extents[1], extents[2]};
    std::vector<double> values(static_cast<size_t>(block.num_points()));
    for (int c = 0; c < phys_dim_; ++c) {
      const auto it = present.find(kNames[c]);
      if (it == present.end()) {
        return absl::InvalidArgumentError(
            absl::StrCat("zone '", name, "' has no ", kNames[c],
                         " (splinegrid reads Cartesian coordinates CoordinateX/Y/Z)"));
      }
      (it->second == CGNS_ENUMV(RealSingle) ? singles_ : doubles_) += 1;
      SG_RETURN_IF_ERROR(
          file_.Check(cg_coord_read(file_.fn(), kBase, z, kNames[c], CGNS_ENUMV(RealDouble), rmin,
                                    rmax, values.data()),
                      absl::StrCat("reading ", kNames[c], " of zone '", name, "'")));
      std::span<double> coords = block.coords();
      for (size_t p = 0; p < values.size(); ++p) coords[p * phys_dim_ + c] = values[p];
    }
    SG_RETURN_IF_ERROR(ValidateFinite(block, absl::StrCat("zone '", name, "'")));
    out_.grid.blocks.push_back(std::move(block));
    return absl::OkStatus();
  }

  // 1-based point range of `n` (= 2 cell_dim) values into begin/end triples.
  void SplitRange(const cgsize_t* pnts, Extents* begin, Extents* end) const {
    *begin = {1, 1, 1};
    *end = {1, 1, 1};
    for (int d = 0; d < cell_dim_; ++d) {
      (*begin)[d] = static_cast<int>(pnts[d]);
      (*end)[d] = static_cast<int>(pnts[cell_dim_ + d]);
    }
  }

  absl::Status ReadConditions(int z) {
    const std::string zone = ZoneName(z);
    const Extents& extents = out_.grid.blocks[z - 1].extents();
    int nbocos = 0;
    SG_RETURN_IF_ERROR(file_.Check(cg_nbocos(file_.fn(), kBase, z, &nbocos),
                                   absl::StrCat("counting the BCs of zone '", zone, "'")));
    for (int bc = 1; bc <= nbocos; ++bc) {
      char name[33] = {};
      CGNS_ENUMT(BCType_t) type;
      CGNS_ENUMT(PointSetType_t) set_type;
      cgsize_t npnts = 0, normal_size = 0;
      int normal_index[3] = {};
      CGNS_ENUMT(DataType_t) normal_type;
      int ndataset = 0;
      SG_RETURN_IF_ERROR(
          file_.Check(cg_boco_info(file_.fn(), kBase, z, bc, name, &type, &set_type, &npnts,
                                   normal_index, &normal_size, &normal_type, &ndataset),
                      absl::StrCat("reading BC ", bc, " of zone '", zone, "'")));
      const std::string what = absl::StrCat("BC '", name, "' of zone '", zone, "'");
      if (set_type != CGNS_ENUMV(PointRange) || npnts != 2) {
        Note(absl::StrCat(what, " is a ", cg_PointSetTypeName(set_type),
                          "; only point ranges are read: it is not kept, and its points keep the "
                          "detected kind"));
        continue;
      }
      CGNS_ENUMT(GridLocation_t) location = CGNS_ENUMV(Vertex);
      SG_RETURN_IF_ERROR(file_.Check(cg_boco_gridlocation_read(file_.fn(), kBase, z, bc, &location),
                                     absl::StrCat("reading the location of ", what)));
      cgsize_t pnts[6] = {};
      SG_RETURN_IF_ERROR(file_.Check(cg_boco_read(file_.fn(), kBase, z, bc, pnts, nullptr),
                                     absl::StrCat("reading the range of ", what)));
      Extents begin, end;
      SplitRange(pnts, &begin, &end);
      if (!ToVertexRange(location, extents, &begin, &end)) {
        Note(absl::StrCat(what, " is located at ", cg_GridLocationName(location),
                          "; only vertex and face-centre ranges are read, its points keep the "
                          "detected kind"));
        continue;
      }
      const std::optional<FaceRange> range = RangeOnFace(z - 1, extents, begin, end);
      if (!range) {
        // In the file's own (1-based) indices, over the zone's index dimensions.
        std::vector<std::string> parts, sizes;
        bool outside = false;
        for (int d = 0; d < cell_dim_; ++d) {
          parts.push_back(absl::StrCat(begin[d], ":", end[d]));
          sizes.push_back(absl::StrCat(extents[d]));
          outside =
              outside || std::min(begin[d], end[d]) < 1 || std::max(begin[d], end[d]) > extents[d];
        }
        Note(absl::StrCat(what, " (", absl::StrJoin(parts, ", "), ", 1-based) ",
                          outside ? absl::StrCat("lies outside the zone's ",
                                                 absl::StrJoin(sizes, " x "), " points")
                                  : "does not cover a rectangle of one face",
                          "; it is not kept"));
        continue;
      }
      SourceBoundary condition;
      condition.range = *range;
      condition.name = name;
      condition.bc_type = cg_BCTypeName(type);
      if (type == CGNS_ENUMV(FamilySpecified)) {
        char family[33] = {};
        if (cg_goto(file_.fn(), kBase, "Zone_t", z, "ZoneBC_t", 1, "BC_t", bc, "end") != CG_OK ||
            cg_famname_read(family) != CG_OK) {
          Note(absl::StrCat(what, " is FamilySpecified but names no family; it is not read"));
          continue;
        }
        const auto it = family_types_.find(family);
        if (it == family_types_.end()) {
          Note(absl::StrCat(what, " names family '", family,
                            "', which has no FamilyBC in the base; it is not read"));
          continue;
        }
        condition.family = family;
        condition.bc_type = it->second;
      }
      const std::optional<BoundaryKind> kind = KindOfBcType(condition.bc_type);
      condition.kind = kind;
      if (!kind) {
        Note(absl::StrCat(what, " has type ", condition.bc_type,
                          ", which says nothing about the kind; it is kept (and written with the "
                          "grid), and its points keep the detected kind"));
      }
      if (kind == BoundaryKind::kInterface && !symmetry_noted_) {
        symmetry_noted_ = true;
        Note(absl::StrCat(what, " is ", condition.bc_type,
                          ": symmetry conditions are fitted to the interface tolerance (a "
                          "symmetry plane is the interface with the grid's mirror image)"));
      }
      out_.boundaries.conditions.push_back(std::move(condition));
    }
    return absl::OkStatus();
  }

  // A face-centre range (face indices) as the vertex range of the same faces; false for other
  // locations. SIDS 4.4: face index f of direction d lies between cells f-1 and f, on vertex f.
  bool ToVertexRange(CGNS_ENUMT(GridLocation_t) location, const Extents& extents, Extents* begin,
                     Extents* end) const {
    int normal = -1;
    switch (location) {
      case CGNS_ENUMV(Vertex):
        return true;
      case CGNS_ENUMV(IFaceCenter):
        normal = 0;
        break;
      case CGNS_ENUMV(JFaceCenter):
        normal = 1;
        break;
      case CGNS_ENUMV(KFaceCenter):
        normal = 2;
        break;
      case CGNS_ENUMV(FaceCenter):
        // The direction whose face index is constant at a boundary (last vertex first: a cell
        // index never reaches it).
        for (int pass = 0; pass < 2 && normal < 0; ++pass) {
          for (int d = 0; d < cell_dim_ && normal < 0; ++d) {
            const int at = pass == 0 ? extents[d] : 1;
            if ((*begin)[d] == (*end)[d] && (*begin)[d] == at) normal = d;
          }
        }
        if (normal < 0) return false;
        break;
      default:
        return false;
    }
    if (normal >= cell_dim_) return false;
    for (int d = 0; d < cell_dim_; ++d) {
      if (d == normal) continue;
      int& hi = (*begin)[d] > (*end)[d] ? (*begin)[d] : (*end)[d];
      hi += 1;  // the last cell's far vertex
    }
    return true;
  }

  absl::Status ReadConnections(int z) {
    const std::string zone = ZoneName(z);
    int nconns = 0, nholes = 0, n1to1 = 0;
    SG_RETURN_IF_ERROR(file_.Check(cg_nconns(file_.fn(), kBase, z, &nconns),
                                   absl::StrCat("counting the connectivity of zone '", zone, "'")));
    SG_RETURN_IF_ERROR(file_.Check(cg_nholes(file_.fn(), kBase, z, &nholes),
                                   absl::StrCat("counting the holes of zone '", zone, "'")));
    if (nconns + nholes > 0) {
      Note(absl::StrCat("zone '", zone, "' has ", nconns,
                        " general connectivity nodes (abutting, overset or point lists) and ",
                        nholes,
                        " overset holes; they are not read (splinegrid finds coinciding "
                        "points itself)"));
    }
    SG_RETURN_IF_ERROR(
        file_.Check(cg_n1to1(file_.fn(), kBase, z, &n1to1),
                    absl::StrCat("counting the 1-to-1 connections of zone '", zone, "'")));
    for (int c = 1; c <= n1to1; ++c) {
      char name[33] = {}, donor_name[33] = {};
      cgsize_t range[6] = {}, donor_range[6] = {};
      int transform[3] = {1, 2, 3};
      SG_RETURN_IF_ERROR(file_.Check(
          cg_1to1_read(file_.fn(), kBase, z, c, name, donor_name, range, donor_range, transform),
          absl::StrCat("reading 1-to-1 connection ", c, " of zone '", zone, "'")));
      const auto& names = out_.boundaries.block_names;
      const auto donor = std::find(names.begin(), names.end(), std::string(donor_name));
      const std::string what = absl::StrCat("1-to-1 connection '", name, "' of zone '", zone, "'");
      if (donor == names.end()) {
        Note(absl::StrCat(what, " names donor zone '", donor_name, "', which is not in the base"));
        continue;
      }
      const int d = static_cast<int>(donor - names.begin());
      Extents b0, e0, b1, e1;
      SplitRange(range, &b0, &e0);
      SplitRange(donor_range, &b1, &e1);
      const std::optional<FaceRange> own =
          RangeOnFace(z - 1, out_.grid.blocks[z - 1].extents(), b0, e0);
      const std::optional<FaceRange> other = RangeOnFace(d, out_.grid.blocks[d].extents(), b1, e1);
      if (!own || !other) {
        Note(absl::StrCat(what, " does not join two face rectangles; it is not compared"));
        continue;
      }
      StatedConnection connection{name, *own, *other, {transform[0], transform[1], 3}};
      if (cell_dim_ == 3) connection.transform[2] = transform[2];
      out_.connections.push_back(std::move(connection));
    }
    return absl::OkStatus();
  }

  CgnsFile& file_;
  ImportedGrid out_;
  int cell_dim_ = 0;
  int phys_dim_ = 0;
  int singles_ = 0;
  int doubles_ = 0;
  bool symmetry_noted_ = false;
  std::map<std::string, std::string> family_types_;  // family name -> FamilyBC type name
};

}  // namespace

absl::StatusOr<ImportedGrid> ReadCgnsFile(const std::string& path) {
  SG_ASSIGN_OR_RETURN(CgnsFile file, CgnsFile::Open(path, CG_MODE_READ));
  Reader reader(&file);
  absl::StatusOr<ImportedGrid> grid = reader.Read();
  SG_RETURN_IF_ERROR(file.Close());
  return grid;
}

}  // namespace splinegrid
