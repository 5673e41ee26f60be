#include "client/cli/output.h"

#include <unistd.h>

#include <cstdio>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "google/protobuf/util/json_util.h"

namespace splinegrid::cli {

std::string ToJson(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.preserve_proto_field_names = true;
  std::string json;
  (void)google::protobuf::util::MessageToJsonString(message, &json, options);
  return json;
}

std::string FormatExtents(const v1::Extents& e) {
  return absl::StrCat(e.i(), "x", e.j(), "x", e.k());
}

std::string FormatFit(const std::string& name, const v1::FitGridResponse& fit) {
  std::string out = absl::StrFormat(
      "%s revision %d: %d points -> %d control points (%.1fx), max deviation %.3g, %.1f ms\n", name,
      fit.revision(), fit.num_points(), fit.num_control_points(), fit.compression_ratio(),
      fit.max_deviation(), 1e3 * fit.seconds());
  absl::StrAppend(&out, absl::StrFormat("%6s %12s %10s %8s %11s %11s %16s %8s\n", "block", "points",
                                        "controls", "ratio", "max dev", "rms dev", "max at", "ms"));
  for (int b = 0; b < fit.blocks_size(); ++b) {
    const v1::BlockFitSummary& s = fit.blocks(b);
    absl::StrAppend(
        &out,
        absl::StrFormat("%6d %12d %10d %8.1f %11.3g %11.3g %16s %8.1f%s\n", b, s.num_points(),
                        s.num_control_points(), s.compression_ratio(), s.max_deviation(),
                        s.rms_deviation(),
                        absl::StrCat("(", s.max_deviation_at().i(), ",", s.max_deviation_at().j(),
                                     ",", s.max_deviation_at().k(), ")"),
                        1e3 * s.seconds(),
                        s.has_tolerance_met() && !s.tolerance_met()
                            ? absl::StrCat("  TOLERANCE NOT MET: ", s.unmet_reason())
                            : ""));
  }
  return out;
}

std::string FormatGrid(const v1::Grid& grid) {
  std::string out =
      absl::StrFormat("%s%s\n  source: %d blocks, %d points, %dD, %s\n", grid.name(),
                      grid.display_name().empty() ? "" : " (" + grid.display_name() + ")",
                      grid.source().blocks_size(), grid.source().num_points(),
                      grid.source().spatial_dim(), grid.source().format());
  if (grid.latest_revision() == 0) {
    absl::StrAppend(&out, "  not fitted yet\n");
    return out;
  }
  const v1::Revision& r = grid.revision();
  absl::StrAppend(
      &out, absl::StrFormat("  revision %d of %d: %d control points (%.1fx), max deviation %.3g\n",
                            r.revision(), grid.latest_revision(), r.num_control_points(),
                            r.compression_ratio(), r.max_deviation()));
  for (const v1::SplineBlock& b : r.blocks()) {
    absl::StrAppend(
        &out,
        absl::StrFormat("  block %d: controls %dx%dx%d, order %d/%d/%d, "
                        "max deviation %.3g\n",
                        b.index(), b.directions(0).num_controls(), b.directions(1).num_controls(),
                        b.directions(2).num_controls(), b.directions(0).order(),
                        b.directions(1).order(), b.directions(2).order(), b.fit().max_deviation()));
  }
  return out;
}

ProgressLine::ProgressLine(std::string label)
    : label_(std::move(label)), enabled_(isatty(STDERR_FILENO) == 1) {}

client::ProgressFn ProgressLine::callback() {
  return [this](int64_t done, int64_t total) {
    if (!enabled_) return;
    const int64_t percent = total > 0 ? 100 * done / total : 0;
    if (percent == last_) return;
    last_ = percent;
    drawn_ = true;
    std::fprintf(stderr, "\r%s %.1f / %.1f MiB (%lld%%)   ", label_.c_str(), done / 1048576.0,
                 total / 1048576.0, static_cast<long long>(percent));
    std::fflush(stderr);
  };
}

void ProgressLine::Done() {
  if (drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace splinegrid::cli
