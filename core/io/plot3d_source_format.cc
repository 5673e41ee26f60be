#include "core/io/plot3d_source_format.h"

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid {

absl::StatusOr<Plot3dWriteBack> ToPlot3dSourceForm(MultiBlockGrid evaluated,
                                                   std::span<const int> block_indices,
                                                   const Plot3dSourceFormat& source,
                                                   Plot3dEncoding encoding) {
  if (block_indices.size() != evaluated.blocks.size()) {
    return absl::InvalidArgumentError(absl::StrCat("Plot3D write-back: ", block_indices.size(),
                                                   " block indices for ", evaluated.blocks.size(),
                                                   " blocks"));
  }
  Plot3dWriteBack out;
  out.format = source.file;
  const bool want_text = encoding == Plot3dEncoding::kAscii;
  const bool was_text = source.file.encoding == Plot3dEncoding::kAscii;
  if (want_text != was_text) {
    out.format.encoding = encoding;
    out.format.bytes_per_real = 8;
    out.format.framing = Plot3dFraming::kFortranRecords;
  }
  if (evaluated.blocks.size() != 1) out.format.has_block_count = true;
  const bool two_planes = !source.two_planes.empty();
  out.grid.blocks.reserve(evaluated.blocks.size());
  for (size_t i = 0; i < evaluated.blocks.size(); ++i) {
    StructuredBlock& block = evaluated.blocks[i];
    const int b = block_indices[i];
    if (two_planes) {
      if (b < 0 || b >= static_cast<int>(source.two_planes.size())) {
        return absl::InvalidArgumentError(absl::StrCat("Plot3D write-back: block ", b,
                                                       " is not a block of the source (",
                                                       source.two_planes.size(), " blocks)"));
      }
      absl::StatusOr<StructuredBlock> restored = TwoPlaneBlock(block, source.two_planes[b]);
      if (!restored.ok()) {
        return absl::InvalidArgumentError(
            absl::StrCat("Plot3D write-back of block ", b, ": ", restored.status().message()));
      }
      out.grid.blocks.push_back(*std::move(restored));
    } else {
      out.grid.blocks.push_back(std::move(block));
    }
    StructuredBlock& written = out.grid.blocks.back();
    if (written.spatial_dim() != source.file.spatial_dim) {
      return absl::InvalidArgumentError(
          absl::StrCat("Plot3D write-back of block ", b, ": it has ", written.spatial_dim(),
                       " coordinates per point, the source file ", source.file.spatial_dim));
    }
    if (source.file.has_iblank) {
      written.iblank().assign(static_cast<size_t>(written.num_points()), 1);
    } else {
      written.iblank().clear();
    }
  }
  return out;
}

}  // namespace splinegrid
