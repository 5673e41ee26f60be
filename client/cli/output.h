// Printing for the `splinegrid` tool: tables, JSON and a progress line on terminals.
#ifndef SPLINEGRID_CLIENT_CLI_OUTPUT_H_
#define SPLINEGRID_CLIENT_CLI_OUTPUT_H_

#include <string>

#include "client/client.h"
#include "core/fit/airfoil/airfoil_fit.h"
#include "google/protobuf/message.h"

namespace splinegrid::cli {

// The message as JSON (proto3 JSON mapping, field names as in the .proto).
std::string ToJson(const google::protobuf::Message& message);

// "225x65x1".
std::string FormatExtents(const v1::Extents& extents);

// The fit report: totals and one line per block.
std::string FormatFit(const std::string& name, const v1::FitGridResponse& fit);

// A generated grid: the generation report (profile fit, layers, quality, stage times), then
// its revision 1 as FormatFit prints it.
std::string FormatGenerate(const v1::GenerateGridResponse& response);
// A volume grid marched off a stored surface.
std::string FormatGenerateVolume(const v1::GenerateGridResponse& response);

// One grid: source, revisions, blocks.
std::string FormatGrid(const v1::Grid& grid);

// The message as JSON on one line (for streams: one object per line).
std::string ToJsonLine(const google::protobuf::Message& message);

// "DEFORM" for REVISION_ORIGIN_DEFORM.
std::string OriginName(v1::RevisionOrigin origin);

// A deformation's new revision and its report (the request gives time and step).
std::string FormatDeform(const std::string& name, const v1::DeformGridRequest& request,
                         const v1::DeformGridResponse& response);

// The quality gate's lines of a deform report.
std::string FormatDeformReport(const v1::DeformReport& report);

// One line of `splinegrid watch`: "revision 3 origin DEFORM parent 1 time 0.02 step 2 ...".
std::string FormatRevisionLine(const v1::RevisionInfo& revision);

// The fit report's grid-wide lines (tolerances, quality, connectivity, fairing, curvature);
// `interpolating`: a control point per grid point (said when no tolerance was given);
// `has_cells`: some block has cells (a curve or a point has none, and no cell figures).
std::string FormatReport(const v1::FitReport& report, bool interpolating, bool has_cells = true);

// Wall curvature metrics, and where the samples were written (if anywhere).
std::string FormatCurvature(const std::string& name, const v1::GetWallCurvatureResponse& curvature,
                            const std::string& csv_path);

// One CSV row per sample: block,direction,start_i,start_j,start_k,line,sample,arc_length,x,y,z,
// curvature (z = 0 in 2D).
std::string CurvatureCsv(const v1::GetWallCurvatureResponse& curvature);

// An airfoil fit: control points, distance, trailing edge, fairing, curvature extrema.
std::string FormatAirfoilFit(const std::string& name, double tolerance, const AirfoilFit& fit);

// One CSV row per curvature sample of the fitted airfoil (8 per data interval):
// u,x,y,curvature (signed, positive turning left).
std::string AirfoilCurvatureCsv(const AirfoilFit& fit);

// A progress callback that redraws "label 12.3 / 45.6 MiB (27%)" on stderr when it is a
// terminal (and prints nothing otherwise); Done() ends the line.
class ProgressLine {
 public:
  explicit ProgressLine(std::string label);
  client::ProgressFn callback();
  void Done();

 private:
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  int64_t last_ = -1;
};

}  // namespace splinegrid::cli

#endif  // SPLINEGRID_CLIENT_CLI_OUTPUT_H_
