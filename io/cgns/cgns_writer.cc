// WriteCgnsFile: one base, a structured zone per block, BCs with families, 1-to-1 connections.
#include <cgnslib.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "absl/strings/str_cat.h"
#include "core/io/file_util.h"
#include "core/util/status_macros.h"
#include "io/cgns/cgns_file.h"
#include "io/cgns/cgns_io.h"

namespace splinegrid {
namespace {

// BCType_t of a type name (cg_BCTypeName is its inverse); BCTypeUserDefined when unknown.
CGNS_ENUMT(BCType_t) BcTypeOf(const std::string& name) {
  for (int t = 0; t < NofValidBCTypes; ++t) {
    const auto type = static_cast<CGNS_ENUMT(BCType_t)>(t);
    if (name == cg_BCTypeName(type)) return type;
  }
  return CGNS_ENUMV(BCTypeUserDefined);
}

// The CGNS transform of a match (SIDS 8.2): transform[d] = +-(b's direction + 1) for each
// direction d of a. Tangential directions come from the match; the normals pair up with the
// sign that keeps "into a" = "out of b" (+ when one face is a min face and the other a max
// face); directions unused by both (extent 1) pair up with each other.
std::array<int, 3> TransformOf(const BoundaryMatch& m) {
  std::array<int, 3> t = {0, 0, 0};
  std::array<bool, 3> used_b = {false, false, false};
  for (int d = 0; d < 3; ++d) {
    if (m.b_direction[d] >= 0) {
      t[d] = (m.reversed[d] ? -1 : 1) * (m.b_direction[d] + 1);
      used_b[m.b_direction[d]] = true;
    }
  }
  const int na = m.a.face.normal, nb = m.b.face.normal;
  t[na] = (m.a.face.upper != m.b.face.upper ? 1 : -1) * (nb + 1);
  used_b[nb] = true;
  for (int d = 0; d < 3; ++d) {
    if (t[d] != 0) continue;
    for (int e = 0; e < 3; ++e) {
      if (!used_b[e]) {
        t[d] = e + 1;
        used_b[e] = true;
        break;
      }
    }
  }
  return t;
}

// The point of the other side that `x` maps to, given one pair of coinciding points.
Extents MapThrough(const std::array<int, 3>& t, const Extents& from0, const Extents& to0,
                   const Extents& x) {
  Extents y = to0;
  for (int d = 0; d < 3; ++d) {
    const int e = std::abs(t[d]) - 1;
    y[e] = to0[e] + (t[d] > 0 ? 1 : -1) * (x[d] - from0[d]);
  }
  return y;
}

std::array<int, 3> Inverse(const std::array<int, 3>& t) {
  std::array<int, 3> inv = {1, 2, 3};
  for (int d = 0; d < 3; ++d) inv[std::abs(t[d]) - 1] = (t[d] > 0 ? 1 : -1) * (d + 1);
  return inv;
}

class Writer {
 public:
  Writer(CgnsFile* file, const MultiBlockGrid& grid, const CgnsWriteOptions& options,
         std::vector<std::string>* notes)
      : file_(*file), grid_(grid), options_(options), notes_(notes) {}

  absl::Status Write() {
    phys_dim_ = grid_.blocks.front().spatial_dim();
    cell_dim_ = 2;
    for (const StructuredBlock& b : grid_.blocks) {
      if (b.extent(2) > 1) cell_dim_ = 3;
    }
    if (cell_dim_ > phys_dim_) {
      return absl::InvalidArgumentError(
          "a planar grid (2 coordinates) with k > 1 has no CGNS form");
    }
    const std::string base_name = options_.base_name.empty() ? "Base" : options_.base_name;
    SG_RETURN_IF_ERROR(
        file_.Check(cg_base_write(file_.fn(), base_name.c_str(), cell_dim_, phys_dim_, &base_),
                    "writing the base"));
    SG_RETURN_IF_ERROR(WriteBaseUnits());
    for (size_t w = 0; w < grid_.blocks.size(); ++w) {
      const int source =
          options_.source_blocks.empty() ? static_cast<int>(w) : options_.source_blocks[w];
      zone_of_source_[source] = static_cast<int>(w) + 1;
      SG_RETURN_IF_ERROR(WriteZone(grid_.blocks[w], ZoneName(source)));
    }
    if (options_.source_extents.empty()) return absl::OkStatus();
    SG_RETURN_IF_ERROR(CheckExtents());
    SG_RETURN_IF_ERROR(WriteFamilies());
    for (const SourceBoundary& c : options_.conditions) SG_RETURN_IF_ERROR(WriteCondition(c));
    for (size_t q = 0; q < options_.matches.size(); ++q) SG_RETURN_IF_ERROR(WriteMatch(q));
    return absl::OkStatus();
  }

 private:
  // The enumerator of T named `name` among the first `count` (cg_*Name), or INVALID_ARGUMENT.
  template <typename T>
  static absl::StatusOr<T> Enumerator(const std::string& name, int count, const char* (*name_of)(T),
                                      const char* what) {
    for (int e = 0; e < count; ++e) {
      if (name == name_of(static_cast<T>(e))) return static_cast<T>(e);
    }
    return absl::InvalidArgumentError(
        absl::StrCat("the source's ", what, " '", name, "' is not a CGNS name"));
  }

  // The source's DataClass and DimensionalUnits on the base (CgnsWriteOptions), or
  // NormalizedByUnknownDimensional when it stated none.
  absl::Status WriteBaseUnits() {
    SG_RETURN_IF_ERROR(file_.Check(cg_goto(file_.fn(), base_, "end"), "opening the base"));
    SG_ASSIGN_OR_RETURN(
        const CGNS_ENUMT(DataClass_t) data_class,
        Enumerator<CGNS_ENUMT(DataClass_t)>(
            options_.data_class.empty() ? "NormalizedByUnknownDimensional" : options_.data_class,
            NofValidDataClass, cg_DataClassName, "DataClass"));
    SG_RETURN_IF_ERROR(file_.Check(cg_dataclass_write(data_class), "writing the DataClass"));
    if (options_.units.empty()) return absl::OkStatus();
    if (options_.units.size() != 5) {
      return absl::InvalidArgumentError(absl::StrCat("the source's DimensionalUnits have ",
                                                     options_.units.size(), " entries, not five"));
    }
    SG_ASSIGN_OR_RETURN(const auto mass,
                        Enumerator<CGNS_ENUMT(MassUnits_t)>(options_.units[0], NofValidMassUnits,
                                                            cg_MassUnitsName, "mass unit"));
    SG_ASSIGN_OR_RETURN(const auto length, Enumerator<CGNS_ENUMT(LengthUnits_t)>(
                                               options_.units[1], NofValidLengthUnits,
                                               cg_LengthUnitsName, "length unit"));
    SG_ASSIGN_OR_RETURN(const auto time,
                        Enumerator<CGNS_ENUMT(TimeUnits_t)>(options_.units[2], NofValidTimeUnits,
                                                            cg_TimeUnitsName, "time unit"));
    SG_ASSIGN_OR_RETURN(const auto temperature, Enumerator<CGNS_ENUMT(TemperatureUnits_t)>(
                                                    options_.units[3], NofValidTemperatureUnits,
                                                    cg_TemperatureUnitsName, "temperature unit"));
    SG_ASSIGN_OR_RETURN(const auto angle,
                        Enumerator<CGNS_ENUMT(AngleUnits_t)>(options_.units[4], NofValidAngleUnits,
                                                             cg_AngleUnitsName, "angle unit"));
    return file_.Check(cg_units_write(mass, length, time, temperature, angle),
                       "writing the DimensionalUnits");
  }

  std::string ZoneName(int source) const {
    if (source < static_cast<int>(options_.block_names.size()) &&
        !options_.block_names[source].empty()) {
      return options_.block_names[source];
    }
    // Zero-padded to the widest index: libcgns lists a file's zones by name, so "block_10"
    // would come back before "block_2".
    const std::string index = absl::StrCat(source);
    const size_t width = absl::StrCat(SourceBlockCount() - 1).size();
    return absl::StrCat("block_", std::string(width > index.size() ? width - index.size() : 0, '0'),
                        index);
  }

  // How many blocks the source grid has, as far as the options tell (at least the written ones).
  int SourceBlockCount() const {
    size_t count = std::max(
        {grid_.blocks.size(), options_.source_extents.size(), options_.block_names.size()});
    for (const int source : options_.source_blocks)
      count = std::max(count, static_cast<size_t>(source) + 1);
    return static_cast<int>(std::max<size_t>(count, 1));
  }

  absl::Status WriteZone(const StructuredBlock& block, const std::string& name) {
    cgsize_t size[9] = {};
    for (int d = 0; d < cell_dim_; ++d) {
      size[d] = block.extent(d);
      size[cell_dim_ + d] = std::max(block.extent(d) - 1, 0);
    }
    int zone = 0;
    SG_RETURN_IF_ERROR(file_.Check(
        cg_zone_write(file_.fn(), base_, name.c_str(), size, CGNS_ENUMV(Structured), &zone),
        absl::StrCat("writing zone '", name, "'")));
    static constexpr const char* kNames[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    const int64_t n = block.num_points();
    std::vector<double> values(n);
    std::vector<float> singles(options_.single_precision ? n : 0);
    for (int c = 0; c < phys_dim_; ++c) {
      for (int64_t p = 0; p < n; ++p) values[p] = block.coords()[p * phys_dim_ + c];
      int index = 0;
      int result;
      if (options_.single_precision) {
        std::copy(values.begin(), values.end(), singles.begin());
        result = cg_coord_write(file_.fn(), base_, zone, CGNS_ENUMV(RealSingle), kNames[c],
                                singles.data(), &index);
      } else {
        result = cg_coord_write(file_.fn(), base_, zone, CGNS_ENUMV(RealDouble), kNames[c],
                                values.data(), &index);
      }
      SG_RETURN_IF_ERROR(
          file_.Check(result, absl::StrCat("writing ", kNames[c], " of '", name, "'")));
      // A coordinate is a length: mass^0 length^1 time^0 temperature^0 angle^0 (SIDS 5.1.1;
      // cgnscheck asks for the exponents of data that are not dimensionless).
      const double exponents[5] = {0.0, 1.0, 0.0, 0.0, 0.0};
      SG_RETURN_IF_ERROR(file_.Check(
          cg_goto(file_.fn(), base_, "Zone_t", zone, "GridCoordinates_t", 1, "DataArray_t", index,
                  "end"),
          absl::StrCat("opening ", kNames[c], " of '", name, "'")));
      SG_RETURN_IF_ERROR(
          file_.Check(cg_exponents_write(CGNS_ENUMV(RealDouble), exponents),
                      absl::StrCat("writing the DimensionalExponents of ", kNames[c])));
    }
    return absl::OkStatus();
  }

  absl::Status CheckExtents() const {
    for (const auto& [source, zone] : zone_of_source_) {
      if (source < 0 || source >= static_cast<int>(options_.source_extents.size())) {
        return absl::InvalidArgumentError(absl::StrCat("written block ", zone - 1,
                                                       " is source block ", source,
                                                       ", which the grid does not have"));
      }
      const Extents& s = options_.source_extents[source];
      const Extents& e = grid_.blocks[zone - 1].extents();
      for (int d = 0; d < 3; ++d) {
        if (static_cast<int64_t>(s[d] - 1) * options_.index_scale + 1 != e[d]) {
          return absl::InvalidArgumentError(
              absl::StrCat("block ", source, " has ", e[d], " points in direction ", d,
                           ", not the (", s[d], " - 1) * ", options_.index_scale,
                           " + 1 of a refinement level: boundary conditions "
                           "and connectivity need an evaluation at a level of whole blocks"));
        }
      }
    }
    return absl::OkStatus();
  }

  absl::Status WriteFamilies() {
    std::map<std::string, std::string> families;
    for (const SourceBoundary& c : options_.conditions) {
      if (!c.family.empty()) families.emplace(c.family, c.bc_type);
    }
    for (const auto& [family, type] : families) {
      int f = 0, bc = 0;
      SG_RETURN_IF_ERROR(file_.Check(cg_family_write(file_.fn(), base_, family.c_str(), &f),
                                     absl::StrCat("writing family '", family, "'")));
      SG_RETURN_IF_ERROR(
          file_.Check(cg_fambc_write(file_.fn(), base_, f, "FamBC", BcTypeOf(type), &bc),
                      absl::StrCat("writing the FamilyBC of '", family, "'")));
    }
    return absl::OkStatus();
  }

  // 1-based scaled PointRange values of a range: begin of each index direction, then end.
  void ScaledRange(const Extents& begin, const Extents& end, cgsize_t* pnts) const {
    for (int d = 0; d < cell_dim_; ++d) {
      pnts[d] = static_cast<cgsize_t>(begin[d]) * options_.index_scale + 1;
      pnts[cell_dim_ + d] = static_cast<cgsize_t>(end[d]) * options_.index_scale + 1;
    }
  }

  absl::Status WriteCondition(const SourceBoundary& c) {
    const auto zone = zone_of_source_.find(c.range.face.block);
    if (zone == zone_of_source_.end()) return absl::OkStatus();  // block not written
    cgsize_t pnts[6] = {};
    ScaledRange(c.range.begin, c.range.end, pnts);
    const bool family = !c.family.empty();
    int bc = 0;
    SG_RETURN_IF_ERROR(
        file_.Check(cg_boco_write(file_.fn(), base_, zone->second, c.name.c_str(),
                                  family ? CGNS_ENUMV(FamilySpecified) : BcTypeOf(c.bc_type),
                                  CGNS_ENUMV(PointRange), 2, pnts, &bc),
                    absl::StrCat("writing BC '", c.name, "'")));
    if (family) {
      SG_RETURN_IF_ERROR(file_.Check(
          cg_goto(file_.fn(), base_, "Zone_t", zone->second, "ZoneBC_t", 1, "BC_t", bc, "end"),
          absl::StrCat("going to BC '", c.name, "'")));
      SG_RETURN_IF_ERROR(file_.Check(cg_famname_write(c.family.c_str()),
                                     absl::StrCat("writing the family of BC '", c.name, "'")));
    }
    return absl::OkStatus();
  }

  absl::Status WriteMatch(size_t q) {
    const BoundaryMatch& m = options_.matches[q];
    const auto za = zone_of_source_.find(m.a.face.block);
    const auto zb = zone_of_source_.find(m.b.face.block);
    if (za == zone_of_source_.end() || zb == zone_of_source_.end()) return absl::OkStatus();
    if (m.step != 1) {
      if (notes_ != nullptr) {
        notes_->push_back(absl::StrCat("match ", m.Describe(),
                                       " has hanging nodes, which a CGNS 1-to-1 connection cannot "
                                       "hold; it is not written"));
      }
      return absl::OkStatus();
    }
    const std::array<int, 3> t = TransformOf(m);
    const Extents b0 = m.MapToB(m.a.begin), b1 = m.MapToB(m.a.end);
    int transform[3] = {t[0], t[1], t[2]};
    cgsize_t range[6] = {}, donor[6] = {};
    ScaledRange(m.a.begin, m.a.end, range);
    ScaledRange(b0, b1, donor);
    const std::string name_a = absl::StrCat("match", q, "a"),
                      name_b = absl::StrCat("match", q, "b");
    int index = 0;
    SG_RETURN_IF_ERROR(file_.Check(
        cg_1to1_write(file_.fn(), base_, za->second, name_a.c_str(),
                      ZoneName(m.b.face.block).c_str(), range, donor, transform, &index),
        absl::StrCat("writing 1-to-1 connection '", name_a, "'")));
    // The other side, its own range ascending: the inverse transform maps it back onto a.
    const std::array<int, 3> inv = Inverse(t);
    Extents lo = b0, hi = b1;
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(b0[d], b1[d]);
      hi[d] = std::max(b0[d], b1[d]);
    }
    const Extents a_lo = MapThrough(inv, b0, m.a.begin, lo),
                  a_hi = MapThrough(inv, b0, m.a.begin, hi);
    int inverse[3] = {inv[0], inv[1], inv[2]};
    ScaledRange(lo, hi, range);
    ScaledRange(a_lo, a_hi, donor);
    return file_.Check(
        cg_1to1_write(file_.fn(), base_, zb->second, name_b.c_str(),
                      ZoneName(m.a.face.block).c_str(), range, donor, inverse, &index),
        absl::StrCat("writing 1-to-1 connection '", name_b, "'"));
  }

  CgnsFile& file_;
  const MultiBlockGrid& grid_;
  const CgnsWriteOptions& options_;
  std::vector<std::string>* notes_;
  int base_ = 0;
  int cell_dim_ = 2;
  int phys_dim_ = 3;
  std::map<int, int> zone_of_source_;  // source block -> 1-based zone
};

// Creates (O_EXCL, mode 0666 less the umask) an unused name "PATH.tmp-PID-N" in the directory
// of `path` for the file to be written and renamed; the caller removes it on failure.
absl::StatusOr<std::string> ClaimTempPath(const std::string& path) {
  static std::atomic<int> counter{0};
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string temp = absl::StrCat(path, ".tmp-", getpid(), "-", counter.fetch_add(1));
    const int fd = open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      close(fd);
      return temp;
    }
    if (errno != EEXIST) {
      return ErrnoToStatusWithMessage(
          errno, absl::StrCat("creating ", temp, " (written, then renamed to ", path, ")"));
    }
  }
  return absl::AlreadyExistsError(absl::StrCat("no free temporary name beside ", path));
}

}  // namespace

absl::Status WriteCgnsFile(const std::string& path, const MultiBlockGrid& grid,
                           const CgnsWriteOptions& options, std::vector<std::string>* notes) {
  if (grid.blocks.empty()) return absl::InvalidArgumentError("the grid has no blocks");
  if (!options.source_blocks.empty() && options.source_blocks.size() != grid.blocks.size()) {
    return absl::InvalidArgumentError("CgnsWriteOptions.source_blocks: one entry per block");
  }
  if (options.index_scale < 1) return absl::InvalidArgumentError("index_scale must be >= 1");
  if (cg_set_file_type(CG_FILE_HDF5) != CG_OK) {
    return absl::InternalError(absl::StrCat("cg_set_file_type: ", cg_get_error()));
  }
  // Written to a fresh file beside `path` and renamed over it only once cg_close succeeded, so
  // that a failed write leaves an existing file as it was (rename within a directory is atomic).
  // A symbolic link is followed (the file it names is replaced, beside itself), and an existing
  // file keeps its permission bits. (A file with several hard links is replaced by a new one.)
  std::string target = path;
  std::error_code link_error;
  if (std::filesystem::is_symlink(path, link_error)) {
    const std::filesystem::path resolved = std::filesystem::weakly_canonical(path, link_error);
    if (!link_error) target = resolved.string();
  }
  struct stat existing;
  const bool exists = stat(target.c_str(), &existing) == 0;
  SG_ASSIGN_OR_RETURN(const std::string temp, ClaimTempPath(target));
  absl::Status status;
  {
    absl::StatusOr<CgnsFile> file = CgnsFile::Open(temp, CG_MODE_WRITE);
    if (!file.ok()) {
      unlink(temp.c_str());
      return file.status();
    }
    Writer writer(&*file, grid, options, notes);
    status = writer.Write();
    if (absl::Status closed = file->Close(); status.ok()) status = closed;
  }
  if (status.ok() && exists && chmod(temp.c_str(), existing.st_mode & 07777) != 0) {
    status = ErrnoToStatusWithMessage(errno, absl::StrCat("keeping the mode of ", target));
  }
  if (status.ok() && rename(temp.c_str(), target.c_str()) != 0) {
    status = ErrnoToStatusWithMessage(errno, absl::StrCat("renaming ", temp, " to ", target));
  }
  if (!status.ok()) unlink(temp.c_str());  // no partial file left behind
  return status;
}

}  // namespace splinegrid
